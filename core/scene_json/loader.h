#pragma once
// Internal to the JSON scene loader (core/scene_loader.h): the Loader class, whose sections are
// defined by concept in the .cpp files of this folder, and the helpers they share.
#include <array>
#include <cstdint>
#include <limits>
#include <nlohmann/json.hpp>
#include <string>
#include <utility>
#include <vector>

#include "core/constants.h"
#include "core/scene_desc.h"
#include "core/scene_json/shape_builders.h"

namespace femto::scene_json {

// Ordered so that media keep the order of the file (their indices are used by the tracer).
using Json = nlohmann::ordered_json;
using Keys = std::vector<std::string>;

constexpr std::uint64_t kMaxFilmBytes = 64ull << 30;  // guards against typos like 1e6 bins
// Bounds of docs/scene-format.md ("Bounds"): values become floats (Embree, the film) or ints.
constexpr double kMaxMagnitude = 1e9;   // any number, in its unit
constexpr double kMinLength = 1e-6;     // mm: radii and widths that are inverted
constexpr double kMinBinWidth = 1e-6;   // ps (or mm of OPL)
constexpr double kMaxWindowEnd = 1e10;  // ps
constexpr double kMinRate = 1e-9;       // per mm of OPL
constexpr double kMinScale = 1e-6, kMaxScale = 1e6;
constexpr int kMaxNesting = 64;  // JSON depth; scenes need fewer than 10 levels

// ---- message text (text.cpp)

std::string fmt(double v);
std::string fmt(const Vec3& v);
/// `path` + "/" + the key escaped as a JSON pointer step, or + the array index.
std::string at(const std::string& path, const std::string& key);
std::string at(const std::string& path, std::size_t index);
std::string show(const Json& v);
std::string suggest(const std::string& got, const Keys& options);
std::string quoted_list(const Keys& options);

// Allowed-range check with a message built from the bounds.
struct Range {
  double lo = -kInf, hi = kInf;
  bool lo_open = false, hi_open = false;
  bool contains(double x) const {
    return (lo_open ? x > lo : x >= lo) && (hi_open ? x < hi : x <= hi);
  }
  std::string text() const {
    if (hi == kInf) return std::string(lo_open ? "must be > " : "must be >= ") + fmt(lo);
    if (lo == -kInf) return std::string(hi_open ? "must be < " : "must be <= ") + fmt(hi);
    return std::string("must be in ") + (lo_open ? "(" : "[") + fmt(lo) + ", " + fmt(hi) +
           (hi_open ? ")" : "]");
  }
};
inline Range at_least(double x) {
  return {x, kInf, false, false};
}
inline Range above(double x) {
  return {x, kInf, true, false};
}
inline Range within(double lo, double hi, bool lo_open = false, bool hi_open = false) {
  return {lo, hi, lo_open, hi_open};
}

// ---- shape geometry (geometry.cpp)

/// Shape transform: scale, then rotate about x, y, z (degrees, in that order), then translate.
struct Transform {
  Vec3 scale{1, 1, 1}, rotate_deg{0, 0, 0}, translate{0, 0, 0};

  Vec3 apply(const Vec3& p) const;
  /// A mirroring transform turns counter-clockwise triangles clockwise.
  bool mirrors() const { return scale.x * scale.y * scale.z < 0; }
};

void apply_transform(const Transform& tf, ShapeDesc& s);
std::string closed_mesh_problem(const std::vector<Vec3>& v,
                                const std::vector<std::array<uint32_t, 3>>& tris);

// ---- the loader

class Loader {
 public:
  Loader(std::string source, std::string base_dir)
      : source_(std::move(source)), base_dir_(std::move(base_dir)) {}

  // core/scene_loader.cpp: the sections in order, and the checks across them.
  SceneDesc load(const std::string& text);

 private:
  std::string source_, base_dir_;

  // parse.cpp: failures and parsing.
  [[noreturn]] void fail(const std::string& path, const std::string& problem) const;
  [[noreturn]] void fail(const std::string& path, const std::string& problem,
                         const Json& got) const;
  Json parse(const std::string& text) const;

  // values.cpp: generic value readers.
  static const Json* find(const Json& o, const std::string& key);
  const Json& require(const Json& o, const std::string& path, const std::string& key) const;
  const Json& object(const Json& v, const std::string& path) const;
  void check_keys(const Json& o, const std::string& path, const Keys& allowed,
                  const std::string& what = "", const Keys& elsewhere = {}) const;
  double number(const Json& v, const std::string& path, const Range& r = {}) const;
  double not_tiny(double x, double lo, const std::string& path, const Json& v) const;
  long long integer(const Json& v, const std::string& path, long long lo, long long hi) const;
  int int_in(const Json& v, const std::string& path, int lo, int hi) const;
  std::string string(const Json& v, const std::string& path) const;
  std::string choice(const Json& v, const std::string& path, const Keys& options) const;
  Vec3 vec3(const Json& v, const std::string& path) const;
  Vec3 nonzero_vec3(const Json& v, const std::string& path) const;
  RGB rgb(const Json& v, const std::string& path, double hi = kInf) const;
  RGB bright_rgb(const Json& v, const std::string& path) const;
  std::string type_of(const Json& o, const std::string& path, const Keys& types,
                      const Keys& all_keys) const;
  static Keys join(Keys a, const Keys& b);
  std::string resolve(const std::string& file) const;

  // camera_time.cpp: camera, time axis and its reconstruction.
  void camera(const Json& v, CameraDesc& c) const;
  void time(const Json& v, SceneDesc& scene) const;
  void reconstruction(const Json& v, const std::string& p, ReconstructionDesc& r) const;

  // media.cpp: media and references to them.
  void media(const Json& v, SceneDesc& scene) const;
  void vdb_medium(const Json& o, const std::string& mp, VdbMediumDesc& d) const;
  void connection_sampling(const Json& o, const std::string& mp, MediumDesc& m) const;
  void distance_sampling(const Json& o, const std::string& mp, MediumDesc& m) const;
  int medium_ref(const Json& v, const std::string& path, const SceneDesc& scene) const;

  // materials.cpp: surface materials.
  MaterialDesc material(const Json& v, const std::string& p) const;

  // geometry.cpp: transforms.
  Transform transform(const Json& v, const std::string& p) const;
  void check_scale(double x, const std::string& path, const Json& v) const;

  // shapes.cpp: shapes.
  void check_vertices(const ShapeDesc& s, const std::string& path) const;
  void shapes(const Json& v, SceneDesc& scene) const;
  ShapeDesc shape(const Json& v, const std::string& p, const SceneDesc& scene) const;

  // lights.cpp: lights and emission pulses.
  PulseDesc pulse(const Json& v, const std::string& p) const;
  Vec3 aim(const Json& o, const std::string& p, const Vec3& position) const;
  void lights(const Json& v, SceneDesc& scene) const;

  // render.cpp: integrator settings.
  void photons(const Json& v, const std::string& p, PhotonDesc& d) const;
  void roulette(const Json& v, const std::string& p, RouletteDesc& d) const;
  void render(const Json& v, IntegratorDesc& d) const;
};

}  // namespace femto::scene_json
