// Scene loader: valid scenes land in SceneDesc; each class of bad input raises an InputError
// whose one-line message names the JSON path and the offending value. Media and materials:
// test_scene_loader_media.cpp; the OBJ reader: test_obj_loader.cpp.
#include <catch2/catch.hpp>
#include <filesystem>
#include <fstream>
#include <string>

#include "core/constants.h"
#include "scene_loader_helpers.h"

using namespace femto::test::loader;

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
  j["time"]["reconstruction"] = {{"type", "kernel"},
                                 {"kernel", "epanechnikov"},
                                 {"alpha", 1},
                                 {"k", 7},
                                 {"first_pass_spp", 9},
                                 {"bandwidth", 12.5},
                                 {"onset_reflection", false}};
  r = load(j).reconstruction;
  CHECK(r.kernel == femto::TemporalKernel::Epanechnikov);
  CHECK(r.alpha == 1.0);
  CHECK(r.knn == 7);
  CHECK(r.first_pass_spp == 9);
  CHECK(r.bandwidth_ps == 12.5);
  CHECK_FALSE(r.onset_reflection);
  j["time"]["reconstruction"] = {{"type", "kernel"}, {"onset_reflection", "yes"}};
  CHECK_THAT(error_of(j),
             Contains("/time/reconstruction/onset_reflection: expected true or false"));

  j["time"]["reconstruction"] = {{"type", "kernel"}, {"alpha", 0}};
  CHECK_THAT(error_of(j), Contains("/time/reconstruction/alpha: must be in (0, 1] (got 0)"));
  j["time"]["reconstruction"] = {{"type", "kernel"}, {"k", 0}};
  CHECK_THAT(error_of(j), Contains("/time/reconstruction/k: must be in [1, 100000] (got 0)"));
  j["time"]["reconstruction"] = {{"type", "kernel"}, {"bandwidth", -1}};
  CHECK_THAT(error_of(j), Contains("/time/reconstruction/bandwidth: must be > 0 (got -1)"));
  j["time"]["reconstruction"] = {{"type", "histogram"}, {"alpha", 0.5}};
  CHECK_THAT(error_of(j),
             Contains("/time/reconstruction/alpha: key 'alpha' does not apply to the histogram"));
  j["time"]["reconstruction"] = {{"type", "kernel"}, {"kernal", "perlin"}};
  CHECK_THAT(error_of(j),
             Contains("/time/reconstruction/kernal: unknown key") && Contains("kernel"));
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

  write_temp_file("bad.obj", "v 0 0 0\nv 1 0 0\nv 0 1 zero\nf 1 2 3\n");
  j["shapes"][3]["file"] = "bad.obj";
  CHECK_THAT(error_of(j),
             Contains("/shapes/3/file") && Contains("bad.obj:3:") && Contains("'zero'"));

  // A medium needs a closed surface: one face of the tetrahedron is missing.
  write_temp_file("open.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 1 4 3\n");
  j["shapes"][3]["file"] = "open.obj";
  CHECK_THAT(error_of(j), Contains("/shapes/3/file") && Contains("not closed"));

  // Inward-facing winding is rejected for a medium-bearing mesh.
  write_temp_file("inward.obj",
                  "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 2 3\nf 1 4 2\nf 1 3 4\nf 2 4 3\n");
  j["shapes"][3]["file"] = "inward.obj";
  CHECK_THAT(error_of(j), Contains("/shapes/3/file") && Contains("inward"));
}

TEST_CASE("scene loader: JSON syntax errors give line and column", "[scene_loader]") {
  CHECK_THAT(error_of_text("{\n  \"camera\": {\n    \"fov\": 30,,\n  }\n}"),
             Contains("test.json: line 3, column 15: ") && Contains("syntax error"));
  CHECK_THAT(error_of_text("{\n  \"camera\": {\n"), Contains("test.json: line 3, column 1: "));
  CHECK_THAT(error_of_text(""), Contains("test.json: line 1, column 1: "));
}
