#pragma once
// The photon random walk of tissue optics and of `femto diffusion`, written once: a step moves a
// photon along one straight piece (to its next scattering, to a voxel face where the label
// changes, or to the window end) and describes that piece as a Segment for the tallies. What the
// space looks like is a template parameter (an unbounded homogeneous medium, or a labelled voxel
// grid with Fresnel interfaces), so the hot loop has no virtual calls.
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>
#include <vector>

#include "core/branchless.h"
#include "core/bsdf/fresnel.h"
#include "core/constants.h"
#include "core/rng.h"
#include "core/transport/closed_form_faces.h"
#include "core/transport/photon.h"
#include "core/transport/safe_distance.h"
#include "core/transport/tissue_volume.h"
#include "media/phase_hg.h"
#include "samplers/exponential_ziggurat.h"

namespace femto {

/// How absorption is simulated. Weighted: flights between scatterings (mu_s), the weight decays
/// as exp(-mu_a s) along the path (implicit absorption, as MCX does; lower variance, and the
/// random walk does not depend on mu_a, which is what makes re-weighting exact). Analog: flights
/// between collisions (mu_t); a collision absorbs the photon with probability mu_a / mu_t.
enum class Absorption { Weighted, Analog };

/// What ended a step.
enum class StepEvent {
  Scattered,  ///< scattered into a new direction
  Absorbed,   ///< analog absorption at a collision (the photon's weight is in Segment::absorbed)
  Face,       ///< crossed into the neighbouring voxel
  Reflected,  ///< Fresnel (or total internal) reflection at a voxel face
  Escaped,    ///< entered label 0 (outside): the photon has left the tissue
  WindowEnd,  ///< reached the end of the time window, still in the tissue
  Lost        ///< an endless flight (unbounded clear medium); the whole weight was absorbed
};

/// Per-label coefficients as the walk uses them.
struct WalkOptics {
  double mu_a = 0, mu_s = 0, mu_t = 0, g = 0, n = 1;
  double v = kSpeedOfLight;  ///< c / n, mm/ps
  // Reciprocals (+inf for 0): a step multiplies instead of dividing.
  double inv_mu_s = kInf, inv_mu_t = kInf, inv_v = 1 / kSpeedOfLight;
  HgCosSampler hg;  ///< the scattering cosine's constants for g
  static WalkOptics of(double mu_a, double mu_s, double g, double n) {
    return of(mu_a, mu_s, g, n, HgCosSampler::of(g));
  }
  /// With hg = HgCosSampler::of(g) worked out already (optics computed per step).
  static WalkOptics of(double mu_a, double mu_s, double g, double n, const HgCosSampler& hg) {
    const double mu_t = mu_a + mu_s, v = kSpeedOfLight / n;
    return {mu_a,  mu_s, mu_t, g, n, v, mu_s > 0 ? 1 / mu_s : kInf, mu_t > 0 ? 1 / mu_t : kInf,
            1 / v, hg};
  }
  static WalkOptics of(const TissueOptics& o) { return of(o.mu_a, o.mu_s, o.g, o.n); }
};

struct WalkSettings {
  Absorption absorption = Absorption::Weighted;
  double t_end = std::numeric_limits<double>::infinity();  ///< window end, ps: photons stop there
};

/// Regular-grid traversal (3-D DDA, Amanatides & Woo) along x + d s from voxel `cell`: the
/// distance to the next face on each axis, advanced incrementally (no division per voxel).
struct VoxelDda {
  int cell[3] = {0, 0, 0}, step[3] = {0, 0, 0};
  double t_max[3] = {0, 0, 0}, t_delta[3] = {0, 0, 0};

  VoxelDda(const Vec3& x_, const Vec3& d_, const int c[3], const Vec3& origin_, const Vec3& h_) {
    // Plain arrays: Vec3's operator[] is a chain of selects where a loop is not unrolled.
    const double x[3] = {x_.x, x_.y, x_.z}, d[3] = {d_.x, d_.y, d_.z};
    const double origin[3] = {origin_.x, origin_.y, origin_.z}, h[3] = {h_.x, h_.y, h_.z};
    for (int a = 0; a < 3; ++a) {
      cell[a] = c[a];
      if (d[a] == 0) {
        step[a] = 0, t_max[a] = kInf, t_delta[a] = kInf;
        continue;
      }
      const int up = d[a] > 0;  // an integer, not a branch: the sign is a coin flip
      step[a] = 2 * up - 1;
      const double face = origin[a] + (c[a] + up) * h[a];
      t_max[a] = select_max(0.0, (face - x[a]) / d[a]);
      t_delta[a] = h[a] / std::abs(d[a]);
    }
  }
  /// The axis of the nearest face.
  int axis() const {
    return t_max[0] < t_max[1] ? (t_max[0] < t_max[2] ? 0 : 2) : (t_max[1] < t_max[2] ? 1 : 2);
  }
  void advance(int a) {
    cell[a] += step[a];
    t_max[a] += t_delta[a];
  }
};

/// An unbounded homogeneous medium (femto diffusion): no faces, one label.
class UnboundedSpace {
 public:
  explicit UnboundedSpace(const TissueOptics& o) : o_(WalkOptics::of(o)) {}
  const WalkOptics& optics(int) const { return o_; }
  const WalkOptics& optics_at(const Photon&) const { return o_; }
  double distance_to_interface(const Photon& p, double, int&, int end_cell[3],
                               VoxelCrossings*) const {
    for (int a = 0; a < 3; ++a) end_cell[a] = p.cell[a];
    return std::numeric_limits<double>::infinity();
  }
  StepEvent cross(Photon&, int, Rng&) const { return StepEvent::Face; }  // never reached

