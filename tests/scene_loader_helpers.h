#pragma once
// Shared by the scene-loader tests: a private temporary folder, a valid base scene (with a
// tetrahedron mesh) and helpers that load a scene or return the one-line InputError it raises.
#include <catch2/catch.hpp>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <random>
#include <string>

#include "core/error.h"
#include "core/scene_loader.h"

namespace femto::test::loader {

using Catch::Matchers::Contains;
using femto::InputError;
using femto::SceneDesc;
using femto::Vec3;
using Json = nlohmann::ordered_json;
namespace fs = std::filesystem;

// A folder private to this process (test cases may run as parallel processes), removed at exit.
struct LoaderTempDir {
  fs::path path;
  LoaderTempDir() {
    std::random_device rd;
    const auto stamp = std::chrono::steady_clock::now().time_since_epoch().count();
    path = fs::temp_directory_path() /
           ("femto-scene-loader-" + std::to_string(rd()) + "-" + std::to_string(stamp));
    fs::create_directories(path);
  }
  ~LoaderTempDir() {
    std::error_code ec;
    fs::remove_all(path, ec);
  }
};

inline const fs::path& temp_dir() {
  static LoaderTempDir dir;
  return dir.path;
}

inline std::string write_temp_file(const std::string& name, const std::string& text) {
  const fs::path p = temp_dir() / name;
  std::ofstream(p, std::ios::binary) << text;
  return p.string();
}

// Outward-facing unit tetrahedron exercising every face-corner form and negative indices.
inline const char* const kTetObj =
    "# tetrahedron\n"
    "mtllib tet.mtl\n"
    "o tet\n"
    "v 0 0 0\n"
    "v 1 0 0\n"
    "v 0 1 0\n"
    "v 0 0 1\r\n"
    "vt 0 0\nvt 1 0\nvt 0 1\n"
    "vn 0 0 -1\n"
    "usemtl glass\n"
    "s off\n"
    "f 1/1 3/2 2/3\n"
    "f 1//1 2//1 4//1\n"
    "f -4/1/1 -1/1/1 -2/1/1  # 1 4 3\n"
    "f 2 3 4\n";

inline Json base_scene() {
  write_temp_file("tet.obj", kTetObj);
  return Json::parse(R"({
    "camera": {"position": [0, 0, 10], "look_at": [0, 0, 0], "up": [0, 2, 0], "fov": 30,
               "resolution": [32, 24]},
    "time": {"t_start": 10, "bin_width": 2, "bins": 50, "mode": "unwarp"},
    "media": {
      "fog": {"type": "homogeneous", "sigma_a": 0.01, "sigma_s": 0.1, "g": 0.3, "eta": 1.33},
      "air": {"type": "homogeneous", "sigma_a": 0, "sigma_s": 0.001}
    },
    "medium": "air",
    "shapes": [
      {"type": "sphere", "center": [0, 0, -5], "radius": 2,
       "material": {"type": "dielectric", "eta": 1.33}, "medium": "fog"},
      {"type": "quad", "corner": [-1, -1, -8], "edge1": [2, 0, 0], "edge2": [0, 3, 0],
       "material": {"type": "diffuse", "albedo": [0.8, 0.5, 0.2]}},
      {"type": "box", "min": [-1, -2, -3], "max": [1, 2, 3],
       "transform": {"translate": [5, 0, 0], "rotate": [30, 45, 60], "scale": [1, -2, 1]},
       "material": {"type": "mirror"}},
      {"type": "mesh", "file": "tet.obj", "medium": "fog",
       "transform": {"scale": [-1, 1, 1]}},
      {"type": "quad", "corner": [0, 5, 0], "edge1": [1, 0, 0], "edge2": [0, 0, 1],
       "emission": 4, "pulse": {"fwhm": 3, "offset": 1}}
    ],
    "lights": [
      {"type": "point", "position": [1, 2, 3], "intensity": [1, 2, 3]},
      {"type": "spot", "position": [0, 0, 0], "look_at": [0, 0, -4], "intensity": 5,
       "cone_angle": 20},
      {"type": "laser", "position": [0, 1, 0], "direction": [0, 0, -3], "radius": 0.2,
       "power": 0.5, "pulse": {"fwhm": 0.1}}
    ],
    "render": {"spp": 4, "max_depth": 50, "seed": 7}
  })");
}

inline SceneDesc load(const Json& j) {
  return femto::load_scene_string(j.dump(2), "test.json", temp_dir().string());
}

inline std::string error_of_text(const std::string& text) {
  try {
    femto::load_scene_string(text, "test.json", temp_dir().string());
  } catch (const InputError& e) {
    const std::string msg = e.what();
    CHECK(msg.find('\n') == std::string::npos);  // messages are one line
    CHECK_THAT(msg, Contains("test.json: "));
    return msg;
  }
  FAIL("expected an InputError for:\n" << text);
  return "";
}

inline std::string error_of(const Json& j) {
  return error_of_text(j.dump(2));
}

inline Vec3 normal_of(const femto::ShapeDesc& s, std::size_t i) {
  const auto& t = s.triangles[i];
  return cross(s.vertices[t[1]] - s.vertices[t[0]], s.vertices[t[2]] - s.vertices[t[0]]);
}

// Every triangle of a convex closed shape faces away from the vertex centroid.
inline void require_outward(const femto::ShapeDesc& s) {
  Vec3 centre;
  for (const auto& v : s.vertices) centre += v;
  centre = centre / static_cast<double>(s.vertices.size());
  for (std::size_t i = 0; i < s.triangles.size(); ++i) {
    const auto& t = s.triangles[i];
    const Vec3 c = (s.vertices[t[0]] + s.vertices[t[1]] + s.vertices[t[2]]) / 3.0;
    INFO("triangle " << i);
    CHECK(dot(normal_of(s, i), c - centre) > 0);
  }
}

}  // namespace femto::test::loader
