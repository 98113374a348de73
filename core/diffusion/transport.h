#pragma once
// Photon transport for `femto diffusion`. A medium advances a photon one straight segment at a
// time; the tallies (core/diffusion/tally.h) only see segments, never how flights are sampled.
// Implemented: an infinite homogeneous medium, and a scene's voxel medium around a source point
// (segments split at every cell, where sigma_t and eta may change).
#include "core/rng.h"
#include "core/vec3.h"
#include "media/grid_medium.h"
#include "media/homogeneous.h"

namespace femto::diffusion {

/// A photon between two segments.
struct Photon {
  Vec3 x;               ///< position, mm
  Vec3 d{0, 0, 1};      ///< unit propagation direction
  double t = 0;         ///< time, ps
  double w = 1;         ///< energy carried, in units of the emitted energy
  int scatterings = 0;  ///< scattering events so far
  bool alive = true;    ///< false once absorbed or gone for good
  double tau_left = -1; ///< optical depth left to the next collision (voxel media); < 0: draw anew
};

/// A straight piece of a path at constant speed: position x0 + d v tau and weight
/// w0 exp(-k tau) for tau in [0, duration]; duration may be +inf (no further collision).
struct Segment {
  Vec3 x0, d;
  double t0 = 0;        ///< start time, ps
  double duration = 0;  ///< ps
  double v = 0;         ///< speed c / eta, mm/ps
  double w0 = 1;        ///< weight at the start
  double k = 0;         ///< weight decay rate along the segment, 1/ps (weighted absorption)
  int scatterings = 0;  ///< scattering events before this segment (0: unscattered light)
};

/// The medium as seen by a photon: advance() returns the segment starting at the photon's state
/// and moves the photon to its end, where it scatters, is absorbed (alive = false) or, in a
/// medium with regions, enters the next region.
class PhotonTransport {
 public:
  virtual ~PhotonTransport() = default;
  virtual Segment advance(Photon& p, Rng& rng) const = 0;
};

/// How absorption is simulated. Weighted: flights between scatterings (sigma_s), the weight
/// decays as exp(-sigma_a v t) along the path (lower variance; the energy is exact by
/// construction). Analog: flights between collisions (sigma_t), each collision absorbs with
/// probability sigma_a / sigma_t (the energy at t is then a genuine Monte Carlo estimate).
enum class Absorption { Weighted, Analog };

/// An unbounded homogeneous medium with a Henyey–Greenstein phase function.
class InfiniteHomogeneous final : public PhotonTransport {
 public:
  InfiniteHomogeneous(const HomogeneousMedium& medium, Absorption absorption);
  Segment advance(Photon& p, Rng& rng) const override;

 private:
  HomogeneousMedium m_;
  Absorption absorption_;
  double v_;
};

/// A voxel medium around a source at world point `origin` (photon positions are relative to it).
/// Analog absorption: collisions at sigma_t, absorbed with probability 1 - albedo. Each call
/// advances to the next collision or to the end of the current cell (constant speed c / eta
/// there; with trilinear data the piece's mean speed, so that its end time is exact). Shapes of
/// the scene are ignored: the medium is taken to fill space (empty outside its grid).
class VoxelTransport final : public PhotonTransport {
 public:
  VoxelTransport(const GridMedium& grid, double g, const Vec3& origin);
  Segment advance(Photon& p, Rng& rng) const override;

 private:
  const GridMedium& grid_;
  double g_;
  Vec3 origin_;
};

}  // namespace femto::diffusion
