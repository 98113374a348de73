// Mitsuba 3 XML import (core/mitsuba/mitsuba_xml.h, docs/mitsuba.md) and the PLY reader.
#include <catch2/catch.hpp>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <string>
#include <vector>

#include "core/constants.h"
#include "core/error.h"
#include "core/io/ply.h"
#include "core/mitsuba/affine.h"
#include "core/mitsuba/mitsuba_xml.h"
#include "core/render.h"
#include "core/scene_loader.h"
#include "tests/run_femto.h"
#include "tests/temp_dir.h"

using namespace femto;
using Catch::Matchers::Contains;
namespace fs = std::filesystem;

namespace {

const fs::path kData = fs::path(FEMTO_SOURCE_DIR) / "tests" / "data" / "mitsuba";

// Renders a scene the way femto render does with its scene settings (2 threads).
TransientFilm render_desc(SceneDesc desc) {
  std::string why;
  RenderOptions opt;
  opt.integrator = resolve_integrator(desc, desc.integrator.kind, why);
  opt.spp = desc.integrator.spp;
  opt.seed = desc.integrator.seed;
  opt.max_depth = desc.integrator.max_depth;
  opt.threads = 2;
  opt.quiet = true;
  const Scene scene(std::move(desc));
  return render(scene, opt).film;
}

// A minimal valid scene; `body` goes inside <scene> after the sensor.
std::string xml_scene(const std::string& body, const std::string& sensor_extra = "") {
  return "<scene version=\"3.0.0\">\n"               // line 1
         "  <sensor type=\"perspective\">\n"         // line 2
         "    <float name=\"fov\" value=\"40\"/>\n"  // line 3
         "    <transform name=\"to_world\"><lookat origin=\"0, 0, 100\" target=\"0, 0, "
         "0\"/></transform>\n"
         "    <film type=\"transient_hdr_film\">\n"  // line 5
         "      <integer name=\"width\" value=\"8\"/><integer name=\"height\" value=\"6\"/>\n"
         "      <integer name=\"temporal_bins\" value=\"10\"/><float name=\"bin_width_opl\" "
         "value=\"5\"/>\n"
         "    </film>\n" +  // line 8
         sensor_extra +
         "  </sensor>\n"
         "  <emitter type=\"point\"><point name=\"position\" value=\"0, 0, 50\"/></emitter>\n" +
         body + "</scene>\n";
}

// The InputError message for `xml` (checked to be one line naming the file).
std::string xml_error_of(const std::string& xml) {
  try {
    load_mitsuba_xml(xml, "bad.xml", ".");
  } catch (const InputError& e) {
    const std::string msg = e.what();
    CHECK(msg.find('\n') == std::string::npos);
    CHECK_THAT(msg, Contains("bad.xml:"));
    return msg;
  }
  FAIL("expected an InputError for:\n" << xml);
  return "";
}

}  // namespace

static bool same(const Vec3& a, const Vec3& b) {
  return a.x == b.x && a.y == b.y && a.z == b.z;
}
static bool same(const RGB& a, const RGB& b) {
  return a.r == b.r && a.g == b.g && a.b == b.b;
}