 private:
  WalkOptics o_;
};

/// The march shared by the voxel spaces: the distance along p.d from p (in voxel p.cell of
/// `vol`) to the first face whose neighbour is outside the grid or fails same(index of the
/// neighbour in vol.labels), if it comes before s_stop (else +inf); see
/// LabelSpace::distance_to_interface. `crossed` (if not null) receives the faces crossed.
template <class Same>
double march_to_change(const LabelVolume& vol, const Photon& p, double s_stop, int& axis,
                       int end_cell[3], VoxelCrossings* crossed, Same same) {
  const VoxelDda dda(p.x, p.d, p.cell, vol.origin, Vec3(vol.voxel));
  // Scalars rather than arrays indexed by the moving axis keep the march in registers; the
  // voxel's index moves by a fixed stride per axis.
  int cx = dda.cell[0], cy = dda.cell[1], cz = dda.cell[2];
  double tx = dda.t_max[0], ty = dda.t_max[1], tz = dda.t_max[2];
  const ptrdiff_t sx = dda.step[0] * static_cast<ptrdiff_t>(vol.n[1]) * vol.n[2];
  const ptrdiff_t sy = dda.step[1] * static_cast<ptrdiff_t>(vol.n[2]), sz = dda.step[2];
  ptrdiff_t i = static_cast<ptrdiff_t>(vol.index(cx, cy, cz));  // a tissue voxel: in the grid
  double s = std::numeric_limits<double>::infinity();
  if (crossed) crossed->count = 0;
  while (true) {
    if (tx < ty && tx < tz) {  // the same choice as VoxelDda::axis()
      if (tx >= s_stop) break;
      const int c = cx + dda.step[0];
      if (c < 0 || c >= vol.n[0] || !same(i + sx)) {
        s = tx, axis = 0;
        break;
      }
      if (crossed) crossed->add(tx, 0);
      cx = c, i += sx, tx += dda.t_delta[0];
    } else if (!(tx < ty) && ty < tz) {
      if (ty >= s_stop) break;
      const int c = cy + dda.step[1];
      if (c < 0 || c >= vol.n[1] || !same(i + sy)) {
        s = ty, axis = 1;
        break;
      }
      if (crossed) crossed->add(ty, 1);
      cy = c, i += sy, ty += dda.t_delta[1];
    } else {
      if (tz >= s_stop) break;
      const int c = cz + dda.step[2];
      if (c < 0 || c >= vol.n[2] || !same(i + sz)) {
        s = tz, axis = 2;
        break;
      }
      if (crossed) crossed->add(tz, 2);
      cz = c, i += sz, tz += dda.t_delta[2];
    }
  }
  end_cell[0] = cx, end_cell[1] = cy, end_cell[2] = cz;
  return s;
}

/// Puts p exactly on the face of its voxel on `axis` that it moves towards (no drift) and gives
/// the voxel beyond that face.
inline void face_neighbour(const LabelVolume& vol, Photon& p, int axis, int next[3]) {
  const int step = p.d[axis] > 0 ? 1 : -1;
  p.x[axis] = vol.origin[axis] + (p.cell[axis] + (step > 0 ? 1 : 0)) * vol.voxel;
  p.face_axis = axis;
  next[0] = p.cell[0], next[1] = p.cell[1], next[2] = p.cell[2];
  next[axis] += step;
}

/// At a face on `axis` between indices n1 (the photon's side) and n2: true if the photon is
/// reflected (Fresnel reflectance of unpolarised light, total internal reflection included),
/// else its direction is refracted by Snell's law (unchanged when n1 == n2).
inline bool reflect_or_refract(Photon& p, int axis, double n1, double n2, Rng& rng) {
  if (n1 == n2) return false;
  const double cos_i = std::abs(p.d[axis]);
  const Fresnel fr = fresnel_dielectric(cos_i, n2 / n1);
  if (fr.R >= 1.0 || rng.uniform() < fr.R) {
    p.d[axis] = -p.d[axis];
    return true;
  }
  // Snell: tangential components scale by n1 / n2, the normal one becomes cos_t.
  const double step = p.d[axis] > 0 ? 1.0 : -1.0;
  Vec3 d = p.d * (n1 / n2);
  d[axis] = step * fr.cos_t;
  p.d = normalize(d);
  return false;
}

/// Moves p into voxel `next` of label `label`; label 0 is outside (the photon has left).
inline StepEvent enter(Photon& p, const int next[3], int label) {
  p.cell[0] = next[0], p.cell[1] = next[1], p.cell[2] = next[2];
  p.label = label;
  if (label == 0) {
    p.alive = false;
    return StepEvent::Escaped;
  }
  return StepEvent::Face;
}

/// A labelled voxel grid. Where the label changes across a voxel face (another tissue, or label
/// 0 at the outer surface) and the refractive index differs, the photon is reflected with the
/// Fresnel reflectance of unpolarised light (total internal reflection included) or refracted by
/// Snell's law, when `fresnel`; otherwise every face is index-matched (straight through).
class LabelSpace {
 public:
  LabelSpace(const LabelVolume& volume, bool fresnel)
      : vol_(volume), fresnel_(fresnel), safe_(safe_distances(volume)) {
    for (const TissueOptics& o : volume.optics) optics_.push_back(WalkOptics::of(o));
    margin_ = 1e-7 * volume.voxel;
  }
  const LabelVolume& volume() const { return vol_; }
  const WalkOptics& optics(int label) const { return optics_[static_cast<size_t>(label)]; }
  /// The optics where photon p is (its label's).
  const WalkOptics& optics_at(const Photon& p) const { return optics(p.label); }
  double outside_n() const { return optics_[0].n; }

