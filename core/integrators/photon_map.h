#pragma once
// Transient photon mapping on surfaces: caustic photons (light -> one or more non-diffuse
// surfaces -> diffuse surface) stored with their arrival time, a hash grid to find them, and the
// gather that camera paths make at diffuse vertices: a disc kernel of radius R in space and a
// kernel K_T of bandwidth T in time (core/temporal_kernel.h), integrated exactly over the bins.
#include <cstdint>
#include <vector>

#include "core/bsdf/bsdf.h"
#include "core/distributed/comm.h"
#include "core/geometry.h"
#include "core/pixel_accumulator.h"
#include "core/scene.h"
#include "core/temporal_filter.h"
#include "core/transport/caustic_aim.h"
#include "core/transport/tracker.h"

namespace femto {

struct Photon {
  Vec3 p;               ///< position on a diffuse surface
  Vec3 n;               ///< geometric normal of that surface (outward / front)
  Vec3 wi;              ///< unit direction back towards where the photon came from
  RGB power;            ///< flux weight (divide by the photons emitted in the pass)
  double t_ps = 0;      ///< emission time + flight time to p
  double sigma_ps = 0;  ///< pulse std of its light
};

/// Uniform hash grid with cells of twice the query radius: a query visits at most 8 cells.
/// Built deterministically (stable counting sort by cell) from a photon list.
class PhotonGrid {
 public:
  void build(std::vector<Photon> photons, double radius);
  /// Calls f(const Photon&) for every photon within `radius` of x (radius <= the build radius).
  template <class F>
  void query(const Vec3& x, double radius, F&& f) const;
  size_t size() const { return photons_.size(); }
  /// Bytes held by the photons and the table.
  uint64_t memory_bytes() const;

 private:
  size_t cell_hash(int64_t ix, int64_t iy, int64_t iz) const;
  std::vector<Photon> photons_;  ///< sorted by cell
  std::vector<uint32_t> start_;  ///< table: photons of hash h are [start_[h], start_[h + 1])
  double cell_ = 1, inv_cell_ = 1;
  Vec3 origin_;
};

/// What a camera path needs to gather one pass's photons.
struct PhotonGather {
  const PhotonGrid* grid = nullptr;
  double radius = 1;        ///< R_j, mm
  double bandwidth_ps = 0;  ///< T_j, ps
  double inv_emitted = 1;   ///< 1 / photons emitted in the pass
  TemporalFilter kernel;    ///< kernel filter on the film's axis
  /// Adds the radiance estimate at a diffuse surface vertex (local frame z = hit.ng) seen with
  /// throughput beta at camera time t_ps.
  void gather(const Bsdf& bsdf, const SurfaceHit& hit, const Frame& frame, const Vec3& wo,
              const RGB& beta, double t_ps, PixelAccumulator& acc, PathStats& stats) const;
};

/// Upper bound on the memory of one pass with `per_pass` photons: every photon kept, the traced
/// list and the grid's sorted copy, and the hash table.
inline uint64_t photon_pass_bytes(int64_t per_pass) {
  const auto n = static_cast<uint64_t>(per_pass);
  uint64_t table = 1;
  while (table < 2 * n) table <<= 1;
  return 2 * n * sizeof(Photon) + n * sizeof(uint32_t) + (table + 1) * sizeof(uint32_t) * 2;
}

/// Traces `count` photons of one pass (streams keyed by seed, pass and photon index) and returns
/// the caustic ones in photon order: the same list for any thread count.
/// `comm`: ranks that share the tracing (core/distributed/comm.h); each counts its own photons.
/// `aim`: the lights it aims emit towards the non-diffuse shapes only (core/transport/
/// caustic_aim.h; every stored photon follows one).
std::vector<Photon> trace_photons(const Scene& scene, uint64_t seed, int pass, int64_t count,
                                  int max_depth, double t_cut_ps, PathStats& stats,
                                  const distributed::Comm* comm = nullptr,
                                  const CausticAim* aim = nullptr);

template <class F>
void PhotonGrid::query(const Vec3& x, double radius, F&& f) const {
  if (photons_.empty()) return;
  const double r2 = radius * radius;
  // Cells overlapping [x - r, x + r]: with cells of 2r, at most two per axis.
  const auto lo = [&](double v, double o) {
    return static_cast<int64_t>(std::floor((v - radius - o) * inv_cell_));
  };
  const int64_t x0 = lo(x.x, origin_.x), y0 = lo(x.y, origin_.y), z0 = lo(x.z, origin_.z);
  size_t visited[8];
  int n_visited = 0;
  for (int64_t iz = z0; iz <= z0 + 1; ++iz)
    for (int64_t iy = y0; iy <= y0 + 1; ++iy)
      for (int64_t ix = x0; ix <= x0 + 1; ++ix) {
        const size_t h = cell_hash(ix, iy, iz);
        bool seen = false;  // two cells may share a hash slot: visit it once
        for (int k = 0; k < n_visited; ++k) seen = seen || visited[k] == h;
        if (seen) continue;
        visited[n_visited++] = h;
        for (uint32_t i = start_[h]; i < start_[h + 1]; ++i) {
          const Photon& ph = photons_[i];
          if (length_squared(ph.p - x) <= r2) f(ph);
        }
      }
}

}  // namespace femto