// Every field the renderer reads, compared exactly (also those whose effect the small film
// might not show).
static void check_same_scene(const SceneDesc& a, const SceneDesc& b) {
  CHECK(same(a.camera.position, b.camera.position));
  CHECK(same(a.camera.look_at, b.camera.look_at));
  CHECK(same(a.camera.up, b.camera.up));
  CHECK(a.camera.fov_deg == b.camera.fov_deg);
  CHECK(a.time.t_start_ps == b.time.t_start_ps);
  CHECK(a.time.bin_width_ps == b.time.bin_width_ps);
  CHECK(a.time.bins == b.time.bins);
  CHECK(a.time_mode == b.time_mode);
  CHECK(a.global_medium == b.global_medium);
  REQUIRE(a.media.size() == b.media.size());
  for (std::size_t i = 0; i < a.media.size(); ++i) {
    INFO("medium " << i);
    CHECK(a.media[i].medium.sigma_a == b.media[i].medium.sigma_a);
    CHECK(a.media[i].medium.sigma_s == b.media[i].medium.sigma_s);
    CHECK(a.media[i].medium.g == b.media[i].medium.g);
    CHECK(a.media[i].medium.eta == b.media[i].medium.eta);
  }
  REQUIRE(a.shapes.size() == b.shapes.size());
  for (std::size_t i = 0; i < a.shapes.size(); ++i) {
    INFO("shape " << i);
    const ShapeDesc &x = a.shapes[i], &y = b.shapes[i];
    CHECK(x.type == y.type);
    CHECK(same(x.center, y.center));
    CHECK(x.radius == y.radius);
    REQUIRE(x.vertices.size() == y.vertices.size());
    for (std::size_t k = 0; k < x.vertices.size(); ++k) CHECK(same(x.vertices[k], y.vertices[k]));
    CHECK(x.triangles == y.triangles);
    CHECK(x.material.type == y.material.type);
    CHECK(same(x.material.albedo, y.material.albedo));
    CHECK(same(x.material.reflectance, y.material.reflectance));
    CHECK(x.material.eta == y.material.eta);
    CHECK(x.material.roughness == y.material.roughness);
    CHECK(x.interior_medium == y.interior_medium);
    CHECK(x.emissive == y.emissive);
    CHECK(same(x.emission, y.emission));
  }
  REQUIRE(a.lights.size() == b.lights.size());
  for (std::size_t i = 0; i < a.lights.size(); ++i) {
    INFO("light " << i);
    const LightDesc &x = a.lights[i], &y = b.lights[i];
    CHECK(x.type == y.type);
    CHECK(same(x.position, y.position));
    CHECK(same(x.direction, y.direction));
    CHECK(same(x.intensity, y.intensity));
    CHECK(x.cone_angle_deg == y.cone_angle_deg);
    CHECK(x.falloff_deg == y.falloff_deg);
  }
  CHECK(a.integrator.spp == b.integrator.spp);
  CHECK(a.integrator.max_depth == b.integrator.max_depth);
  CHECK(a.integrator.max_depth_set == b.integrator.max_depth_set);
  CHECK(a.integrator.seed == b.integrator.seed);
  CHECK(a.integrator.kind == b.integrator.kind);
}

// Catches: any mapping error between the two formats (camera frame, fov axis, time axis and
// camera_unwarp, media coefficients and their scale, dielectric eta on the interior medium, the
// rectangle/cube/sphere/mesh placements, BSDF and light parameters, max_depth offset, spp and
// seed): every scene field is compared exactly, and the films bit for bit.
TEST_CASE("mitsuba xml: the twin scene renders to the same bits as its femto JSON", "[mitsuba]") {
  const MitsubaImport xml = load_mitsuba_xml(read_scene_text((kData / "twin.xml").string()),
                                             (kData / "twin.xml").string(), kData.string());
  const SceneDesc json = load_scene_file((kData / "twin.json").string());
  REQUIRE(xml.desc.shapes.size() == json.shapes.size());
  REQUIRE(xml.desc.media.size() == json.media.size());
  CHECK(xml.desc.integrator.max_depth == 7);
  CHECK(xml.desc.time_mode == TimeMode::Unwarp);
  CHECK(xml.desc.media[1].medium.eta == 1.5);
  check_same_scene(xml.desc, json);
  const TransientFilm a = render_desc(xml.desc);
  const TransientFilm b = render_desc(json);
  REQUIRE(a.width() == 16);
  REQUIRE(a.height() == 12);
  REQUIRE(a.bins() == 32);
  const std::size_t n = static_cast<std::size_t>(a.width()) * a.height() * a.bins() * 3;
  double sum = 0;
  for (std::size_t i = 0; i < n; ++i) sum += a.transient()[i];
  CHECK(sum > 0);  // a black film would match trivially
  CHECK(std::memcmp(a.transient(), b.transient(), n * sizeof(float)) == 0);
  // rr_depth and near_clip are accepted and reported as not used.
  REQUIRE(xml.desc.warnings.size() == 2);
  CHECK_THAT(xml.desc.warnings[0], Contains("near_clip") && Contains("not used"));
  CHECK_THAT(xml.desc.warnings[1], Contains("rr_depth") && Contains("Russian roulette"));
}

