#pragma once
// Transient photon beams (Jarosz et al. 2011, beam x beam with a 1-D kernel; in time as in
// seed 000 Sec. 6 and Marco et al. 2019): every light-path segment in a scattering medium is a
// beam, and a camera ray through the medium gathers the beams that pass within R of it at their
// closest approach:
//   L += beta_c T_c(t) sigma_s(x) f_p(cos) Phi_b / (2 R sin(theta) N),
// deposited at t_camera(t) + t_beam(v) through the temporal kernel K_T. Beams are "short": a
// segment ends at its mean-free-path collision, so the chance that it reaches v is the
// transmittance to v and the beam carries no transmittance of its own.
#include <cstdint>
#include <vector>

#include "core/distributed/comm.h"
#include "core/pixel_accumulator.h"
#include "core/scene.h"
#include "core/temporal_filter.h"
#include "core/transport/caustic_aim.h"
#include "core/transport/tracker.h"

namespace femto {

struct Beam {
  Vec3 o;               ///< start
  Vec3 d;               ///< unit direction of travel
  double length = 0;    ///< to the next collision or surface (may be infinite), mm
  RGB power;            ///< flux weight at the start (divide by the light paths of the pass)
  double t_ps = 0;      ///< emission time + flight time to the start
  double sigma_ps = 0;  ///< pulse std of its light
  double g = 0;         ///< HG asymmetry of its medium
  int medium = 0;       ///< region it lies in
};

/// A beam piece's box while BeamBvh builds its tree (the items are partitioned in place).
struct BeamBuildItem {
  float lo[3], hi[3];
  float centre[3];
  uint32_t piece;  ///< index into the unsorted pieces, also the tie-break of median splits
};

/// Bounding-volume hierarchy over beams thickened by R, for segment queries; built per pass.
/// A long beam is cut into pieces of about 4 R (at most kMaxPieces) so that the boxes stay tight
/// around slanted beams; a crossing belongs to the one piece whose range holds its closest
/// approach, so no beam is gathered twice.
class BeamBvh {
 public:
  /// Pieces per beam at most: bounds the tree's memory whatever the radius.
  static constexpr uint32_t kMaxPieces = 16;
  /// One piece of a beam: parameters [v0, v1) along it (the last piece's v1 is +inf).
  struct Piece {
    uint32_t beam = 0;
    float v0 = 0, v1 = 0;
  };
  /// Beams must be finite (trace_beams clips them where their time passes the window end).
  void build(std::vector<Beam> beams, double radius);
  /// Calls f(const Beam&, const Piece&) for every beam piece whose thickened box the segment
  /// o + t d, t in [0, t_max), meets.
  template <class F>
  void query(const Vec3& o, const Vec3& d, double t_max, F&& f) const;
  size_t size() const { return beams_.size(); }
  size_t pieces() const { return pieces_.size(); }
  uint64_t memory_bytes() const;

