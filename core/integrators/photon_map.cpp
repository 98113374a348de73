#include "core/integrators/photon_map.h"

#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>

#include "core/constants.h"
#include "core/transport/chunked_paths.h"
#include "core/transport/light_walk.h"

namespace femto {

namespace {
constexpr int64_t kPhotonChunk = 1024;  // photons per task: the unit of deterministic ordering
/// Photon streams are keyed apart from camera pixels (whose keys are < 2^62).
constexpr uint64_t kPhotonStream = 0x5000000000000000ULL;
/// Normals closer than this (cosine) count as the same surface in a gather.
constexpr double kSameSurfaceCos = 0.7;
}  // namespace

size_t PhotonGrid::cell_hash(int64_t ix, int64_t iy, int64_t iz) const {
  const uint64_t h = (static_cast<uint64_t>(ix) * 73856093ULL) ^
                     (static_cast<uint64_t>(iy) * 19349663ULL) ^
                     (static_cast<uint64_t>(iz) * 83492791ULL);
  return static_cast<size_t>(mix64(h) & (start_.size() - 2));
}

void PhotonGrid::build(std::vector<Photon> photons, double radius) {
  cell_ = 2.0 * radius;
  inv_cell_ = 1.0 / cell_;
  origin_ = photons.empty() ? Vec3(0, 0, 0) : photons.front().p;
  size_t table = 1;
  while (table < 2 * photons.size()) table <<= 1;
  start_.assign(table + 1, 0);  // power-of-two slots + 1 end marker
  std::vector<uint32_t> slot(photons.size());
  tbb::parallel_for(tbb::blocked_range<size_t>(0, photons.size(), 4096),
                    [&](const tbb::blocked_range<size_t>& r) {
                      for (size_t i = r.begin(); i != r.end(); ++i) {
                        const Vec3 q = (photons[i].p - origin_) * inv_cell_;
                        slot[i] =
                            static_cast<uint32_t>(cell_hash(static_cast<int64_t>(std::floor(q.x)),
                                                            static_cast<int64_t>(std::floor(q.y)),
                                                            static_cast<int64_t>(std::floor(q.z))));
                      }
                    });
  // Stable counting sort by slot: photon order within a slot stays the trace order.
  for (uint32_t s : slot) ++start_[s + 1];
  for (size_t h = 1; h < start_.size(); ++h) start_[h] += start_[h - 1];
  photons_.resize(photons.size());
  std::vector<uint32_t> next(start_.begin(), start_.end() - 1);
  for (size_t i = 0; i < photons.size(); ++i) photons_[next[slot[i]]++] = photons[i];
}

uint64_t PhotonGrid::memory_bytes() const {
  return photons_.capacity() * sizeof(Photon) + start_.capacity() * sizeof(uint32_t);
}

void PhotonGather::gather(const Bsdf& bsdf, const SurfaceHit& hit, const Frame& frame,
                          const Vec3& wo, const RGB& beta, double t_ps, PixelAccumulator& acc,
                          PathStats& stats) const {
  ++stats.photon_gathers;
  const double norm = inv_emitted / (kPi * radius * radius);  // disc kernel 1 / (pi R^2)
  grid->query(hit.p, radius, [&](const Photon& ph) {
    if (dot(ph.n, hit.ng) < kSameSurfaceCos) return;
    const RGB f = bsdf.f(wo, frame.to_local(ph.wi), TransportMode::Radiance);
    if (f.is_black()) return;
    const RGB value = beta * f * ph.power * norm;
    const double t = t_ps + ph.t_ps;
    if (!value.is_finite() || !std::isfinite(t)) {
      ++stats.nonfinite_dropped;
      return;
    }
    acc.add_now(kernel, t, ph.sigma_ps, value, bandwidth_ps);
  });
}

std::vector<Photon> trace_photons(const Scene& scene, uint64_t seed, int pass, int64_t count,
                                  int max_depth, double t_cut_ps, PathStats& stats,
                                  const distributed::Comm* comm, const CausticAim* aim) {
  const MediumTracker tracker(scene);
  return trace_in_chunks<Photon>(
      count, kPhotonChunk, stats,
      [&](int64_t i, std::vector<Photon>& out, PathStats& st) {
        Rng rng = Rng::for_sample(seed, kPhotonStream + static_cast<uint64_t>(pass),
                                  static_cast<uint64_t>(i));
        walk_light_path(
            scene, tracker, rng, max_depth, t_cut_ps, st,
            [&](const LightVertex& v) {
              if (v.kind != LightVertex::Kind::Surface) return v.kind == LightVertex::Kind::Emitter;
              if (!v.bsdf->is_diffuse()) return true;  // glossy and specular chains go on
              if (v.chain >= 1) {                      // light -> non-diffuse surfaces -> here
                out.push_back({v.p, v.hit->ng, -v.d, v.beta, v.t_ps, v.sigma_ps});
                ++st.photons_stored;
              }
              return false;  // after a diffuse vertex the camera paths take over
            },
            false, false, aim);
      },
      comm);
}

}  // namespace femto