// Catches: a wrong conversion of Mitsuba's horizontal/diagonal fov to femto's vertical one.
TEST_CASE("mitsuba xml: fov_axis becomes femto's vertical field of view", "[mitsuba]") {
  const double t = std::tan(30.0 * kPi / 180.0);  // fov 60; the film is 8 x 6
  const auto vertical = [&](const std::string& axis) {
    std::string xml = xml_scene("", "");
    const std::string fov40 = "<float name=\"fov\" value=\"40\"/>";
    xml.replace(
        xml.find(fov40), fov40.size(),
        "<float name=\"fov\" value=\"60\"/><string name=\"fov_axis\" value=\"" + axis + "\"/>");
    return load_mitsuba_xml(xml, "fov.xml", ".").desc.camera.fov_deg;
  };
  CHECK(vertical("x") == Approx(2 * std::atan(t * 6 / 8) * 180 / kPi).epsilon(1e-12));
  CHECK(vertical("y") == 60.0);
  CHECK(vertical("diagonal") == Approx(2 * std::atan(t * 6 / 10) * 180 / kPi).epsilon(1e-12));
  CHECK(vertical("smaller") == 60.0);
  CHECK(vertical("larger") == Approx(vertical("x")).epsilon(1e-15));
}

// Catches: femto_unit_mm not scaling lengths, OPL, coefficients and point intensities
// consistently (the image must not change with the unit, only the time labels).
TEST_CASE("mitsuba xml: femto_unit_mm scales lengths, OPL, media and intensities", "[mitsuba]") {
  const std::string body =
      "  <medium type=\"homogeneous\" id=\"fog\"><float name=\"sigma_t\" value=\"0.5\"/></medium>\n"
      "  <shape type=\"sphere\"><float name=\"radius\" value=\"2\"/></shape>\n"
      "  <emitter type=\"spot\"><transform name=\"to_world\"><translate "
      "x=\"1\"/></transform></emitter>\n";
  std::string xml = xml_scene(body, "    <ref id=\"fog\"/>\n");
  const SceneDesc one = load_mitsuba_xml(xml, "u.xml", ".").desc;
  xml.insert(xml.find('\n') + 1, "  <default name=\"femto_unit_mm\" value=\"1000\"/>\n");
  const SceneDesc km = load_mitsuba_xml(xml, "u.xml", ".").desc;
  CHECK(km.shapes[0].radius == 1000 * one.shapes[0].radius);
  CHECK(km.camera.position.z == 1000 * one.camera.position.z);
  CHECK(km.time.bin_width_ps == Approx(1000 * one.time.bin_width_ps).epsilon(1e-14));
  CHECK(km.media[0].medium.sigma_t() ==
        Approx(one.media[0].medium.sigma_t() / 1000).epsilon(1e-14));
  CHECK(km.media[0].medium.albedo() == Approx(0.75).epsilon(1e-14));  // Mitsuba's default albedo
  CHECK(km.lights[0].intensity.r == 1e6 * one.lights[0].intensity.r);
  CHECK(km.lights[1].position.x == 1000.0);
  CHECK(km.lights[1].cone_angle_deg == 20.0);  // Mitsuba's spot defaults
  CHECK(km.lights[1].falloff_deg == 15.0);
  CHECK(km.time.bin_width_ps == Approx(5000 / kSpeedOfLight).epsilon(1e-14));
}

