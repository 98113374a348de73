// Scene loader and OBJ loader: valid scenes land in SceneDesc; each class of bad input raises an
// InputError whose one-line message names the JSON path and the offending value.
#include <catch2/catch.hpp>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <functional>
#include <nlohmann/json.hpp>
#include <random>
#include <string>

#include "core/constants.h"
#include "core/error.h"
#include "core/obj_loader.h"
#include "core/scene_loader.h"

namespace {

using Catch::Matchers::Contains;
using femto::InputError;
using femto::SceneDesc;
using femto::Vec3;
using Json = nlohmann::ordered_json;
namespace fs = std::filesystem;

// A folder private to this process (test cases may run as parallel processes), removed at exit.
struct TempDir {
  fs::path path;
  TempDir() {
    std::random_device rd;
    const auto stamp = std::chrono::steady_clock::now().time_since_epoch().count();
    path = fs::temp_directory_path() /
           ("femto-scene-loader-" + std::to_string(rd()) + "-" + std::to_string(stamp));
    fs::create_directories(path);
  }
  ~TempDir() {
    std::error_code ec;
    fs::remove_all(path, ec);
  }
};

const fs::path& temp_dir() {
  static TempDir dir;
  return dir.path;
}

std::string write_file(const std::string& name, const std::string& text) {
  const fs::path p = temp_dir() / name;
  std::ofstream(p, std::ios::binary) << text;
  return p.string();
}

// Outward-facing unit tetrahedron exercising every face-corner form and negative indices.
const char* const kTetObj =
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

Json base_scene() {
  write_file("tet.obj", kTetObj);
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

SceneDesc load(const Json& j) {
  return femto::load_scene_string(j.dump(2), "test.json", temp_dir().string());
}

std::string error_of_text(const std::string& text) {
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

std::string error_of(const Json& j) { return error_of_text(j.dump(2)); }

Vec3 normal_of(const femto::ShapeDesc& s, std::size_t i) {
  const auto& t = s.triangles[i];
  return cross(s.vertices[t[1]] - s.vertices[t[0]], s.vertices[t[2]] - s.vertices[t[0]]);
}

// Every triangle of a convex closed shape faces away from the vertex centroid.
void require_outward(const femto::ShapeDesc& s) {
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

}  // namespace

TEST_CASE("scene loader: a valid scene lands in SceneDesc", "[scene_loader]") {
  const SceneDesc s = load(base_scene());
  CHECK(s.source == "test.json");

  CHECK(s.camera.type == femto::CameraDesc::Type::Perspective);
  CHECK(s.camera.position.z == 10);
  CHECK(s.camera.up.y == Approx(1.0));  // normalised
  CHECK(s.camera.fov_deg == 30);
  CHECK(s.camera.width == 32);
  CHECK(s.camera.height == 24);

  CHECK(s.time.t_start_ps == 10);
  CHECK(s.time.bin_width_ps == 2);
  CHECK(s.time.bins == 50);
  CHECK(s.time_mode == femto::TimeMode::Unwarp);

  // Media keep the order of the file.
  REQUIRE(s.media.size() == 2);
  CHECK(s.media[0].name == "fog");
  CHECK(s.media[0].medium.sigma_a == 0.01);
  CHECK(s.media[0].medium.sigma_s == 0.1);
  CHECK(s.media[0].medium.g == 0.3);
  CHECK(s.media[0].medium.eta == 1.33);
  CHECK(s.media[1].name == "air");
  CHECK(s.media[1].medium.eta == 1.0);
  CHECK(s.global_medium == 1);

  REQUIRE(s.shapes.size() == 5);
  const auto& sphere = s.shapes[0];
  CHECK(sphere.type == femto::ShapeDesc::Type::Sphere);
  CHECK(sphere.where == "/shapes/0");
  CHECK(sphere.center.z == -5);
  CHECK(sphere.radius == 2);
  CHECK(sphere.material.type == femto::MaterialDesc::Type::Dielectric);
  CHECK(sphere.material.eta == 1.33);
  CHECK(sphere.interior_medium == 0);
  CHECK_FALSE(sphere.emissive);

  const auto& quad = s.shapes[1];
  CHECK(quad.type == femto::ShapeDesc::Type::Quad);
  CHECK(quad.material.type == femto::MaterialDesc::Type::Diffuse);
  CHECK(quad.material.albedo.g == 0.5);
  REQUIRE(quad.triangles.size() == 2);
  for (std::size_t i = 0; i < 2; ++i) {
    const Vec3 n = normal_of(quad, i);  // edge1 x edge2 = +z, each triangle half the area
    CHECK(n.x == Approx(0).margin(1e-12));
    CHECK(n.y == Approx(0).margin(1e-12));
    CHECK(n.z == Approx(6.0));
  }

  const auto& box = s.shapes[2];
  CHECK(box.type == femto::ShapeDesc::Type::Box);
  CHECK(box.material.type == femto::MaterialDesc::Type::Mirror);
  CHECK(box.material.reflectance.r == 1.0);
  REQUIRE(box.vertices.size() == 8);
  REQUIRE(box.triangles.size() == 12);
  require_outward(box);  // despite rotation and a mirroring scale

  const auto& mesh = s.shapes[3];
  CHECK(mesh.type == femto::ShapeDesc::Type::Mesh);
  CHECK(mesh.material.type == femto::MaterialDesc::Type::None);
  CHECK(mesh.interior_medium == 0);
  REQUIRE(mesh.vertices.size() == 4);
  REQUIRE(mesh.triangles.size() == 4);
  CHECK(mesh.vertices[1].x == -1);  // mirrored
  require_outward(mesh);

  const auto& lamp = s.shapes[4];
  CHECK(lamp.emissive);
  CHECK(lamp.emission.b == 4);
  CHECK(lamp.pulse.fwhm_ps == 3);
  CHECK(lamp.pulse.offset_ps == 1);
  CHECK(normal_of(lamp, 0).y < 0);  // x cross z = -y

  REQUIRE(s.lights.size() == 3);
  CHECK(s.lights[0].type == femto::LightDesc::Type::Point);
  CHECK(s.lights[0].where == "/lights/0");
  CHECK(s.lights[0].intensity.b == 3);
  const auto& spot = s.lights[1];
  CHECK(spot.type == femto::LightDesc::Type::Spot);
  CHECK(spot.direction.z == Approx(-1.0));
  CHECK(spot.cone_angle_deg == 20);
  CHECK(spot.falloff_deg == Approx(16));  // default 0.8 * cone_angle
  const auto& laser = s.lights[2];
  CHECK(laser.type == femto::LightDesc::Type::Laser);
  CHECK(laser.direction.z == Approx(-1.0));  // normalised
  CHECK(laser.radius == 0.2);
  CHECK(laser.power.g == 0.5);
  CHECK(laser.pulse.fwhm_ps == 0.1);

  CHECK(s.integrator.spp == 4);
  CHECK(s.integrator.max_depth == 50);
  CHECK(s.integrator.seed == 7);
}

TEST_CASE("scene loader: defaults and the optical-path-length time axis", "[scene_loader]") {
  const Json j = Json::parse(R"({
    "camera": {"type": "orthographic", "position": [0, 0, 5], "look_at": [0, 0, 0],
               "width": 12, "resolution": [8, 4]},
    "time": {"start_opl": 3, "bin_width_opl": 0.6, "bins": 10},
    // comments are allowed
    "lights": [{"type": "point", "position": [0, 0, 0], "intensity": 1}]
  })",
                             nullptr, true, true);
  const SceneDesc s = femto::load_scene_string(j.dump(), "<default scene>", "");
  CHECK(s.camera.type == femto::CameraDesc::Type::Orthographic);
  CHECK(s.camera.ortho_width == 12);
  CHECK(s.camera.up.y == 1);
  CHECK(s.time.t_start_ps == Approx(3 / femto::kSpeedOfLight));
  CHECK(s.time.bin_width_ps == Approx(0.6 / femto::kSpeedOfLight));
  CHECK(s.time.bin_width_ps == Approx(2.00138).epsilon(1e-5));
  CHECK(s.time_mode == femto::TimeMode::Camera);
  CHECK(s.global_medium == -1);
  CHECK(s.media.empty());
  CHECK(s.shapes.empty());
  CHECK(s.integrator.spp == 16);
  CHECK(s.integrator.max_depth == 1000);
  CHECK(s.integrator.seed == 1);

  // Comments are accepted in the text itself too.
  CHECK_NOTHROW(femto::load_scene_string("// a scene\n" + j.dump(2) + "\n/* end */", "x.json", ""));
}

TEST_CASE("scene loader: load_scene_file resolves meshes next to the scene", "[scene_loader]") {
  const fs::path sub = temp_dir() / "scenes";
  fs::create_directories(sub / "meshes");
  std::ofstream(sub / "meshes" / "tet.obj") << kTetObj;
  Json j = base_scene();
  j["shapes"][3]["file"] = "meshes/tet.obj";
  std::ofstream(sub / "scene.json") << j.dump(2);
  const SceneDesc s = femto::load_scene_file((sub / "scene.json").string());
  CHECK(s.source == (sub / "scene.json").string());
  CHECK(s.shapes[3].triangles.size() == 4);

  const std::string missing = (temp_dir() / "nope.json").string();
  CHECK_THROWS_WITH(femto::load_scene_file(missing),
                    Contains("nope.json") && Contains("not found"));
}

TEST_CASE("scene loader: the example mesh is a closed outward icosahedron", "[scene_loader]") {
#ifdef FEMTO_SOURCE_DIR
  const fs::path root = FEMTO_SOURCE_DIR;
#else
  const fs::path root = fs::path(__FILE__).parent_path().parent_path();
#endif
  const fs::path obj = root / "data" / "meshes" / "icosahedron.obj";
  if (!fs::exists(obj)) {
    WARN("example mesh not found at " << obj.string());
    return;
  }
  Json j = base_scene();
  j["shapes"][3]["file"] = obj.string();
  j["shapes"][3].erase("transform");
  const SceneDesc s = load(j);
  CHECK(s.shapes[3].vertices.size() == 12);
  CHECK(s.shapes[3].triangles.size() == 20);
  require_outward(s.shapes[3]);
}

TEST_CASE("scene loader: unknown keys", "[scene_loader]") {
  Json j = base_scene();
  j["media"]["fog"]["sigmaa"] = j["media"]["fog"]["sigma_a"];
  j["media"]["fog"].erase("sigma_a");
  const std::string msg = error_of(j);
  CHECK_THAT(msg, Contains("/media/fog/sigmaa") && Contains("unknown key 'sigmaa'") &&
                      Contains("did you mean 'sigma_a'"));

  j = base_scene();
  j["colour"] = 1;
  CHECK_THAT(error_of(j), Contains("/colour") && Contains("unknown key 'colour'"));

  j = base_scene();
  j["camera"]["width"] = 3;  // orthographic only
  CHECK_THAT(error_of(j), Contains("/camera/width") && Contains("perspective camera"));

  j = base_scene();
  j["shapes"][0]["tpye"] = "box";
  j["shapes"][0].erase("type");
  CHECK_THAT(error_of(j), Contains("/shapes/0/tpye") && Contains("did you mean 'type'"));
}

TEST_CASE("scene loader: duplicate keys", "[scene_loader]") {
  const std::string text = base_scene().dump(2);
  const std::string dup = text.substr(0, text.rfind('}')) + R"(, "render": {"spp": 2} })";
  CHECK_THAT(error_of_text(dup), Contains("/render") && Contains("duplicate key 'render'"));
  CHECK_THAT(error_of_text(R"({"lights": [{"type": "point", "type": "spot"}]})"),
             Contains("/lights/0/type") && Contains("duplicate"));
}

TEST_CASE("scene loader: wrong types", "[scene_loader]") {
  Json j = base_scene();
  j["camera"]["fov"] = "wide";
  CHECK_THAT(error_of(j), Contains("/camera/fov: expected a number (got \"wide\")"));

  j = base_scene();
  j["camera"]["position"] = {1, 2};
  CHECK_THAT(error_of(j), Contains("/camera/position: expected an array of 3 numbers (got [1,2])"));

  j = base_scene();
  j["time"]["bins"] = 2.5;
  CHECK_THAT(error_of(j), Contains("/time/bins: expected an integer (got 2.5)"));

  j = base_scene();
  j["shapes"][1]["material"]["albedo"] = "red";
  CHECK_THAT(error_of(j), Contains("/shapes/1/material/albedo") && Contains("\"red\""));

  j = base_scene();
  j["shapes"] = Json::object();
  CHECK_THAT(error_of(j), Contains("/shapes: expected an array"));

  CHECK_THAT(error_of_text("[1, 2]"), Contains("test.json: /: ") && Contains("[1,2]"));
}

TEST_CASE("scene loader: missing required keys", "[scene_loader]") {
  Json j = base_scene();
  j["camera"].erase("position");
  CHECK_THAT(error_of(j), Contains("/camera/position: missing required key 'position'"));

  j = base_scene();
  j.erase("time");
  CHECK_THAT(error_of(j), Contains("/time: missing required key 'time'"));

  j = base_scene();
  j["time"].erase("bin_width");
  CHECK_THAT(error_of(j), Contains("/time/bin_width") && Contains("bin_width_opl"));

  j = base_scene();
  j["shapes"][0].erase("radius");
  CHECK_THAT(error_of(j), Contains("/shapes/0/radius: missing required key 'radius'"));
}

TEST_CASE("scene loader: out-of-range numbers", "[scene_loader]") {
  Json j = base_scene();
  j["media"]["fog"]["sigma_a"] = -0.5;
  CHECK_THAT(error_of(j), Contains("test.json: /media/fog/sigma_a: must be >= 0 (got -0.5)"));

  j = base_scene();
  j["media"]["fog"]["eta"] = 0.9;
  CHECK_THAT(error_of(j), Contains("/media/fog/eta: must be >= 1 (got 0.9)"));

  j = base_scene();
  j["shapes"][0]["material"]["eta"] = 0.5;
  CHECK_THAT(error_of(j), Contains("/shapes/0/material/eta: must be >= 1 (got 0.5)"));

  for (double g : {1.0, -1.5}) {
    j = base_scene();
    j["media"]["fog"]["g"] = g;
    CHECK_THAT(error_of(j), Contains("/media/fog/g: must be in (-1, 1) (got " + Json(g).dump()));
  }

  j = base_scene();
  j["time"]["bins"] = 0;
  CHECK_THAT(error_of(j), Contains("/time/bins: must be in [1, 100000] (got 0)"));

  j = base_scene();
  j["shapes"][1]["material"]["albedo"] = {0.5, 1.2, 0.5};
  CHECK_THAT(error_of(j), Contains("/shapes/1/material/albedo/1: must be in [0, 1] (got 1.2)"));

  j = base_scene();
  j["lights"][0]["intensity"] = {0, 0, 0};
  CHECK_THAT(error_of(j),
             Contains("/lights/0/intensity: must be > 0 in some channel (got [0,0,0])"));

  j = base_scene();
  j["lights"][1]["falloff_start"] = 25;
  CHECK_THAT(error_of(j),
             Contains("/lights/1/falloff_start: must be in [0, 20]") && Contains("(got 25)"));

  // JSON has no infinity; an overflowing literal is reported with its position.
  CHECK_THAT(error_of_text("{\n \"camera\": {\"fov\": 1e999}}"),
             Contains("line 2") && Contains("1e999"));
}

// Catches: reconstruction keys read into the wrong field, defaults that differ from the
// documented ones, and out-of-range kernel settings accepted.
TEST_CASE("scene loader: temporal reconstruction", "[scene_loader]") {
  Json j = base_scene();
  CHECK(load(j).reconstruction.type == femto::TemporalFilter::Kind::Histogram);
  j["time"]["reconstruction"] = "kernel";
  femto::ReconstructionDesc r = load(j).reconstruction;
  CHECK(r.type == femto::TemporalFilter::Kind::Kernel);
  CHECK(r.kernel == femto::TemporalKernel::Perlin);
  CHECK(r.alpha == 0.8);
  CHECK(r.knn == 40);
  CHECK(r.first_pass_spp == 160);
  CHECK(r.bandwidth_ps == 0.0);
  CHECK(r.onset_reflection);
  j["time"]["reconstruction"] = {{"type", "kernel"}, {"kernel", "epanechnikov"}, {"alpha", 1}, {"k", 7},
                                 {"first_pass_spp", 9}, {"bandwidth", 12.5}, {"onset_reflection", false}};
  r = load(j).reconstruction;
  CHECK(r.kernel == femto::TemporalKernel::Epanechnikov);
  CHECK(r.alpha == 1.0);
  CHECK(r.knn == 7);
  CHECK(r.first_pass_spp == 9);
  CHECK(r.bandwidth_ps == 12.5);
  CHECK_FALSE(r.onset_reflection);
  j["time"]["reconstruction"] = {{"type", "kernel"}, {"onset_reflection", "yes"}};
  CHECK_THAT(error_of(j), Contains("/time/reconstruction/onset_reflection: expected true or false"));

  j["time"]["reconstruction"] = {{"type", "kernel"}, {"alpha", 0}};
  CHECK_THAT(error_of(j), Contains("/time/reconstruction/alpha: must be in (0, 1] (got 0)"));
  j["time"]["reconstruction"] = {{"type", "kernel"}, {"k", 0}};
  CHECK_THAT(error_of(j), Contains("/time/reconstruction/k: must be in [1, 100000] (got 0)"));
  j["time"]["reconstruction"] = {{"type", "kernel"}, {"bandwidth", -1}};
  CHECK_THAT(error_of(j), Contains("/time/reconstruction/bandwidth: must be > 0 (got -1)"));
  j["time"]["reconstruction"] = {{"type", "histogram"}, {"alpha", 0.5}};
  CHECK_THAT(error_of(j), Contains("/time/reconstruction/alpha: key 'alpha' does not apply to the histogram"));
  j["time"]["reconstruction"] = {{"type", "kernel"}, {"kernal", "perlin"}};
  CHECK_THAT(error_of(j), Contains("/time/reconstruction/kernal: unknown key") && Contains("kernel"));
  j["time"]["reconstruction"] = 3;
  CHECK_THAT(error_of(j), Contains("/time/reconstruction: expected an object"));
}

TEST_CASE("scene loader: huge film", "[scene_loader]") {
  Json j = base_scene();
  j["camera"]["resolution"] = {16384, 16384};
  j["time"]["bins"] = 100000;
  CHECK_THAT(error_of(j), Contains("/time/bins") && Contains("(got 100000)") && Contains("GiB") &&
                              Contains("16384 x 16384 x 100000"));
}

TEST_CASE("scene loader: time axis units cannot be mixed", "[scene_loader]") {
  Json j = base_scene();
  j["time"]["start_opl"] = 3;
  CHECK_THAT(error_of(j), Contains("/time/start_opl") && Contains("(got 3)"));
  j = base_scene();
  j["time"]["bin_width_opl"] = 0.5;
  CHECK_THAT(error_of(j), Contains("/time/bin_width_opl") && Contains("not both"));
}

TEST_CASE("scene loader: unknown medium names", "[scene_loader]") {
  Json j = base_scene();
  j["shapes"][0]["medium"] = "fgo";
  CHECK_THAT(error_of(j), Contains("/shapes/0/medium: unknown medium 'fgo'") &&
                              Contains("did you mean 'fog'") && Contains("(got \"fgo\")"));
  j = base_scene();
  j["medium"] = "vapour";
  CHECK_THAT(error_of(j), Contains("/medium: unknown medium 'vapour'"));
}

TEST_CASE("scene loader: shape consistency rules", "[scene_loader]") {
  Json j = base_scene();
  j["shapes"][0]["material"]["eta"] = 1.5;  // interior medium has 1.33
  CHECK_THAT(error_of(j), Contains("/shapes/0/material/eta") && Contains("1.5") &&
                              Contains("1.33") && Contains("'fog'"));

  j = base_scene();
  j["shapes"][1]["medium"] = "fog";
  CHECK_THAT(error_of(j), Contains("/shapes/1/medium") && Contains("quad"));

  j = base_scene();
  j["shapes"][2]["medium"] = "fog";  // mirror box
  CHECK_THAT(error_of(j), Contains("/shapes/2/medium") && Contains("opaque"));

  j = base_scene();
  j["shapes"][0]["transform"] = {{"translate", {1, 0, 0}}};
  CHECK_THAT(error_of(j), Contains("/shapes/0/transform") && Contains("sphere"));

  j = base_scene();
  j["shapes"][1].erase("material");
  CHECK_THAT(error_of(j), Contains("/shapes/1: ") && Contains("invisible"));

  j = base_scene();
  j["shapes"][1]["pulse"] = {{"fwhm", 1}};
  CHECK_THAT(error_of(j), Contains("/shapes/1/pulse") && Contains("emission"));

  j = base_scene();
  j["shapes"][2]["max"] = {1, -2, 3};
  CHECK_THAT(error_of(j), Contains("/shapes/2/max") && Contains("[1,-2,3]"));

  j = base_scene();
  j["shapes"][2]["transform"]["scale"] = {1, 0, 1};
  CHECK_THAT(error_of(j), Contains("/shapes/2/transform/scale/1: must be non-zero (got 0)"));
}

TEST_CASE("scene loader: degenerate quad", "[scene_loader]") {
  Json j = base_scene();
  j["shapes"][1]["edge2"] = {4, 0, 0};  // parallel to edge1
  CHECK_THAT(error_of(j),
             Contains("/shapes/1/edge2") && Contains("degenerate") && Contains("(got [4,0,0])"));
  j = base_scene();
  j["shapes"][1]["edge1"] = {0, 0, 0};
  CHECK_THAT(error_of(j), Contains("/shapes/1/edge1") && Contains("(got [0,0,0])"));
}

TEST_CASE("scene loader: no lights", "[scene_loader]") {
  Json j = base_scene();
  j.erase("lights");
  j["shapes"].erase(4);  // the emissive quad
  CHECK_THAT(error_of(j), Contains("/lights: scene has no light"));
  j["lights"] = Json::array();
  CHECK_THAT(error_of(j), Contains("scene has no light"));
}

TEST_CASE("scene loader: mesh files", "[scene_loader]") {
  Json j = base_scene();
  j["shapes"][3]["file"] = "nope.obj";
  CHECK_THAT(error_of(j),
             Contains("/shapes/3/file") && Contains("not found") && Contains("(got \"nope.obj\")"));

  write_file("bad.obj", "v 0 0 0\nv 1 0 0\nv 0 1 zero\nf 1 2 3\n");
  j["shapes"][3]["file"] = "bad.obj";
  CHECK_THAT(error_of(j),
             Contains("/shapes/3/file") && Contains("bad.obj:3:") && Contains("'zero'"));

  // A medium needs a closed surface: one face of the tetrahedron is missing.
  write_file("open.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 1 4 3\n");
  j["shapes"][3]["file"] = "open.obj";
  CHECK_THAT(error_of(j), Contains("/shapes/3/file") && Contains("not closed"));

  // Inward-facing winding is rejected for a medium-bearing mesh.
  write_file("inward.obj",
             "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 2 3\nf 1 4 2\nf 1 3 4\nf 2 4 3\n");
  j["shapes"][3]["file"] = "inward.obj";
  CHECK_THAT(error_of(j), Contains("/shapes/3/file") && Contains("inward"));
}

// Catches: rough-material keys read into the wrong field or with undocumented defaults,
// out-of-range roughness, eta or reflectance accepted, and rough dielectrics or conductors
// escaping the shape rules of their smooth counterparts.
TEST_CASE("scene loader: rough dielectric and rough conductor materials", "[scene_loader]") {
  Json j = base_scene();
  j["shapes"][0]["material"] = {{"type", "rough_dielectric"}, {"eta", 1.33}, {"roughness", 0.3}};
  j["shapes"][1]["material"] = {
      {"type", "rough_conductor"}, {"reflectance", {0.9, 0.6, 0.3}}, {"roughness", 1}};
  j["shapes"][2]["material"] = {{"type", "rough_dielectric"}};
  j["shapes"][3]["material"] = {{"type", "rough_dielectric"}, {"eta", 1.33}};  // the fog's eta
  j["shapes"][4]["material"] = {{"type", "rough_conductor"}};
  SceneDesc s = load(j);
  const femto::MaterialDesc& rd = s.shapes[0].material;
  CHECK(rd.type == femto::MaterialDesc::Type::RoughDielectric);
  CHECK(rd.eta == 1.33);
  CHECK(rd.roughness == 0.3);
  const femto::MaterialDesc& rc = s.shapes[1].material;
  CHECK(rc.type == femto::MaterialDesc::Type::RoughConductor);
  CHECK(rc.reflectance.g == 0.6);
  CHECK(rc.roughness == 1.0);
  CHECK(s.shapes[2].material.eta == 1.5);  // defaults
  CHECK(s.shapes[2].material.roughness == 0.1);
  CHECK(s.shapes[2].interior_medium == -1);
  CHECK(s.shapes[4].material.reflectance.b == 1.0);
  CHECK(s.shapes[4].material.roughness == 0.1);

  // One error per key.
  for (const double r : {0.0, 1.5, -0.1}) {
    Json k = j;
    k["shapes"][0]["material"]["roughness"] = r;
    CHECK_THAT(error_of(k), Contains("/shapes/0/material/roughness: must be in (0, 1] (got " +
                                     Json(r).dump() + ")"));
  }
  Json k = j;
  k["shapes"][1]["material"]["roughness"] = "smooth";
  CHECK_THAT(error_of(k), Contains("/shapes/1/material/roughness: expected a number"));
  k = j;
  k["shapes"][2]["material"]["eta"] = 0.9;
  CHECK_THAT(error_of(k), Contains("/shapes/2/material/eta: must be >= 1 (got 0.9)"));
  k = j;
  k["shapes"][1]["material"]["reflectance"] = {0.5, 1.2, 0.5};
  CHECK_THAT(error_of(k),
             Contains("/shapes/1/material/reflectance/1: must be in [0, 1] (got 1.2)"));
  k = j;
  k["shapes"][1]["material"]["eta"] = 1.5;
  CHECK_THAT(error_of(k), Contains("/shapes/1/material/eta: key 'eta' does not apply to a rough "
                                   "conductor material"));
  k = j;
  k["shapes"][0]["material"]["reflectance"] = 1;
  CHECK_THAT(error_of(k), Contains("/shapes/0/material/reflectance: key 'reflectance' does not "
                                   "apply to a rough dielectric material"));
  k = j;
  k["shapes"][1]["material"] = {{"type", "mirror"}, {"roughness", 0.2}};
  CHECK_THAT(error_of(k), Contains("/shapes/1/material/roughness: key 'roughness' does not apply "
                                   "to a mirror material"));
  k = j;
  k["shapes"][0]["material"]["type"] = "rough_dielectirc";
  CHECK_THAT(error_of(k), Contains("/shapes/0/material/type") &&
                              Contains("did you mean 'rough_dielectric'"));

  // Shape rules: a rough dielectric behaves like a dielectric, a rough conductor like a mirror.
  k = j;
  k["shapes"][1]["material"] = {{"type", "rough_dielectric"}};
  CHECK_THAT(error_of(k), Contains("/shapes/1/material: a rough dielectric needs a closed shape"));
  k = j;
  k["shapes"][0]["material"]["eta"] = 1.5;  // interior medium has 1.33
  CHECK_THAT(error_of(k), Contains("/shapes/0/material/eta: rough dielectric eta 1.5 differs") &&
                              Contains("'fog'"));
  k = j;
  k["shapes"][3]["material"].erase("eta");
  CHECK_THAT(error_of(k), Contains("/shapes/3/material: rough dielectric eta 1.5 (the default)"));
  k = j;
  k["shapes"][2]["medium"] = "fog";  // rough conductor box
  k["shapes"][2]["material"] = {{"type", "rough_conductor"}};
  CHECK_THAT(error_of(k), Contains("/shapes/2/medium") && Contains("opaque"));
  write_file("open.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 1 4 3\n");
  k = j;
  k["shapes"][3]["file"] = "open.obj";
  k["shapes"][3].erase("medium");
  CHECK_THAT(error_of(k), Contains("/shapes/3/file") && Contains("rough dielectric") &&
                              Contains("not closed"));
  k["shapes"][3]["material"] = {{"type", "rough_conductor"}};  // opaque: may be open
  CHECK(load(k).shapes[3].material.type == femto::MaterialDesc::Type::RoughConductor);
}

TEST_CASE("scene loader: JSON syntax errors give line and column", "[scene_loader]") {
  CHECK_THAT(error_of_text("{\n  \"camera\": {\n    \"fov\": 30,,\n  }\n}"),
             Contains("test.json: line 3, column 15: ") && Contains("syntax error"));
  CHECK_THAT(error_of_text("{\n  \"camera\": {\n"), Contains("test.json: line 3, column 1: "));
  CHECK_THAT(error_of_text(""), Contains("test.json: line 1, column 1: "));
}

// A VDB medium named "cloud" (the loader only checks that its file exists; it never parses it).
Json vdb_scene(const Json& cloud) {
  write_file("cloud.vdb", "not parsed by the loader");
  Json j = base_scene();
  j["media"]["cloud"] = cloud;
  j["shapes"].push_back(Json::parse(
      R"({"type": "box", "min": [20, 0, 0], "max": [30, 10, 10], "medium": "cloud"})"));
  return j;
}

Json minimal_vdb() {
  return Json::parse(R"({"type": "vdb", "file": "cloud.vdb", "sigma_t_scale": 0.5})");
}

TEST_CASE("scene loader: vdb media and distance-sampling keys", "[scene_loader]") {
  Json j = vdb_scene(Json::parse(R"({
    "type": "vdb", "file": "cloud.vdb", "density_grid": "smoke", "sigma_t_scale": 0.5,
    "albedo_grid": "a", "eta_grid": "e", "eta": 1.2, "g": 0.4, "interpolation": "trilinear",
    "transform": {"translate": [1, 2, 3], "rotate": [0, 90, 0], "scale": 2},
    "distance_sampling": "mis", "time_uniform_rate": 0.25, "mis_heuristic": "power",
    "connection_sampling": "mis", "direction_sampling": "angular"})"));
  j["media"]["fog"]["distance_sampling"] = "time_uniform";
  j["media"]["fog"]["connection_sampling"] = "line_to_point";
  j["media"]["air"]["connection_sampling"] = "equiangular";
  j["media"]["fog"]["time_uniform_rate"] = 3;
  j["media"]["air"]["distance_sampling"] = "mfp";
  j["medium"] = "cloud";
  const SceneDesc s = load(j);
  REQUIRE(s.media.size() == 3);
  const femto::MediumDesc& m = s.media[2];
  CHECK(s.global_medium == 2);
  CHECK(s.shapes.back().interior_medium == 2);
  CHECK(m.type == femto::MediumDesc::Type::Vdb);
  CHECK(m.vdb.file == (temp_dir() / "cloud.vdb").lexically_normal().string());
  CHECK(m.vdb.density_grid == "smoke");
  CHECK(m.vdb.sigma_t_scale == 0.5);
  CHECK(m.vdb.albedo_grid == "a");
  CHECK(m.vdb.eta_grid == "e");
  CHECK(m.vdb.eta == 1.2);
  CHECK(m.medium.eta == 1.2);
  CHECK(m.medium.g == 0.4);
  CHECK(m.vdb.interpolation == femto::VdbMediumDesc::Interpolation::Trilinear);
  CHECK(m.vdb.transform.translate.z == 3);
  CHECK(m.vdb.transform.rotate_deg.y == 90);
  CHECK(m.vdb.transform.scale.x == 2);
  CHECK(m.vdb.transform.scale.z == 2);
  CHECK(m.sampling == femto::DistanceSampling::Mis);
  CHECK(m.time_uniform_rate == 0.25);
  CHECK(m.mis_heuristic == femto::MisHeuristic::Power);
  CHECK(m.connection == femto::ConnectionSampling::Mis);
  CHECK(m.direction == femto::DirectionSampling::Angular);
  CHECK(s.media[0].connection == femto::ConnectionSampling::LineToPoint);
  CHECK(s.media[0].direction == femto::DirectionSampling::Phase);
  CHECK(s.media[1].connection == femto::ConnectionSampling::Equiangular);
  CHECK(s.media[0].type == femto::MediumDesc::Type::Homogeneous);
  CHECK(s.media[0].sampling == femto::DistanceSampling::TimeUniform);
  CHECK(s.media[0].time_uniform_rate == 3);
  CHECK(s.media[1].sampling == femto::DistanceSampling::Mfp);
  j["media"]["air"]["connection_sampling"] = "auto";
  CHECK(load(j).media[1].connection == femto::ConnectionSampling::Auto);
  // The one-sample mixture takes a time-uniform rate like time_uniform and mis.
  j["media"]["air"]["distance_sampling"] = "mixture";
  j["media"]["air"]["time_uniform_rate"] = 0.5;
  CHECK(load(j).media[1].sampling == femto::DistanceSampling::Mixture);
  CHECK(load(j).media[1].time_uniform_rate == 0.5);

  // Defaults of a minimal vdb medium.
  const SceneDesc d = load(vdb_scene(minimal_vdb()));
  const femto::MediumDesc& md = d.media[2];
  CHECK(md.vdb.density_grid == "density");
  CHECK(md.vdb.albedo == 0.9);
  CHECK(md.vdb.albedo_grid.empty());
  CHECK(md.vdb.eta == 1.0);
  CHECK(md.vdb.eta_grid.empty());
  CHECK(md.medium.g == 0.0);
  CHECK(md.vdb.interpolation == femto::VdbMediumDesc::Interpolation::Nearest);
  CHECK(md.vdb.transform.scale.y == 1);
  CHECK(md.time_uniform_rate == 0.0);  // automatic
  CHECK(md.mis_heuristic == femto::MisHeuristic::Balance);
  CHECK(md.connection == femto::ConnectionSampling::Auto);  // the scene-file defaults
  CHECK(md.sampling == femto::DistanceSampling::Mfp);
  CHECK(md.direction == femto::DirectionSampling::Phase);

  // A constant albedo; a dielectric around a VDB medium of the same eta.
  Json c = minimal_vdb();
  c["albedo"] = 0.25;
  c["eta"] = 1.33;
  j = vdb_scene(c);
  j["shapes"][0]["medium"] = "cloud";  // the dielectric sphere of eta 1.33
  const SceneDesc e = load(j);
  CHECK(e.media[2].vdb.albedo == 0.25);
  CHECK(e.shapes[0].interior_medium == 2);
}

TEST_CASE("scene loader: vdb and distance-sampling errors", "[scene_loader]") {
  const auto err = [](const std::function<void(Json&)>& edit) {
    Json c = minimal_vdb();
    edit(c);
    return error_of(vdb_scene(c));
  };
  CHECK_THAT(err([](Json& c) { c.erase("sigma_t_scale"); }),
             Contains("/media/cloud/sigma_t_scale: missing required key 'sigma_t_scale'"));
  CHECK_THAT(err([](Json& c) { c["sigma_t_scale"] = 0; }),
             Contains("/media/cloud/sigma_t_scale: must be > 0 (got 0)"));
  CHECK_THAT(err([](Json& c) { c.erase("file"); }),
             Contains("/media/cloud/file: missing required key 'file'"));
  CHECK_THAT(err([](Json& c) { c["file"] = "nope.vdb"; }),
             Contains("/media/cloud/file: VDB file not found: ") && Contains("nope.vdb") &&
                 Contains("(got \"nope.vdb\")"));
  CHECK_THAT(err([](Json& c) { c["file"] = ""; }), Contains("/media/cloud/file: must name a VDB file"));
  CHECK_THAT(err([](Json& c) { c["file"] = 3; }), Contains("/media/cloud/file: expected a string"));
  CHECK_THAT(err([](Json& c) { c["density_grid"] = ""; }),
             Contains("/media/cloud/density_grid: must name a grid"));
  CHECK_THAT(err([](Json& c) { c["eta_grid"] = 1.4; }),
             Contains("/media/cloud/eta_grid: expected a string (got 1.4)"));
  CHECK_THAT(err([](Json& c) {
               c["albedo"] = 0.5;
               c["albedo_grid"] = "albedo";
             }),
             Contains("/media/cloud/albedo_grid: give either 'albedo'") && Contains("not both"));
  CHECK_THAT(err([](Json& c) { c["albedo"] = 1.5; }),
             Contains("/media/cloud/albedo: must be in [0, 1] (got 1.5)"));
  CHECK_THAT(err([](Json& c) { c["eta"] = 0.9; }), Contains("/media/cloud/eta: must be >= 1 (got 0.9)"));
  CHECK_THAT(err([](Json& c) { c["g"] = 1; }), Contains("/media/cloud/g: must be in (-1, 1) (got 1)"));
  CHECK_THAT(err([](Json& c) { c["interpolation"] = "cubic"; }),
             Contains("/media/cloud/interpolation: must be one of \"nearest\", \"trilinear\""));
  CHECK_THAT(err([](Json& c) { c["transform"] = {{"scale", 0}}; }),
             Contains("/media/cloud/transform/scale: must be non-zero (got 0)"));
  CHECK_THAT(err([](Json& c) { c["transform"] = {{"shift", {1, 2, 3}}}; }),
             Contains("/media/cloud/transform/shift: unknown key 'shift'"));
  CHECK_THAT(err([](Json& c) { c["sigma_a"] = 0.1; }),
             Contains("/media/cloud/sigma_a: key 'sigma_a' does not apply to a vdb medium"));
  CHECK_THAT(err([](Json& c) { c["sigma_t_scal"] = 0.1; }),
             Contains("unknown key 'sigma_t_scal'") && Contains("did you mean 'sigma_t_scale'"));
  CHECK_THAT(err([](Json& c) { c["type"] = "voxel"; }),
             Contains("/media/cloud/type: must be one of \"homogeneous\", \"vdb\""));

  Json j = base_scene();
  j["media"]["fog"]["file"] = "cloud.vdb";
  CHECK_THAT(error_of(j),
             Contains("/media/fog/file: key 'file' does not apply to a homogeneous medium"));

  // Distance sampling, on both medium types.
  CHECK_THAT(err([](Json& c) { c["distance_sampling"] = "uniform"; }),
             Contains("/media/cloud/distance_sampling: must be one of \"mfp\", \"time_uniform\", \"mis\""));
  CHECK_THAT(err([](Json& c) {
               c["distance_sampling"] = "mfp";
               c["time_uniform_rate"] = 1;
             }),
             Contains("/media/cloud/time_uniform_rate: only applies with") &&
                 Contains("this medium uses \"mfp\"") && Contains("(got 1)"));
  CHECK_THAT(err([](Json& c) {
               c["distance_sampling"] = "time_uniform";
               c["time_uniform_rate"] = 0;
             }),
             Contains("/media/cloud/time_uniform_rate: must be > 0 (got 0)"));
  CHECK_THAT(err([](Json& c) {
               c["distance_sampling"] = "time_uniform";
               c["mis_heuristic"] = "power";
             }),
             Contains("/media/cloud/mis_heuristic: only applies with \"distance_sampling\": \"mis\""));
  CHECK_THAT(err([](Json& c) {
               c["distance_sampling"] = "mis";
               c["mis_heuristic"] = "max";
             }),
             Contains("/media/cloud/mis_heuristic: must be one of \"balance\", \"power\""));
  j = base_scene();
  j["media"]["fog"]["distance_sampling"] = "mfp";
  j["media"]["fog"]["mis_heuristic"] = "balance";
  CHECK_THAT(error_of(j), Contains("/media/fog/mis_heuristic: only applies"));
  j = base_scene();
  j["media"]["air"]["time_uniform_rate"] = 0.5;  // the default distance sampling is mfp
  CHECK_THAT(error_of(j), Contains("/media/air/time_uniform_rate: only applies"));
  j["media"]["air"]["distance_sampling"] = "mis";
  j["media"]["air"]["time_uniform_rate"] = -1;
  CHECK_THAT(error_of(j), Contains("/media/air/time_uniform_rate: must be > 0 (got -1)"));

  // A dielectric around a VDB medium must match its constant eta.
  j = vdb_scene(minimal_vdb());
  j["shapes"][0]["medium"] = "cloud";  // dielectric sphere of eta 1.33, medium eta 1
  CHECK_THAT(error_of(j), Contains("/shapes/0/material/eta") && Contains("'cloud'"));
}

TEST_CASE("obj loader: faces, indices and errors", "[obj_loader]") {
  std::vector<Vec3> v;
  std::vector<std::array<uint32_t, 3>> t;

  femto::load_obj(write_file("pent.obj",
                             "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0.5 1.5 0\nv +0 1 -0e0\n"
                             "g poly\nf 1 2 3 4 5\nl 1 2\n"),
                  v, t);
  REQUIRE(v.size() == 5);
  CHECK(v[3].x == 0.5);
  REQUIRE(t.size() == 3);  // fan around the first corner
  CHECK(t[0] == std::array<uint32_t, 3>{0, 1, 2});
  CHECK(t[2] == std::array<uint32_t, 3>{0, 3, 4});

  femto::load_obj(write_file("tet.obj", kTetObj), v, t);
  REQUIRE(t.size() == 4);
  CHECK(t[2] == std::array<uint32_t, 3>{0, 3, 2});  // from negative indices

  // Forward references are allowed as long as the vertex exists by the end of the file.
  femto::load_obj(write_file("fwd.obj", "f 1 2 3\nv 0 0 0\nv 1 0 0\nv 0 1 0\n"), v, t);
  CHECK(t.size() == 1);

  auto error = [&](const std::string& name, const std::string& text) -> std::string {
    const std::string path = write_file(name, text);
    try {
      femto::load_obj(path, v, t);
    } catch (const InputError& e) {
      return e.what();
    }
    FAIL("expected an InputError for " << name);
    return "";
  };
  CHECK_THAT(error("range.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\n\nf 1 2 9\n"),
             Contains("range.obj:5:") && Contains("9") && Contains("3 vertices"));
  CHECK_THAT(error("neg.obj", "v 0 0 0\nf -1 -2 -3\n"), Contains("neg.obj:2:") && Contains("-2"));
  CHECK_THAT(error("zero.obj", "v 0 0 0\nf 0 1 1\n"), Contains("zero.obj:2:") && Contains("'0'"));
  CHECK_THAT(error("num.obj", "# x\nv 0 0 nan\n"), Contains("num.obj:2:") && Contains("'nan'"));
  CHECK_THAT(error("short.obj", "v 0 0\n"), Contains("short.obj:1:"));
  CHECK_THAT(error("two.obj", "v 0 0 0\nv 1 0 0\nf 1 2\n"), Contains("two.obj:3:"));
  CHECK_THAT(error("slash.obj", "v 0 0 0\nf 1/x 1 1\n"),
             Contains("slash.obj:2:") && Contains("1/x"));
  CHECK_THAT(error("curve.obj", "v 0 0 0\ncurv 0 1 1\n"),
             Contains("curve.obj:2:") && Contains("curv"));
  CHECK_THAT(error("empty.obj", "# nothing\nv 0 0 0\n"),
             Contains("empty.obj") && Contains("no faces"));
  CHECK_THROWS_AS(femto::load_obj((temp_dir() / "missing.obj").string(), v, t), InputError);
}
