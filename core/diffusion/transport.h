#pragma once
// Photon transport for `femto diffusion`. A medium advances a photon one straight segment at a
// time; the tallies (core/diffusion/tally.h) only see segments, never how flights are sampled.
// Implemented: an infinite homogeneous medium (the shared tissue walk, core/transport/), and a
// scene's voxel (OpenVDB) medium around a source point (segments split at every cell, where
// sigma_t and eta may change; interpolated fields, analog absorption).
#include "core/rng.h"
#include "core/transport/tissue_walk.h"
#include "core/vec3.h"
#include "media/grid_medium.h"
#include "media/homogeneous.h"

namespace femto::diffusion {

// Photon, Segment and Absorption are the shared walk's (core/transport/tissue_walk.h).
using femto::Absorption;
using femto::Photon;
using femto::Segment;

/// The medium as seen by a photon: advance() returns the segment starting at the photon's state
/// and moves the photon to its end, where it scatters, is absorbed (alive = false) or, in a
/// medium with regions, enters the next region.
class PhotonTransport {
 public:
  virtual ~PhotonTransport() = default;
  virtual Segment advance(Photon& p, Rng& rng) const = 0;
};

/// An unbounded homogeneous medium with a Henyey–Greenstein phase function: the tissue walk
/// (walk_step) over an UnboundedSpace, one step per call.
class InfiniteHomogeneous final : public PhotonTransport {
 public:
  InfiniteHomogeneous(const HomogeneousMedium& medium, Absorption absorption);
  Segment advance(Photon& p, Rng& rng) const override;
  /// advance() without the virtual call and the copy: fills every field of seg in place.
  void step(Photon& p, Rng& rng, Segment& seg) const { walk_step(space_, settings_, p, rng, seg); }

 private:
  UnboundedSpace space_;
  WalkSettings settings_;
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