// Catches: the decomposition of a to_world matrix into femto's scale / rotate / translate.
TEST_CASE("mitsuba xml: rotations in to_world reach femto's shape transform", "[mitsuba]") {
  using mitsuba::Affine;
  const Affine m = Affine::translate({5, -3, 2}) * Affine::rotate(normalize(Vec3(1, 2, 3)), 70) *
                   Affine::scale({2, 3, 4});
  mitsuba::SplitTransform st;
  REQUIRE(mitsuba::split(m, st));
  // Rebuild with femto's order: scale, rotate about x, y, z, translate.
  const Affine r = Affine::translate(st.translate) * Affine::rotate({0, 0, 1}, st.rotate_deg.z) *
                   Affine::rotate({0, 1, 0}, st.rotate_deg.y) *
                   Affine::rotate({1, 0, 0}, st.rotate_deg.x) * Affine::scale(st.scale);
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 4; ++j) CHECK(r.m[i][j] == Approx(m.m[i][j]).margin(1e-12));
  // Shear is refused.
  Affine shear;
  shear.m[0][1] = 0.5;
  CHECK_FALSE(mitsuba::split(shear, st));

  // And a rotated cube lands where Mitsuba puts it: corner (1, 1, 1) after rotate z 90.
  const std::string body =
      "  <shape type=\"cube\"><transform name=\"to_world\"><rotate z=\"1\" angle=\"90\"/>"
      "<translate x=\"10\"/></transform></shape>\n";
  const SceneDesc d = load_mitsuba_xml(xml_scene(body), "r.xml", ".").desc;
  bool found = false;
  for (const Vec3& v : d.shapes[0].vertices)
    found |= std::abs(v.x - 9) < 1e-12 && std::abs(v.y - 1) < 1e-12 && std::abs(v.z - 1) < 1e-12;
  CHECK(found);  // rotate z 90 maps (1, 1, 1) to (-1, 1, 1), then x + 10
}

// Catches: wrong mappings of the elements the twin scene does not use: rough dielectrics with
// named indices, lights placed by general transforms, flipped rectangles, exterior media.
TEST_CASE("mitsuba xml: rough dielectric, named ior, placed lights, flip_normals", "[mitsuba]") {
  const std::string body =
      "  <shape type=\"sphere\">\n"
      "    <bsdf type=\"roughdielectric\"><string name=\"distribution\" value=\"ggx\"/>\n"
      "      <float name=\"alpha\" value=\"0.3\"/><string name=\"int_ior\" value=\"water\"/>\n"
      "      <string name=\"ext_ior\" value=\"vacuum\"/></bsdf>\n"
      "    <medium type=\"homogeneous\" name=\"interior\"><float name=\"sigma_t\" "
      "value=\"0.5\"/></medium>\n"
      "    <ref name=\"exterior\" id=\"fog\"/>\n"
      "  </shape>\n"
      "  <shape type=\"rectangle\"><boolean name=\"flip_normals\" value=\"true\"/>\n"
      "    <emitter type=\"area\"><rgb name=\"radiance\" value=\"1, 2, 3\"/></emitter></shape>\n"
      "  <emitter type=\"spot\"><transform name=\"to_world\"><rotate x=\"1\" angle=\"90\"/>\n"
      "    <translate y=\"4\"/></transform><float name=\"cutoff_angle\" value=\"40\"/></emitter>\n"
      "  <emitter type=\"point\"><transform name=\"to_world\"><translate value=\"1, 2, "
      "3\"/></transform>\n"
      "    <ref id=\"fog\"/></emitter>\n"
      "  <medium type=\"homogeneous\" id=\"fog\"><float name=\"sigma_t\" "
      "value=\"0.25\"/></medium>\n";
  const SceneDesc d =
      load_mitsuba_xml(xml_scene(body, "    <ref id=\"fog\"/>\n"), "m.xml", ".").desc;
  REQUIRE(d.shapes.size() == 2);
  CHECK(d.shapes[0].material.type == MaterialDesc::Type::RoughDielectric);
  CHECK(d.shapes[0].material.eta == 1.333);  // Mitsuba's "water" over "vacuum"
  CHECK(d.shapes[0].material.roughness == 0.3);
  REQUIRE(d.shapes[0].interior_medium == 1);
  CHECK(d.media[1].medium.eta == 1.333);
  CHECK(d.global_medium == 0);
  // A flipped rectangle faces -z.
  const ShapeDesc& q = d.shapes[1];
  const Vec3 nrm = cross(q.vertices[q.triangles[0][1]] - q.vertices[q.triangles[0][0]],
                         q.vertices[q.triangles[0][2]] - q.vertices[q.triangles[0][0]]);
  CHECK(nrm.z < 0);
  CHECK(q.emission.b == 3.0);
  // The spot looks along its local +z turned by rotate x 90, which is -y.
  REQUIRE(d.lights.size() == 3);
  CHECK(d.lights[1].type == LightDesc::Type::Spot);
  CHECK(d.lights[1].position.y == 4.0);
  CHECK(d.lights[1].direction.y == Approx(-1.0).epsilon(1e-12));
  CHECK(d.lights[1].cone_angle_deg == 40.0);
  CHECK(d.lights[2].position.z == 3.0);
  // A <lookat> without 'up' takes Mitsuba's generated perpendicular: +x when looking down -z.
  CHECK(d.camera.up.x == 1.0);
  CHECK(d.camera.up.y == 0.0);
}

