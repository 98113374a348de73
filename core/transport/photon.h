#pragma once
// A photon of a tally-driven random walk and the straight segments it leaves behind. Shared by
// the tissue transport (core/transport/tissue_walk.h) and `femto diffusion`: the walk yields
// segments, tallies integrate them.
#include <cmath>
#include <cstdint>

#include "core/vec3.h"

namespace femto {

/// A photon between two steps of the walk.
struct Photon {
  Vec3 x;                   ///< position, mm (diffusion: relative to the source)
  Vec3 d{0, 0, 1};          ///< unit propagation direction
  double t = 0;             ///< time, ps
  double w = 1;             ///< energy carried, in units of the launched energy
  int scatterings = 0;      ///< scattering events so far
  bool alive = true;        ///< false once absorbed, escaped or past the window end
  double tau_left = -1;     ///< optical depth left to the next event; < 0: draw anew
  int cell[3] = {0, 0, 0};  ///< voxel of a labelled grid (tissue walk)
  int label = 0;            ///< label of that voxel (tissue walk)
  int face_axis = -1;       ///< axis of the last voxel face crossed or reflected at (tissue walk)
};

/// The voxel faces crossed inside one step of the tissue walk (filled by its march when a tally
/// asks for them, so that a tally on the same grid need not march again): the distance along the
/// step of each face and the axis it is normal to.
struct VoxelCrossings {
  static constexpr int kMax = 64;
  int count = 0;  ///< faces crossed; above kMax only the first kMax are recorded
  double s[kMax];
  int8_t axis[kMax];
  bool complete() const { return count <= kMax; }
  void add(double at, int a) {
    if (count < kMax) s[count] = at, axis[count] = static_cast<int8_t>(a);
    ++count;
  }
};

/// A straight piece of a path at constant speed (in the tissue walk: inside one label, across
/// any number of its voxels): position x0 + d v tau and weight
/// w0 exp(-k tau) for tau in [0, duration]; duration may be +inf (no further event).
struct Segment {
  Vec3 x0, d;
  double t0 = 0;            ///< start time, ps
  double duration = 0;      ///< ps
  double v = 0;             ///< speed c / n, mm/ps
  double w0 = 1;            ///< weight at the start
  double k = 0;             ///< weight decay rate along the segment, 1/ps (weighted absorption)
  double mu = 0;            ///< the same per mm: k / v
  double absorbed = 0;      ///< w0 (1 - exp(-k duration)): the energy absorbed along the segment
  double decay = 0;         ///< integral of exp(-mu s) over the segment's length, mm
  int scatterings = 0;      ///< scattering events before this segment (0: unscattered light)
  double distance = 0;      ///< geometric length, mm (tissue walk; v * duration up to rounding)
  int label = 0;            ///< label of the region crossed (tissue walk: one label, many voxels)
  int cell[3] = {0, 0, 0};  ///< voxel of the start (tissue walk)
  /// Set by the caller (or nullptr): the walk records there the voxel faces crossed in the step.
  VoxelCrossings* crossings = nullptr;
  double length() const { return distance; }
};

/// Integral over tau in [a, b] of exp(-k tau), stable for k b small (k >= 0).
inline double exp_integral(double k, double a, double b) {
  if (k == 0) return b - a;
  return std::exp(-k * a) * -std::expm1(-k * (b - a)) / k;
}

}  // namespace femto