  /// Distance along p.d to the first voxel face where the label changes, if it comes before
  /// s_stop (else +inf); `axis` is that face's axis. end_cell: the voxel holding the end of the
  /// piece (the last voxel before that face, or the voxel at s_stop). Faces between voxels of
  /// the same label are crossed here, without a step of the walk (recorded in `crossed`, if not
  /// null).
  double distance_to_interface(const Photon& p, double s_stop, int& axis, int end_cell[3],
                               VoxelCrossings* crossed) const {
    // Far from other labels (most steps in a large tissue): no label to look up.
    const int safe = safe_[vol_.index(p.cell[0], p.cell[1], p.cell[2])];
    const Vec3 x1 = p.x + p.d * s_stop;
    if (inside_safe_box(vol_, p.cell, safe, x1, margin_)) {
      if (crossed) {  // the faces for a tally; every voxel on the way has the label
        crossings_in_safe_box(vol_, p.x, p.d, p.cell, s_stop, end_cell, *crossed);
        return std::numeric_limits<double>::infinity();
      }
      for (int a = 0; a < 3; ++a)
        end_cell[a] =
            std::clamp(static_cast<int>(std::floor((x1[a] - vol_.origin[a]) / vol_.voxel)),
                       p.cell[a] - (safe - 1), p.cell[a] + (safe - 1));
      return std::numeric_limits<double>::infinity();
    }
    const uint16_t* labels = vol_.labels.data();
    const uint16_t label = static_cast<uint16_t>(p.label);
    return march_to_change(vol_, p, s_stop, axis, end_cell, crossed,
                           [&](ptrdiff_t i) { return labels[i] == label; });
  }

  /// The photon is on the face of its voxel on `axis`, facing another label: reflect, or move
  /// into the neighbour.
  StepEvent cross(Photon& p, int axis, Rng& rng) const {
    int next[3];
    face_neighbour(vol_, p, axis, next);
    const int label = vol_.label_at(next[0], next[1], next[2]);
    if (fresnel_ && reflect_or_refract(p, axis, optics_[static_cast<size_t>(p.label)].n,
                                       optics_[static_cast<size_t>(label)].n, rng))
      return StepEvent::Reflected;
    return enter(p, next, label);
  }