// Catches: a constant emitter changing the scene (mitransient puts its light at infinite path
// length, outside every bin), or not being reported.
TEST_CASE("mitsuba xml: a constant emitter is left out with a warning", "[mitsuba]") {
  const SceneDesc with =
      load_mitsuba_xml(
          xml_scene(
              "  <emitter type=\"constant\"><rgb name=\"radiance\" value=\"0.5\"/></emitter>\n"),
          "c.xml", ".")
          .desc;
  const SceneDesc without = load_mitsuba_xml(xml_scene(""), "c.xml", ".").desc;
  CHECK(with.lights.size() == without.lights.size());
  CHECK(with.shapes.size() == without.shapes.size());
  REQUIRE(with.warnings.size() == 1);
  CHECK_THAT(with.warnings[0], Contains("c.xml:11: <emitter type=\"constant\">: left out"));
}

// Catches: elements outside the subset silently ignored, and messages that do not locate the
// problem (file, line, element, attribute or value).
TEST_CASE("mitsuba xml: bad input names the file, line and element", "[mitsuba]") {
  // Line 11 is the first line of `body` (xml_scene's layout).
  const auto body_error = [](const std::string& body) { return xml_error_of(xml_scene(body)); };
  CHECK_THAT(body_error("  <shape type=\"sphere\"><bsdf type=\"plastic\"/></shape>\n"),
             Contains("bad.xml:11: <bsdf type=\"plastic\">: unsupported bsdf \"plastic\""));
  CHECK_THAT(body_error("  <shape type=\"disk\"/>\n"),
             Contains("bad.xml:11: <shape type=\"disk\">: unsupported shape \"disk\""));
  CHECK_THAT(
      body_error(
          "  <shape type=\"sphere\">\n    <float name=\"radius\" valeu=\"2\"/>\n  </shape>\n"),
      Contains("bad.xml:12: <float name=\"radius\">: unknown attribute 'valeu'"));
  CHECK_THAT(
      body_error("  <shape type=\"sphere\"><float name=\"radius\" value=\"2cm\"/></shape>\n"),
      Contains("bad.xml:11: <float name=\"radius\">: attribute 'value': expected a finite number "
               "(got \"2cm\")"));
  CHECK_THAT(body_error("  <shape type=\"sphere\"><ref id=\"glass\"/></shape>\n"),
             Contains("bad.xml:11: <ref id=\"glass\">: reference to an unknown id \"glass\""));
  CHECK_THAT(
      body_error("  <shape type=\"sphere\"><float name=\"radius\" value=\"$r\"/></shape>\n"),
      Contains("bad.xml:11: <float name=\"radius\">: attribute 'value': undefined variable $r"));
  CHECK_THAT(body_error("  <shape type=\"sphere\"><float name=\"radius\" value=\"-1\"/></shape>\n"),
             Contains("bad.xml:11: <float name=\"radius\">: radius must be > 0 (got -1)"));
  CHECK_THAT(body_error("  <shape type=\"sphere\"><float name=\"radiuss\" value=\"1\"/></shape>\n"),
             Contains("bad.xml:11: <float name=\"radiuss\">: property 'radiuss' is not supported "
                      "for <shape type=\"sphere\">"));
  CHECK_THAT(body_error("  <emitter type=\"envmap\"/>\n"),
             Contains("bad.xml:11: <emitter type=\"envmap\">: unsupported emitter"));
  CHECK_THAT(
      body_error("  <texture type=\"bitmap\" id=\"t\"/>\n"),
      Contains("bad.xml:11: <texture type=\"bitmap\" id=\"t\">: textures are not supported"));
  CHECK_THAT(
      body_error(
          "  <shape type=\"cube\"><medium type=\"homogeneous\" name=\"interior\">"
          "<rgb name=\"albedo\" value=\"0.9, 0.5, 0.5\"/></medium><bsdf type=\"null\"/></shape>\n"),
      Contains("bad.xml:11: <rgb name=\"albedo\">: femto media are grey"));
  CHECK_THAT(
      body_error("  <shape type=\"cube\"><bsdf type=\"roughconductor\"/></shape>\n"),
      Contains("bad.xml:11: <bsdf type=\"roughconductor\">: femto's rough surfaces use the GGX"));
  CHECK_THAT(
      body_error("  <shape type=\"sphere\"><bsdf type=\"null\"/></shape>\n"),
      Contains(
          "bad.xml:11: <shape type=\"sphere\">: a shape with a null bsdf and no interior medium"));
  CHECK_THAT(
      body_error(
          "  <shape type=\"obj\"><string name=\"filename\" value=\"nowhere.obj\"/></shape>\n"),
      Contains("bad.xml:11: <string name=\"filename\">: mesh file not found"));
  // A value only femto's loader checks is reported at the XML element it came from.
  CHECK_THAT(
      body_error("  <shape type=\"sphere\">\n    <emitter type=\"area\"><rgb name=\"radiance\" "
                 "value=\"0\"/></emitter>\n  </shape>\n"),
      Contains(
          "bad.xml:12: <emitter type=\"area\">: must be > 0 in some channel (got [0.0,0.0,0.0]) "
          "(femto scene key /shapes/0/emission)"));
  // Structure.
  CHECK_THAT(xml_error_of("<scene version=\"3.0.0\">\n  <shape type=\"sphere\">\n</scene>\n"),
             Contains("bad.xml:3: XML syntax error"));
  CHECK_THAT(xml_error_of("<scene>\n  <bogus/>\n</scene>\n"),
             Contains("bad.xml:2: <bogus>: unsupported element <bogus> at the scene level"));
  CHECK_THAT(xml_error_of("<scene>\n</scene>\n"),
             Contains("bad.xml:1: <scene>: the scene has no <sensor>"));
  std::string dark = xml_scene("");
  const std::size_t e0 = dark.find("  <emitter"), e1 = dark.find("</emitter>\n") + 11;
  dark.erase(e0, e1 - e0);
  CHECK_THAT(xml_error_of(dark), Contains("bad.xml:1: <scene>: the scene has no emitter"));
  // A constant emitter alone: left out (infinite arrival time), so there is no light.
  dark.insert(dark.find("</scene>"), "  <emitter type=\"constant\"/>\n");
  CHECK_THAT(xml_error_of(dark), Contains("a constant emitter adds nothing to the time bins"));
  std::string steady = xml_scene("");
  steady.replace(steady.find("transient_hdr_film"), 18, "hdrfilm");
  CHECK_THAT(xml_error_of(steady),
             Contains("bad.xml:5: <film type=\"hdrfilm\">: unsupported film \"hdrfilm\""));
  CHECK_THAT(xml_error_of(xml_scene("  <integrator type=\"path\"/>\n")),
             Contains("bad.xml:11: <integrator type=\"path\">: unsupported integrator \"path\""));
  CHECK_THAT(
      xml_error_of(xml_scene("  <integrator type=\"transient_path\"><integer name=\"max_depth\" "
                             "value=\"1\"/></integrator>\n")),
      Contains("bad.xml:11: <integer name=\"max_depth\">: max_depth must be -1 (no bound) "
               "or in [2, 1000001]"));
  // Names become JSON strings: bytes that are not UTF-8 are refused (a fuzzer finding).
  CHECK_THAT(xml_error_of("<scene>\n  <shape id=\"a\xff\"/>\n</scene>\n"),
             Contains("bad.xml:2: the file is not valid UTF-8"));
  CHECK_THAT(xml_error_of(xml_scene(
                 "  <shape type=\"obj\"><string name=\"filename\" value=\"\xc3\"/></shape>\n")),
             Contains("bad.xml:11: the file is not valid UTF-8"));
  // The error type is InputError (exit code 2 in the CLI).
  CHECK_THROWS_AS(load_mitsuba_xml(xml_scene("  <shape type=\"torus\"/>\n"), "bad.xml", "."),
                  InputError);
}