 private:
  /// 32 bytes, two to a cache line (the traversal waits on node loads).
  struct Node {
    float lo[3], hi[3];
    /// Leaf: pieces [first, first + count). Inner (count = 0): children first and first + 1.
    uint32_t first = 0, count = 0;
  };
  static bool hits(const Node& n, const float o[3], const float inv_d[3], float t_max);
  std::vector<Beam> beams_;
  std::vector<Piece> pieces_;
  std::vector<Node> nodes_;
  // The build's scratch (boxes of the pieces, the pieces in tree order), kept from pass to pass
  // with the arrays above: a pass's build reuses their memory (fresh memory costs page faults).
  std::vector<BeamBuildItem> items_;
  std::vector<Piece> sorted_;
};

/// What a camera ray needs to gather one pass's beams.
struct BeamGather {
  const BeamBvh* bvh = nullptr;
  const Scene* scene = nullptr;
  const MediumTracker* tracker = nullptr;
  double radius = 1;  ///< R_j, mm (with radius_per_mm: the smallest)
  /// Kernel widening along the camera ray (the camera ball): R = max(radius, radius_per_mm tc)
  /// at the crossing's distance tc from the ray's origin; 0: R = radius.
  double radius_per_mm = 0;
  double bandwidth_ps = 0;  ///< T_j, ps
  double inv_paths = 1;     ///< 1 / light paths traced in the pass
  TemporalFilter kernel;
  /// Caustic beams only (the hybrid integrator): the beams are light paths' segments after one or
  /// more non-diffuse surfaces and nothing else; camera paths gather them along every medium
  /// segment and leave those paths out of their own estimate. Otherwise (all beams) camera paths
  /// gather them only before their first non-specular surface, and do not scatter in media there.
  bool caustic_only = false;
  /// Long beams (the camera ball's): a beam runs past its collisions, so the crossing also takes
  /// the beam's own transmittance from its start.
  bool carry_transmittance = false;
  /// The hybrid's camera ball (core/integrators/camera_ball.h): its beams, gathered along the
  /// first `ball_radius` mm of the camera's own segment.
  const BeamGather* ball = nullptr;
  double ball_radius = 0;
  /// Adds the in-scattered radiance from beams along [0, s_max) of `ray` in medium m, seen with
  /// throughput beta from camera time t (t_factor converts OPL to time on this segment: 0 on an
  /// unwarped camera segment).
  void gather(int m, const Ray& ray, double s_max, const RGB& beta, double t, double t_factor,
              PixelAccumulator& acc, PathStats& stats) const;
};

/// Traces `count` light paths of one pass and returns their beams in path order (the same list
/// for any thread count). `caustic_only`: only segments that follow one or more non-diffuse
/// surfaces with no medium or diffuse scattering before them (light -> (S|G)+ -> medium); only
/// then may `aim` aim the lights' emission at those surfaces (core/transport/caustic_aim.h).
std::vector<Beam> trace_beams(const Scene& scene, uint64_t seed, int pass, int64_t count,
                              int max_depth, double t_cut_ps, PathStats& stats,
                              bool caustic_only = false, const distributed::Comm* comm = nullptr,
                              const CausticAim* aim = nullptr);

/// Memory of one pass holding `beams` beams: the traced lists and the tree's copy, and at most
/// kMaxPieces pieces per beam (twice: unsorted and in tree order) with their build boxes and
/// nodes (40 + 32 bytes a piece, and up to half the nodes again, with growth, in the right
/// halves built in parallel).
inline uint64_t beam_pass_bytes(uint64_t beams) {
  return beams * (3 * sizeof(Beam) + BeamBvh::kMaxPieces * (2 * sizeof(BeamBvh::Piece) + 104));
}

template <class F>
void BeamBvh::query(const Vec3& o, const Vec3& d, double t_max, F&& f) const {
  if (nodes_.empty()) return;
  const float of[3] = {static_cast<float>(o.x), static_cast<float>(o.y), static_cast<float>(o.z)};
  const float inv[3] = {static_cast<float>(1.0 / d.x), static_cast<float>(1.0 / d.y),
                        static_cast<float>(1.0 / d.z)};
  const float tf = static_cast<float>(t_max);
  uint32_t stack[64];
  int top = 0;
  stack[top++] = 0;
  while (top > 0) {
    const Node& n = nodes_[stack[--top]];
    if (!hits(n, of, inv, tf)) continue;
    if (n.count > 0) {
      for (uint32_t i = n.first; i < n.first + n.count; ++i)
        f(beams_[pieces_[i].beam], pieces_[i]);
    } else if (top + 2 <= 64) {
      stack[top++] = n.first + 1;
      stack[top++] = n.first;
    }
  }
}

inline bool BeamBvh::hits(const Node& n, const float o[3], const float inv_d[3], float t_max) {
  // Slab test; boxes are padded by a relative epsilon at build time, so float rounding here
  // cannot drop a beam within R (a ray parallel to a slab gives +-inf or NaN, which the
  // comparisons below treat as a miss only when the origin is outside that slab).
  float t0 = 0.0f, t1 = t_max;
  for (int a = 0; a < 3; ++a) {
    const float ta = (n.lo[a] - o[a]) * inv_d[a], tb = (n.hi[a] - o[a]) * inv_d[a];
    const float near = ta < tb ? ta : tb, far = ta < tb ? tb : ta;
    t0 = near > t0 ? near : t0;
    t1 = far < t1 ? far : t1;
  }
  return t0 <= t1;
}

}  // namespace femto
