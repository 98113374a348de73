#pragma once
// Everything a tissue-optics run needs (docs/tissue.md): the labelled volume, the boundary
// model, the pulsed source, the time gates and the tallies.
#include <array>
#include <atomic>
#include <cstdint>
#include <string>
#include <vector>

#include "core/time_axis.h"
#include "core/transport/tissue_volume.h"
#include "core/transport/tissue_walk.h"

namespace femto::distributed {
class Comm;
}
namespace femto::tissue {

/// A pulsed source. Beams (pencil, gaussian, disk) travel along `direction` from positions in the
/// plane through `position` perpendicular to it; photons starting outside the tissue fly straight
/// (in the outside index) to the first tissue voxel. Spot: the camera scenes' spot light (emitted
/// through core/lights.h), directions uniform in its cone weighted by its smooth falloff.
struct Source {
  enum class Type { Pencil, Gaussian, Disk, Isotropic, Spot, Sphere, Quad, Box, Mesh };
  Type type = Type::Pencil;
  Vec3 position{0, 0, 0};         ///< sphere: its centre; quad: its corner
  Vec3 direction{0, 0, 1};        ///< unit; unused by isotropic, sphere and quad
  double waist = 0;               ///< gaussian: 1/e^2 intensity radius, mm
  double radius = 0;              ///< disk, sphere: radius, mm
  Vec3 edge1{0, 0, 0}, edge2{0, 0, 0};  ///< quad: its edges; it emits along edge1 x edge2
  Vec3 box_min{0, 0, 0}, box_max{0, 0, 0};  ///< box: its corners; it emits outwards
  /// mesh: its triangles (mm, from the file), each emitting along its normal (right-hand rule)
  std::vector<Vec3> mesh_vertices;
  std::vector<std::array<uint32_t, 3>> mesh_triangles;
  double cone_angle_deg = 30;     ///< spot: half-angle of the cone
  double falloff_start_deg = 24;  ///< spot: half-angle where the smooth falloff starts
  double fwhm_ps = 0;             ///< Gaussian pulse FWHM; 0 = delta pulse
  double offset_ps = 0;           ///< emission time of the pulse centre
  bool specular = false;  ///< remove the Fresnel reflection at the entry surface from the weight
  double sigma_ps() const { return fwhm_ps / 2.3548200450309493; }
};

/// Sources that emit from a surface (the camera scenes' emissive shapes).
inline bool is_surface(Source::Type t) {
  return t == Source::Type::Sphere || t == Source::Type::Quad || t == Source::Type::Box ||
         t == Source::Type::Mesh;
}

/// A disc detector on the tissue surface: photons leaving the tissue through a voxel face in the
/// plane of `center` and within `radius` of it are detected, if their exit direction lies within
/// the numerical aperture (na > 0; in the outside medium, from the normal of the face they leave
/// through). A photon counts for the first detector (in order) that it reaches.
struct Detector {
  Vec3 center{0, 0, 0};
  double radius = 1;  ///< mm
  double na = 0;      ///< 0: any direction
};

/// The fluence volume: its own grid (resolution and placement) over time gates of `time`.
struct FluenceGrid {
  int n[3] = {0, 0, 0};
  Vec3 origin{0, 0, 0};  ///< lower corner, mm
  Vec3 size{0, 0, 0};    ///< extent, mm
  Vec3 spacing() const { return {size.x / n[0], size.y / n[1], size.z / n[2]}; }
  size_t cells() const { return static_cast<size_t>(n[0]) * n[1] * n[2]; }
};

struct Setup {
  LabelVolume volume;
  bool fresnel = true;  ///< "boundary": "fresnel"; false: "matched" (no reflection anywhere)
  Absorption absorption = Absorption::Weighted;
  Source source;
  TimeAxis time;  ///< gates; photons stop at time.t_end_ps()
  bool fluence = true;
  FluenceGrid fluence_grid;
  bool fluence_stderr = false;  ///< per-voxel standard errors from the batches
  bool faces = false;           ///< exitance images of the six faces of the volume over time
  std::vector<Detector> detectors;
  bool save_detected = true;  ///< per detected photon: partial paths, scatterings, weight, time
  uint64_t max_detected = 10000000;  ///< records kept at most (the TPSF counts every photon)
  uint64_t photons = 1000000;
  uint64_t seed = 1;
  int batches = 10;  ///< independent batches for standard errors and confidence intervals
  int threads = 0;   ///< 0: all cores
  bool quiet = true;
  /// The processes sharing the run (core/distributed/comm.h; nullptr: this one alone): chunk c of
  /// a batch is traced by rank c % ranks and rank 0 gets the result of a single process.
  const distributed::Comm* comm = nullptr;
  /// Set by another thread: simulate() skips the chunks not yet started and throws
  /// tissue::Stopped.
  const std::atomic<bool>* stop = nullptr;
  /// Photons traced so far, raised after every chunk (for a progress display elsewhere).
  std::atomic<uint64_t>* photons_done = nullptr;
};

}  // namespace femto::tissue