// Catches: a reference cycle recursing without end.
TEST_CASE("mitsuba xml: a reference cycle is an error", "[mitsuba]") {
  CHECK_THAT(xml_error_of(xml_scene("  <bsdf type=\"twosided\" id=\"a\"><ref id=\"a\"/></bsdf>\n"
                                "  <shape type=\"sphere\"><ref id=\"a\"/></shape>\n")),
             Contains("references nest too deep"));
}

// Catches: PLY encodings read differently, polygons not fanned, unchecked indices.
TEST_CASE("ply: ascii and binary little-endian files give the same mesh", "[mitsuba][ply]") {
  test::TempDir tmp("femto_ply");
  const std::string header_common =
      "element vertex 4\nproperty float x\nproperty float y\nproperty float z\n"
      "element face 2\nproperty list uchar uint vertex_indices\nend_header\n";
  test::write_file(tmp.dir / "a.ply", "ply\nformat ascii 1.0\n" + header_common +
                                          "0 0 0\n1 0 0\n1 1 0\n0 1 0\n4 0 1 2 3\n3 0 2 3\n");
  std::string bin = "ply\nformat binary_little_endian 1.0\n" + header_common;
  const float v[12] = {0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0};
  for (float f : v) {
    unsigned char b[4];
    std::memcpy(b, &f, 4);  // the test hosts are little-endian (x86-64, arm64)
    bin.append(reinterpret_cast<const char*>(b), 4);
  }
  const auto put_face = [&](std::vector<uint32_t> idx) {
    bin += static_cast<char>(idx.size());
    for (uint32_t i : idx) bin.append(reinterpret_cast<const char*>(&i), 4);
  };
  put_face({0, 1, 2, 3});
  put_face({0, 2, 3});
  test::write_file(tmp.dir / "b.ply", bin);
  std::vector<Vec3> va, vb;
  std::vector<std::array<uint32_t, 3>> ta, tb;
  load_ply((tmp.dir / "a.ply").string(), va, ta);
  load_ply((tmp.dir / "b.ply").string(), vb, tb);
  REQUIRE(va.size() == 4);
  REQUIRE(ta.size() == 3);  // the quad as a fan of two, then the triangle
  CHECK(ta[0] == std::array<uint32_t, 3>{0, 1, 2});
  CHECK(ta[1] == std::array<uint32_t, 3>{0, 2, 3});
  CHECK(va[2].x == 1.0);
  CHECK(va[2].y == 1.0);
  CHECK(ta == tb);
  for (std::size_t i = 0; i < 4; ++i) {
    CHECK(va[i].x == vb[i].x);
    CHECK(va[i].y == vb[i].y);
    CHECK(va[i].z == vb[i].z);
  }

  // Bad files: each an InputError naming the file.
  const auto ply_error = [&](const std::string& text) {
    test::write_file(tmp.dir / "bad.ply", text);
    try {
      load_ply((tmp.dir / "bad.ply").string(), va, ta);
    } catch (const InputError& e) {
      CHECK_THAT(e.what(), Contains("bad.ply"));
      return std::string(e.what());
    }
    FAIL("expected an InputError");
    return std::string();
  };
  CHECK_THAT(ply_error("ply\nformat binary_big_endian 1.0\nend_header\n"), Contains("big-endian"));
  CHECK_THAT(ply_error("ply\nformat ascii 1.0\n" + header_common +
                       "0 0 0\n1 0 0\n1 1 0\n0 1 0\n3 0 1 7\n3 0 1 2\n"),
             Contains("vertex index 7 out of range"));
  CHECK_THAT(ply_error("ply\nformat ascii 1.0\n" + header_common + "0 0 0\n1 0 0\n"),
             Contains("file ends inside the data"));
  CHECK_THAT(ply_error("ply\nformat ascii 1.0\nelement vertex 1000000000\nproperty float "
                       "x\nproperty float y\nproperty float z\nend_header\n"),
             Contains("exceeds the file's data"));
  CHECK_THAT(ply_error("obj\n"), Contains("not a PLY file"));
}

