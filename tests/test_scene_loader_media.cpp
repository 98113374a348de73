// Scene loader, media and materials: rough BSDF keys, VDB media and the sampling keys, each bad
// value refused with a one-line message that names its JSON path.
#include <catch2/catch.hpp>
#include <functional>
#include <string>

#include "scene_loader_helpers.h"

using namespace femto::test::loader;

namespace {

// A VDB medium named "cloud" (the loader only checks that its file exists; it never parses it).
Json vdb_scene(const Json& cloud) {
  write_temp_file("cloud.vdb", "not parsed by the loader");
  Json j = base_scene();
  j["media"]["cloud"] = cloud;
  j["shapes"].push_back(
      Json::parse(R"({"type": "box", "min": [20, 0, 0], "max": [30, 10, 10], "medium": "cloud"})"));
  return j;
}

Json minimal_vdb() {
  return Json::parse(R"({"type": "vdb", "file": "cloud.vdb", "sigma_t_scale": 0.5})");
}

}  // namespace

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
  CHECK_THAT(error_of(k),
             Contains("/shapes/0/material/type") && Contains("did you mean 'rough_dielectric'"));

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
  write_temp_file("open.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 1 4 3\n");
  k = j;
  k["shapes"][3]["file"] = "open.obj";
  k["shapes"][3].erase("medium");
  CHECK_THAT(error_of(k),
             Contains("/shapes/3/file") && Contains("rough dielectric") && Contains("not closed"));
  k["shapes"][3]["material"] = {{"type", "rough_conductor"}};  // opaque: may be open
  CHECK(load(k).shapes[3].material.type == femto::MaterialDesc::Type::RoughConductor);
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
  CHECK_THAT(err([](Json& c) { c["file"] = ""; }),
             Contains("/media/cloud/file: must name a VDB file"));
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
  CHECK_THAT(err([](Json& c) { c["eta"] = 0.9; }),
             Contains("/media/cloud/eta: must be >= 1 (got 0.9)"));
  CHECK_THAT(err([](Json& c) { c["g"] = 1; }),
             Contains("/media/cloud/g: must be in (-1, 1) (got 1)"));
  CHECK_THAT(err([](Json& c) { c["interpolation"] = "cubic"; }),
             Contains("/media/cloud/interpolation: must be one of \"nearest\", \"trilinear\""));
  CHECK_THAT(err([](Json& c) {
               c["transform"] = {{"scale", 0}};
             }),
             Contains("/media/cloud/transform/scale: must be non-zero (got 0)"));
  CHECK_THAT(err([](Json& c) {
               c["transform"] = {{"shift", {1, 2, 3}}};
             }),
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
  CHECK_THAT(
      err([](Json& c) { c["distance_sampling"] = "uniform"; }),
      Contains(
          "/media/cloud/distance_sampling: must be one of \"mfp\", \"time_uniform\", \"mis\""));
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
  CHECK_THAT(
      err([](Json& c) {
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