 private:
  const LabelVolume& vol_;
  bool fresnel_;
  std::vector<WalkOptics> optics_;
  std::vector<uint8_t> safe_;  // safe_distances(vol_)
  double margin_ = 0;          // how far inside its safe box a step must end, mm
};

/// (1 - exp(-x)) / x for 0 <= x < 0.05 by its series, truncated after x^6 (relative error below
/// x^7 / 8! < 2e-14), in powers of x^2 so that the steps overlap instead of waiting in a chain.
inline double exp_mean_series(double x) {
  const double x2 = x * x;
  return (1 - x * (1.0 / 2)) + x2 * ((1.0 / 6 - x * (1.0 / 24)) +
                                     x2 * ((1.0 / 120 - x * (1.0 / 720)) + x2 * (1.0 / 5040)));
}

/// 1 - exp(-x) for x >= 0, to a relative error below 1e-13, cheaper than std::expm1: a series
/// for x < 0.05 (a step's mu_a s in most tissues: no exponential), where 1 - exp(-x) would
/// also cancel; truncated after x^7, the error is below x^7 / 8! / x < 2e-14.
inline double one_minus_exp(double x) {
  if (x < 0.05) return x * exp_mean_series(x);
  return 1 - std::exp(-x);
}

/// The integral of exp(-mu u) over u in [0, s], mu >= 0: s (1 - e^-x) / x with x = mu s; a
/// series for x < 0.05 (no exponential).
inline double decay_integral(double mu, double s) {
  const double x = mu * s;
  if (x < 0.05) return s * exp_mean_series(x);
  return -std::expm1(-x) / mu;
}

/// One step of the walk: moves p along a straight piece, fills `seg` with it (weight, absorbed
/// energy, time, label and voxel) and returns what ended it.
template <class Space>
StepEvent walk_step(const Space& space, const WalkSettings& ws, Photon& p, Rng& rng, Segment& seg) {
  const auto& o = space.optics_at(p);  // a reference, or a voxel's optics by value
  const bool analog = ws.absorption == Absorption::Analog;
  const double rate = analog ? o.mu_t : o.mu_s;
  if (p.tau_left < 0) p.tau_left = sample_unit_exponential(rng);
  int axis = 0, end_cell[3];
  const double s_event = rate > 0 ? p.tau_left * (analog ? o.inv_mu_t : o.inv_mu_s) : kInf;
  const double s_window = (ws.t_end - p.t) * o.v;
  const double s_face =
      space.distance_to_interface(p, std::min(s_event, s_window), axis, end_cell, seg.crossings);
  StepEvent ev;
  double s;
  if (s_face < s_event && s_face < s_window) {
    s = s_face, ev = StepEvent::Face;
  } else if (s_event <= s_window) {
    s = s_event, ev = StepEvent::Scattered;
  } else {
    s = std::max(0.0, s_window), ev = StepEvent::WindowEnd;
  }
  seg.x0 = p.x, seg.d = p.d, seg.t0 = p.t, seg.v = o.v, seg.w0 = p.w;
  seg.k = analog ? 0.0 : o.mu_a * o.v;
  seg.mu = analog ? 0.0 : o.mu_a;
  seg.scatterings = p.scatterings, seg.label = p.label;
  seg.cell[0] = p.cell[0], seg.cell[1] = p.cell[1], seg.cell[2] = p.cell[2];
  seg.duration = s * o.inv_v;
  seg.distance = s;
  if (!std::isfinite(s)) {  // an endless flight: everything is absorbed on the way (if mu_a > 0)
    seg.absorbed = seg.k > 0 ? p.w : 0.0;
    p.w -= seg.absorbed;
    p.alive = false;
    p.t = kInf;
    return StepEvent::Lost;
  }
  // 1 - exp(-mu s) = mu F(s): the tally's fluence takes F(s) too.
  seg.decay = decay_integral(seg.mu, s);
  seg.absorbed = p.w * (seg.mu * seg.decay);
  p.w -= seg.absorbed;  // absorbed + carried = w0 exactly, up to one rounding
  p.x += p.d * s;
  p.cell[0] = end_cell[0], p.cell[1] = end_cell[1], p.cell[2] = end_cell[2];
  if (ev == StepEvent::WindowEnd) {
    p.t = ws.t_end;
    p.tau_left -= rate * s;
    p.alive = false;
    return ev;
  }
  p.t += seg.duration;
  if (ev == StepEvent::Face) {
    p.tau_left = std::max(0.0, p.tau_left - rate * s);
    return space.cross(p, axis, rng);
  }
  p.tau_left = -1;
  if (analog && rng.uniform() * o.mu_t < o.mu_a) {
    seg.absorbed += p.w;
    p.w = 0;
    p.alive = false;
    return StepEvent::Absorbed;
  }
  // Two draws in a stated order (as arguments their order would be the compiler's): the
  // azimuth's first, as GCC evaluated them.
  const double u_phi = rng.uniform32();
  const double u_cos = rng.uniform32();
  p.d = hg_sample_direction(p.d, o.hg, u_cos, u_phi);
  ++p.scatterings;
  return StepEvent::Scattered;
}

}  // namespace femto