// Catches: the example scene drifting out of the supported subset or rendering black.
TEST_CASE("mitsuba xml: the example scene data/scenes/mitsuba_fog.xml renders", "[mitsuba]") {
  const fs::path file = fs::path(FEMTO_SOURCE_DIR) / "data" / "scenes" / "mitsuba_fog.xml";
  SceneDesc desc = load_scene_file(file.string());
  CHECK(desc.global_medium >= 0);
  desc.camera.width = 24;
  desc.camera.height = 18;
  desc.integrator.spp = 2;
  const TransientFilm f = render_desc(std::move(desc));
  double sum = 0;
  const std::size_t n = static_cast<std::size_t>(f.width()) * f.height() * f.bins() * 3;
  for (std::size_t i = 0; i < n; ++i) {
    REQUIRE(std::isfinite(f.transient()[i]));
    sum += f.transient()[i];
  }
  CHECK(sum > 0);
}

// Catches: the CLI not dispatching .xml scenes, or a bad XML scene not giving exit code 2.
TEST_CASE("mitsuba xml: femto render and femto info on XML scenes", "[mitsuba][cli]") {
  test::TempDir tmp("femto_xml_cli");
  const test::Run info = test::run_femto({"info", (kData / "twin.xml").string()}, tmp.dir);
  CHECK(info.code == 0);
  CHECK_THAT(info.out, Contains("32 bins"));
  CHECK_THAT(info.err, Contains("femto: warning:") && Contains("rr_depth"));

  const test::Run ok = test::run_femto({"render", (kData / "twin.xml").string(), "--out",
                                        (tmp.dir / "out").string(), "--no-previews", "--quiet"},
                                       tmp.dir);
  CHECK(ok.code == 0);
  CHECK(fs::exists(tmp.dir / "out" / "render.json"));
  // render.json records the translated femto scene and the warnings.
  const std::string record = test::read_file(tmp.dir / "out" / "render.json");
  CHECK_THAT(record,
             Contains("\"bin_width_opl\": 16") && Contains("\"warnings\"") && Contains("rr_depth"));

  // -D NAME=VALUE sets $NAME over the file's <default> (the twin's film width is $width).
  const test::Run wide =
      test::run_femto({"info", (kData / "twin.xml").string(), "-D", "width=20"}, tmp.dir);
  CHECK(wide.code == 0);
  CHECK_THAT(wide.out, Contains("20 x 12 pixels"));
  CHECK(test::run_femto({"info", (kData / "twin.xml").string(), "-D", "width"}, tmp.dir).code == 2);
  const test::Run json_d = test::run_femto(
      {"render", FEMTO_SOURCE_DIR "/data/scenes/default.json", "-D", "spp=1"}, tmp.dir);
  CHECK(json_d.code == 2);
  CHECK_THAT(json_d.err, Contains("-D spp: applies to Mitsuba XML scenes (.xml) only"));

  test::write_file(tmp.dir / "bad.xml", xml_scene("  <shape type=\"torus\"/>\n"));
  const test::Run bad = test::run_femto(
      {"render", (tmp.dir / "bad.xml").string(), "--out", (tmp.dir / "bad_out").string()}, tmp.dir);
  CHECK(bad.code == 2);
  CHECK_THAT(bad.err, Contains("bad.xml:11: <shape type=\"torus\">: unsupported shape"));
  CHECK_FALSE(fs::exists(tmp.dir / "bad_out"));
}
