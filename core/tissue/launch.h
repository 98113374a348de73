#pragma once
// Photons from the pulsed source of a tissue run (docs/tissue.md, "Sources"): position,
// direction, emission time and weight, then straight through the outside to the first tissue
// voxel, with Fresnel (and optional specular loss) at the entry face.
#include <memory>

#include "core/lights.h"
#include "core/rng.h"
#include "core/scene_desc.h"
#include "core/tissue/setup.h"
#include "core/transport/photon.h"

namespace femto::tissue {

/// Sources emitted by the camera scenes' light code (spot, emissive sphere and quad): the light
/// and the normalisation that makes the mean launch weight 1.
struct Emitter {
  SceneDesc scene;
  std::unique_ptr<LightSet> lights;
  double inv_mean_beta = 1;
  double max_weight = 1;  ///< the largest launch weight
  explicit Emitter(const Source& src);
  // `lights` points into `scene`: built in place, never copied or moved.
  Emitter(const Emitter&) = delete;
  Emitter& operator=(const Emitter&) = delete;
};

/// Launches photon p from the source (position, direction, time, weight) and moves it to the first
/// tissue voxel; false when it never reaches tissue. `specular` receives the weight reflected at
/// the entry surface (source.specular), already removed from p.w.
/// Space: LabelSpace or VoxelSpace (core/transport/).
template <class Space>
bool launch(const Setup& s, const Space& space, const Emitter& emitter, Rng& rng, Photon& p,
            double& specular);

}  // namespace femto::tissue
