#include "core/scene.h"

#include <algorithm>

namespace femto {

Scene::Scene(SceneDesc desc)
    : desc_(std::move(desc)), geometry_(desc_), lights_(desc_), camera_(desc_.camera) {
  for (const MediumDesc& m : desc_.media) media_.push_back(m.medium);
  if (desc_.global_medium >= 0) {
    outside_ = desc_.global_medium;
  } else {
    media_.push_back(HomogeneousMedium{});  // vacuum
    outside_ = static_cast<int>(media_.size()) - 1;
  }
  inside_.assign(desc_.shapes.size(), outside_);
  for (size_t i = 0; i < desc_.shapes.size(); ++i) {
    const ShapeDesc& sh = desc_.shapes[i];
    if (sh.material.type == MaterialDesc::Type::None) has_null_boundaries_ = true;
    if (sh.interior_medium >= 0) {
      inside_[i] = sh.interior_medium;
    } else if (sh.material.type == MaterialDesc::Type::Dielectric) {
      HomogeneousMedium clear;
      clear.eta = sh.material.eta;
      media_.push_back(clear);
      inside_[i] = static_cast<int>(media_.size()) - 1;
    }
  }
  const Vec3 lo = geometry_.bounds_min(), hi = geometry_.bounds_max();
  const double extent = std::max({max_abs_component(lo), max_abs_component(hi),
                                  max_abs_component(desc_.camera.position), 1.0});
  ray_eps_ = 2e-6 * extent;  // a few float ulps of Embree's single-precision vertices
}

}  // namespace femto
