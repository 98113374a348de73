#include "core/scene.h"

#include <algorithm>

#include "core/constants.h"
#include "core/medium_nesting.h"
#include "media/volume_data.h"

namespace femto {

Scene::Scene(SceneDesc desc)
    : desc_(std::move(desc)), geometry_(desc_), lights_(desc_), camera_(desc_.camera) {
  // Time-uniform sampling by default aims at about 3.5 vertices per path before the window end.
  const double t_ref = desc_.time.t_end_ps() > 0 ? desc_.time.t_end_ps() : desc_.time.bin_width_ps * desc_.time.bins;
  const double lambda_auto = 3.5 / (kSpeedOfLight * t_ref);
  for (const MediumDesc& md : desc_.media) {
    Medium m;
    m.homogeneous = md.medium;
    m.strategy.kind = md.sampling;
    m.strategy.lambda = md.time_uniform_rate > 0 ? md.time_uniform_rate : lambda_auto;
    m.strategy.heuristic = md.mis_heuristic;
    m.connection = md.connection;
    m.direction = md.direction;
    if (md.type == MediumDesc::Type::Vdb) {
      const VolumeData data = load_volume(md.vdb, desc_.source, medium_where(md.name));
      grids_.push_back(std::make_unique<GridMedium>(data, md.vdb));
      m.type = Medium::Type::Grid;
      m.grid = grids_.back().get();
      m.homogeneous.eta = md.vdb.eta;
    }
    media_.push_back(m);
  }
  if (desc_.global_medium >= 0) {
    outside_ = desc_.global_medium;
  } else {
    media_.push_back(Medium{});  // vacuum
    outside_ = static_cast<int>(media_.size()) - 1;
  }
  const size_t n = desc_.shapes.size();
  inside_.assign(n, outside_);
  for (size_t i = 0; i < n; ++i) {
    const ShapeDesc& sh = desc_.shapes[i];
    if (sh.material.type == MaterialDesc::Type::None) has_null_boundaries_ = true;
    if (sh.interior_medium >= 0) {
      inside_[i] = sh.interior_medium;
    } else if (sh.material.is_transmissive()) {
      Medium clear;
      clear.homogeneous.eta = sh.material.eta;
      media_.push_back(clear);
      inside_[i] = static_cast<int>(media_.size()) - 1;
    }
  }
  // Media nest: a shape's outside is the inside of the innermost medium shape around it, and a
  // shape that bounds no medium has that medium on both sides.
  enclosing_ = enclosing_shapes(desc_);
  outside_of_.assign(n, outside_);
  bounds_.assign(n, 0);
  for (size_t i = 0; i < n; ++i) {
    const int e = enclosing_[i];
    if (e >= 0) outside_of_[i] = inside_[static_cast<size_t>(e)];
    bounds_[i] = bounds_a_medium(desc_.shapes[i]) ? 1 : 0;
    if (!bounds_[i]) inside_[i] = outside_of_[i];
  }
  camera_medium_ = medium_at(desc_.camera.position);
  const Vec3 lo = geometry_.bounds_min(), hi = geometry_.bounds_max();
  const double extent = std::max({max_abs_component(lo), max_abs_component(hi),
                                  max_abs_component(desc_.camera.position), 1.0});
  ray_eps_ = 2e-6 * extent;  // a few float ulps of Embree's single-precision vertices
}

int Scene::medium_at(const Vec3& p) const {
  const int around = innermost_shape_at(desc_, enclosing_, p);
  return around >= 0 ? inside_[static_cast<size_t>(around)] : outside_;
}

}  // namespace femto
