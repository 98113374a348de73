#pragma once
// A voxel medium as the space of the tissue walk (docs/tissue.md, "Voxel media"): every voxel of
// the grid has its own mu_a, mu_s and n (g is shared), as an OpenVDB density/albedo/eta medium
// gives them. A step of the walk ends at every voxel face where the optics change, so each step
// crosses constant optics and the tallies see the same segments as in a labelled volume; faces
// between equal voxels are crossed inside the step. Fresnel (or matched) at index changes, as
// LabelSpace does between labels.
#include "core/transport/tissue_walk.h"

namespace femto {

class VoxelSpace {
 public:
  /// `volume.voxel_optics` holds the optics; every voxel has label 1; optics[0].n is outside and
  /// optics[1].g the medium's anisotropy.
  VoxelSpace(const LabelVolume& volume, bool fresnel)
      : vol_(volume), fresnel_(fresnel), g_(volume.optics.at(1).g), hg_(HgCosSampler::of(g_)) {
    outside_ = WalkOptics::of(volume.optics.at(0));
  }
  const LabelVolume& volume() const { return vol_; }
  double outside_n() const { return outside_.n; }

  /// The optics of the voxel holding photon p (computed: no per-voxel table of WalkOptics).
  WalkOptics optics_at(const Photon& p) const {
    if (p.label == 0) return outside_;
    const VoxelOptics& v = voxel(p.cell);
    return WalkOptics::of(v.mu_a, v.mu_s, g_, v.n, hg_);
  }

  /// As LabelSpace::distance_to_interface, with "the same optics" in place of "the same label".
  double distance_to_interface(const Photon& p, double s_stop, int& axis, int end_cell[3],
                               VoxelCrossings* crossed) const {
    const VoxelOptics* optics = vol_.voxel_optics.data();
    const VoxelOptics here = voxel(p.cell);
    return march_to_change(vol_, p, s_stop, axis, end_cell, crossed,
                           [&](ptrdiff_t i) { return optics[i] == here; });
  }

  /// The photon is on a face where the optics change: reflect, or move into the neighbour (the
  /// outside beyond the grid).
  StepEvent cross(Photon& p, int axis, Rng& rng) const {
    int next[3];
    face_neighbour(vol_, p, axis, next);
    const bool inside = vol_.label_at(next[0], next[1], next[2]) != 0;
    const double n2 = inside ? static_cast<double>(voxel(next).n) : outside_.n;
    if (fresnel_ && reflect_or_refract(p, axis, voxel(p.cell).n, n2, rng))
      return StepEvent::Reflected;
    return enter(p, next, inside ? 1 : 0);
  }

 private:
  const VoxelOptics& voxel(const int c[3]) const {
    return vol_.voxel_optics[vol_.index(c[0], c[1], c[2])];
  }

  const LabelVolume& vol_;
  bool fresnel_;
  double g_;
  HgCosSampler hg_;  // g_'s: optics_at builds WalkOptics per step
  WalkOptics outside_;
};

}  // namespace femto
