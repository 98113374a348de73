#pragma once
// A photon of a tally-driven random walk and the straight segments it leaves behind. Shared by
// the tissue transport (core/transport/tissue_walk.h) and `femto diffusion`: the walk yields
// segments, tallies integrate them.
#include <cmath>

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
  double absorbed = 0;      ///< w0 (1 - exp(-k duration)): the energy absorbed along the segment
  int scatterings = 0;      ///< scattering events before this segment (0: unscattered light)
  double distance = 0;      ///< geometric length, mm (tissue walk; v * duration up to rounding)
  int label = 0;            ///< label of the region crossed (tissue walk: one label, many voxels)
  int cell[3] = {0, 0, 0};  ///< voxel of the start (tissue walk)
  double length() const { return distance; }
};

/// Integral over tau in [a, b] of exp(-k tau), stable for k b small (k >= 0).
inline double exp_integral(double k, double a, double b) {
  if (k == 0) return b - a;
  return std::exp(-k * a) * -std::expm1(-k * (b - a)) / k;
}

}  // namespace femto
