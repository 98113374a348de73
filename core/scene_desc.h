#pragma once
// Plain description of a scene as read from JSON (docs/scene-format.md). The loader validates and
// fills it; geometry, lights and the tracer are built from it.
#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "core/reconstruction.h"
#include "core/spectrum.h"
#include "core/time_axis.h"
#include "core/vec3.h"
#include "media/homogeneous.h"

namespace femto {

/// Temporal profile of a light's emission: delta (fwhm 0) or Gaussian, centred at offset.
struct PulseDesc {
  double fwhm_ps = 0.0;    ///< full width at half maximum of a Gaussian pulse; 0 = delta
  double offset_ps = 0.0;  ///< emission time of the pulse centre
  double sigma_ps() const { return fwhm_ps / 2.3548200450309493; }  // FWHM = 2 sqrt(2 ln 2) sigma
};

struct CameraDesc {
  enum class Type { Perspective, Orthographic };
  Type type = Type::Perspective;
  Vec3 position{0, 0, 0};
  Vec3 look_at{0, 0, -1};
  Vec3 up{0, 1, 0};
  double fov_deg = 40.0;      ///< perspective: vertical field of view, degrees
  double ortho_width = 1.0;   ///< orthographic: horizontal extent of the film, mm
  int width = 64;
  int height = 64;
};

struct MaterialDesc {
  enum class Type { None, Diffuse, Mirror, Dielectric, RoughDielectric, RoughConductor };
  Type type = Type::None;        ///< None: an index-matched boundary that only bounds a medium
  RGB albedo{0.5};               ///< diffuse reflectance
  RGB reflectance{1.0};          ///< mirror reflectance; rough conductor: reflectance at normal incidence
  double eta = 1.5;              ///< dielectric, rough dielectric: refractive index of the interior
  double roughness = 0.1;        ///< rough dielectric, rough conductor: GGX alpha (0 < alpha <= 1)
  /// Whether the material scatters light into a single direction (a delta BSDF).
  bool is_specular() const { return type == Type::Mirror || type == Type::Dielectric; }
  /// Whether the material scatters into a lobe around a specular direction (rough, not diffuse).
  bool is_glossy() const { return type == Type::RoughConductor || type == Type::RoughDielectric; }
  /// Whether light can pass through it into the shape's interior.
  bool is_transmissive() const { return type == Type::Dielectric || type == Type::RoughDielectric; }
};

/// How collision distances are sampled in a medium.
enum class DistanceSampling {
  Mfp,          ///< mean-free-path: p(s) = sigma_t(s) exp(-tau(s))
  TimeUniform,  ///< exponential in optical path length with rate lambda (seed 000 Sec. 5.1)
  Mis,          ///< both, combined by multiple importance sampling
  Mixture       ///< one of the two per segment, picked by the remaining window (one-sample MIS)
};
enum class MisHeuristic { Balance, Power };

/// How a medium's direct light from point and spot lights is estimated along each ray segment.
enum class ConnectionSampling {
  Collision,    ///< next-event estimation at the sampled collisions (default)
  Equiangular,  ///< a vertex per segment, uniform in the angle seen from the light (Kulla & Fajardo 2012)
  LineToPoint,  ///< a vertex per segment, uniform in connection time (seed 000 Sec. 5.2)
  Mis,          ///< line-to-point and equiangular, one vertex each, balance heuristic
  Auto          ///< Mis on segments that pass close to the light (connection_choice.h), else Collision
};

/// The scene-file spelling of a connection strategy.
inline const char* connection_sampling_name(ConnectionSampling c) {
  switch (c) {
    case ConnectionSampling::Collision: return "collision";
    case ConnectionSampling::Equiangular: return "equiangular";
    case ConnectionSampling::LineToPoint: return "line_to_point";
    case ConnectionSampling::Mis: return "mis";
    case ConnectionSampling::Auto: return "auto";
  }
  return "?";
}

/// How the next direction is chosen at a collision in a medium.
enum class DirectionSampling {
  Phase,   ///< the phase function
  Angular  ///< half phase, half angular time sampling towards a point or spot light (Sec. 5.3)
};

/// Affine placement applied after a volume's own index-to-world transform:
/// scale, then rotate about x, y, z (degrees, in that order), then translate.
struct TransformDesc {
  Vec3 translate{0, 0, 0};
  Vec3 rotate_deg{0, 0, 0};
  Vec3 scale{1, 1, 1};
};

/// A heterogeneous medium read from an OpenVDB file.
struct VdbMediumDesc {
  std::string file;                    ///< path of the .vdb file (resolved against the scene)
  std::string density_grid = "density";
  double sigma_t_scale = 1.0;          ///< sigma_t = sigma_t_scale * density, 1/mm
  double albedo = 0.9;                 ///< single-scattering albedo where no albedo grid is given
  std::string albedo_grid;             ///< optional per-voxel albedo in [0, 1]
  double eta = 1.0;                    ///< refractive index where no eta grid is given, and outside the grid
  std::string eta_grid;                ///< optional per-voxel refractive index >= 1
  enum class Interpolation { Nearest, Trilinear };
  Interpolation interpolation = Interpolation::Nearest;
  TransformDesc transform;
  uint64_t max_dense_bytes = 16ull << 30;  ///< memory allowed for the dense grids (--max-memory)
  /// How the grids are kept in memory (docs/volumes.md, "Dense or sparse").
  enum class Storage { Auto, Dense, Sparse };
  Storage storage = Storage::Auto;
  uint64_t max_sparse_bytes = 64ull << 30;  ///< memory allowed for sparse grids (--max-memory)
};

struct MediumDesc {
  enum class Type { Homogeneous, Vdb };
  std::string name;
  Type type = Type::Homogeneous;
  HomogeneousMedium medium;            ///< homogeneous coefficients; for VDB media only g is used
  VdbMediumDesc vdb;                   ///< when type == Vdb
  DistanceSampling sampling = DistanceSampling::Mfp;
  double time_uniform_rate = 0.0;      ///< lambda, per mm of optical path length; 0 = automatic
  MisHeuristic mis_heuristic = MisHeuristic::Balance;
  ConnectionSampling connection = ConnectionSampling::Collision;
  DirectionSampling direction = DirectionSampling::Phase;
};

struct ShapeDesc {
  enum class Type { Sphere, Quad, Box, Mesh };
  Type type = Type::Sphere;
  std::string where;             ///< JSON path for error messages, e.g. "/shapes/2"
  // Sphere.
  Vec3 center{0, 0, 0};
  double radius = 1.0;
  // Triangle shapes (quad, box, mesh) in world space, filled by the loader.
  std::vector<Vec3> vertices;
  std::vector<std::array<uint32_t, 3>> triangles;
  MaterialDesc material;
  int interior_medium = -1;      ///< index into SceneDesc::media; -1: none named
  bool emissive = false;
  RGB emission{0.0};             ///< radiance emitted from the front side (along the normal)
  PulseDesc pulse;               ///< emission time profile when emissive
};

struct LightDesc {
  enum class Type { Point, Spot, Laser };
  Type type = Type::Point;
  std::string where;
  Vec3 position{0, 0, 0};
  Vec3 direction{0, 0, -1};      ///< spot and laser: unit emission direction
  RGB intensity{1.0};            ///< point and spot: radiant intensity, W/sr
  double cone_angle_deg = 30.0;  ///< spot: half-angle of the cone, degrees
  double falloff_deg = 25.0;     ///< spot: half-angle where the smooth falloff starts
  double radius = 0.5;           ///< laser: beam radius, mm
  RGB power{1.0};                ///< laser: total flux, W
  PulseDesc pulse;
};

/// Which estimators render the image (docs/outputs.md, "Integrators").
enum class IntegratorKind {
  Auto,     ///< hybrid (beams when a scattering medium lies behind specular surfaces only) when
            ///< the scene has delta lights and non-diffuse surfaces, else path
  Path,     ///< camera paths only (volumetric path tracing)
  Light,    ///< light paths connected to the camera (light tracing)
  Photons,  ///< camera paths + transient progressive photon mapping for caustics on diffuse
            ///< surfaces
  Beams,    ///< camera paths + transient progressive photon beams for all light scattered in media
  Hybrid    ///< camera paths + photons on surfaces + beams in media, each for caustic paths only
};

/// Progressive density estimation: photons on surfaces or photon beams in media (one pass =
/// light paths + one camera sample per pixel). Zero (or -1 for beta_t) means the integrator's
/// default (resolved by progressive_settings in core/render.h).
struct PhotonDesc {
  int64_t per_pass = 0;          ///< light paths (photons) emitted per pass
  double radius = 0.0;           ///< initial gather radius R_1, mm
  double bandwidth_ps = 0.0;     ///< initial temporal bandwidth T_1, ps
  double alpha = 0.0;            ///< kernel volume ratio per pass, (j + alpha) / (j + 1)
  double beta_t = -1.0;          ///< share of the shrinkage given to time (R^dims takes 1 - beta_t)
  TemporalKernel kernel = TemporalKernel::Epanechnikov;
  /// Photons and caustic beams: point and spot lights emit towards the non-diffuse shapes only
  /// (core/transport/caustic_aim.h).
  bool aim = true;
};

/// Russian roulette on camera paths (docs/scene-format.md, "render"): after the scattering or
/// bounce at vertex `depth` and later, a path whose throughput's largest component b is below
/// `threshold` goes on with probability b / threshold, its throughput divided by it (unbiased).
struct RouletteDesc {
  int depth = 3;           ///< first vertex where the roulette may end a path; 0 = off
  double threshold = 0.2;  ///< throughput below which it plays, in (0, 1]
};

struct IntegratorDesc {
  int spp = 16;
  int max_depth = 1000;          ///< safety bound on scattering/bounce vertices per path
  bool max_depth_set = false;    ///< the scene chose max_depth (e.g. 1: single scattering)
  uint64_t seed = 1;
  IntegratorKind kind = IntegratorKind::Auto;
  int64_t light_paths = 0;       ///< light tracing: paths in all; 0 = spp x width x height
  /// Hybrid: radius of the camera ball, mm (core/integrators/camera_ball.h); < 0: the default
  /// rule, 0: none.
  double camera_ball_mm = -1;
  PhotonDesc photons;
  RouletteDesc roulette;
};

struct SceneDesc {
  std::string source;            ///< file name, or "<default scene>"
  CameraDesc camera;
  TimeAxis time;
  TimeMode time_mode = TimeMode::Camera;
  ReconstructionDesc reconstruction;  ///< /time/reconstruction
  std::vector<MediumDesc> media;
  int global_medium = -1;        ///< medium filling everything outside closed shapes; -1 = vacuum
  std::vector<ShapeDesc> shapes;
  std::vector<LightDesc> lights;
  IntegratorDesc integrator;
  std::vector<std::string> warnings;  ///< imported settings accepted but not used (Mitsuba XML)
};

}  // namespace femto
