#include "core/integrators/photon_beams.h"

#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include "core/constants.h"
#include "core/transport/chunked_paths.h"
#include "core/transport/light_walk.h"
#include "media/phase_hg.h"

namespace femto {

namespace {
constexpr int64_t kChunk = 256;  // light paths per task: the unit of deterministic ordering
/// Beam streams are keyed apart from camera pixels and photons.
constexpr uint64_t kBeamStream = 0x6000000000000000ULL;
constexpr uint32_t kLeafSize = 4;

double axis_of(const Vec3& v, int a) {
  return a == 0 ? v.x : (a == 1 ? v.y : v.z);
}
}  // namespace

void BeamBvh::build(std::vector<Beam> beams, double radius) {
  beams_ = std::move(beams);
  nodes_.clear();
  if (beams_.empty()) return;
  std::vector<Vec3> lo(beams_.size()), hi(beams_.size()), centre(beams_.size());
  const Vec3 r(radius);
  for (size_t i = 0; i < beams_.size(); ++i) {
    const Vec3 a = beams_[i].o, b = beams_[i].o + beams_[i].d * beams_[i].length;
    lo[i] = vmin(a, b) - r;
    hi[i] = vmax(a, b) + r;
    centre[i] = (a + b) * 0.5;
  }
  nodes_.reserve(2 * beams_.size() / kLeafSize + 1);
  build_node(0, static_cast<uint32_t>(beams_.size()), lo, hi, centre);
}

uint32_t BeamBvh::build_node(uint32_t first, uint32_t count, std::vector<Vec3>& lo,
                             std::vector<Vec3>& hi, std::vector<Vec3>& centre) {
  const auto index = static_cast<uint32_t>(nodes_.size());
  nodes_.push_back({});
  Vec3 blo = lo[first], bhi = hi[first], clo = centre[first], chi = centre[first];
  for (uint32_t i = first + 1; i < first + count; ++i) {
    blo = vmin(blo, lo[i]);
    bhi = vmax(bhi, hi[i]);
    clo = vmin(clo, centre[i]);
    chi = vmax(chi, centre[i]);
  }
  nodes_[index].lo = blo;
  nodes_[index].hi = bhi;
  const Vec3 ext = chi - clo;
  if (count <= kLeafSize || std::fmax(ext.x, std::fmax(ext.y, ext.z)) <= 0) {
    nodes_[index].first = first;
    nodes_[index].count = count;
    return index;
  }
  // Median split on the widest axis of the centres; beams and their boxes move together.
  const int axis = ext.x >= ext.y && ext.x >= ext.z ? 0 : (ext.y >= ext.z ? 1 : 2);
  std::vector<uint32_t> order(count);
  for (uint32_t i = 0; i < count; ++i) order[i] = first + i;
  const uint32_t half = count / 2;
  std::nth_element(order.begin(), order.begin() + half, order.end(), [&](uint32_t a, uint32_t b) {
    const double ca = axis_of(centre[a], axis), cb = axis_of(centre[b], axis);
    return ca < cb || (ca == cb && a < b);  // ties by index: the same tree on every run
  });
  std::vector<Beam> b2(count);
  std::vector<Vec3> l2(count), h2(count), c2(count);
  for (uint32_t i = 0; i < count; ++i) {
    b2[i] = beams_[order[i]];
    l2[i] = lo[order[i]];
    h2[i] = hi[order[i]];
    c2[i] = centre[order[i]];
  }
  std::copy(b2.begin(), b2.end(), beams_.begin() + first);
  std::copy(l2.begin(), l2.end(), lo.begin() + first);
  std::copy(h2.begin(), h2.end(), hi.begin() + first);
  std::copy(c2.begin(), c2.end(), centre.begin() + first);
  const uint32_t left = build_node(first, half, lo, hi, centre);
  const uint32_t right = build_node(first + half, count - half, lo, hi, centre);
  nodes_[index].left = left;
  nodes_[index].right = right;
  return index;
}

bool BeamBvh::hits(const Node& n, const Vec3& o, const Vec3& inv_d, double t_max) {
  double t0 = 0.0, t1 = t_max;
  for (int a = 0; a < 3; ++a) {
    const double inv = axis_of(inv_d, a), oa = axis_of(o, a);
    double ta = (axis_of(n.lo, a) - oa) * inv, tb = (axis_of(n.hi, a) - oa) * inv;
    if (std::isnan(ta) || std::isnan(tb)) {  // ray parallel to the slab, on its boundary
      if (oa < axis_of(n.lo, a) || oa > axis_of(n.hi, a)) return false;
      continue;
    }
    if (ta > tb) std::swap(ta, tb);
    t0 = std::fmax(t0, ta);
    t1 = std::fmin(t1, tb);
    if (t0 > t1) return false;
  }
  return true;
}

uint64_t BeamBvh::memory_bytes() const {
  return beams_.capacity() * sizeof(Beam) + nodes_.capacity() * sizeof(Node);
}

void BeamGather::gather(int m, const Ray& ray, double s_max, const RGB& beta, double t,
                        double t_factor, PixelAccumulator& acc, PathStats& stats) const {
  const Medium& med = scene->media()[static_cast<size_t>(m)];
  const double norm = inv_paths / (2.0 * radius);  // 1-D kernel 1 / (2 R)
  const double R2 = radius * radius;
  bvh->query(ray.o, ray.d, s_max, [&](const Beam& b) {
    if (b.medium != m) return;
    // Closest approach of the camera line o + tc u and the beam line b.o + vb b.d.
    const Vec3 w0 = ray.o - b.o;
    const double cos_ub = dot(ray.d, b.d), du = dot(ray.d, w0), db = dot(b.d, w0);
    const double sin2 = 1.0 - cos_ub * cos_ub;
    if (!(sin2 > 1e-12)) return;  // parallel lines meet in a set of measure zero
    const double tc = (cos_ub * db - du) / sin2, vb = (db - cos_ub * du) / sin2;
    if (!(tc >= 0 && tc < s_max && vb >= 0 && vb < b.length)) return;
    const Vec3 xc = ray.at(tc);
    if (length_squared(xc - (b.o + b.d * vb)) >= R2) return;
    const double sigma_s = med.type == Medium::Type::Grid
                               ? med.grid->sigma_t_at(xc) * med.grid->albedo_at(xc)
                               : med.homogeneous.sigma_s;
    if (!(sigma_s > 0)) return;
    double tau_c, opl_c, tau_b, opl_b;
    tracker->segment_integrals(m, ray, tc, tau_c, opl_c);
    tracker->segment_integrals(b.medium, {b.o, b.d}, vb, tau_b, opl_b);
    // Light travels along b.d and scatters towards the camera, along -u.
    const double f = hg_eval(-cos_ub, b.g);
    const RGB value = beta * b.power * (std::exp(-tau_c) * sigma_s * f * norm / std::sqrt(sin2));
    const double time = t + opl_c * t_factor + b.t_ps + opl_b / kSpeedOfLight;
    if (!value.is_finite() || !std::isfinite(time)) {
      ++stats.nonfinite_dropped;
      return;
    }
    ++stats.beam_gathers;
    acc.add_now(kernel, time, b.sigma_ps, value, bandwidth_ps);
  });
}

std::vector<Beam> trace_beams(const Scene& scene, uint64_t seed, int pass, int64_t count,
                              int max_depth, double t_cut_ps, PathStats& stats, bool caustic_only) {
  const MediumTracker tracker(scene);
  return trace_in_chunks<Beam>(
      count, kChunk, stats, [&](int64_t i, std::vector<Beam>& out, PathStats& st) {
        Rng rng = Rng::for_sample(seed, kBeamStream + static_cast<uint64_t>(pass),
                                  static_cast<uint64_t>(i));
        walk_light_path(
            scene, tracker, rng, max_depth, t_cut_ps, st,
            [&](const LightVertex& v) {
              // A caustic path is over once it scatters off a diffuse surface or in a medium.
              if (caustic_only && v.chain < 0) return false;
              if (v.kind != LightVertex::Kind::Segment) return true;
              if (caustic_only && v.chain < 1) return true;
              // Beyond the window's end nothing it lights can be seen (eta >= 1: time >= distance /
              // c).
              const double length = std::fmin(v.length, (t_cut_ps - v.t_ps) * kSpeedOfLight);
              if (length > 0) {
                out.push_back({v.p, v.d, length, v.beta, v.t_ps, v.sigma_ps, v.g, v.medium});
                ++st.beams_stored;
              }
              return true;
            },
            /*segments=*/true);
      });
}

}  // namespace femto
