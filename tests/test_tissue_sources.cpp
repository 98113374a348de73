// Tissue-optics sources (docs/tissue.md, "Sources"): beam profiles and the spot source.
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <nlohmann/json.hpp>

#include "core/bsdf/fresnel.h"
#include "core/io/nifti.h"
#include "core/io/npy.h"
#include "core/obj_loader.h"
#include "core/tissue/launch.h"
#include "core/tissue/pulse.h"
#include "core/tissue/scene.h"
#include "core/tissue/simulate.h"
#include "core/transport/tissue_walk.h"
#include "media/label_grid_vdb.h"
#include "run_femto.h"
#include "samplers/stats.h"
#include "temp_dir.h"
#include "tissue_setups.h"

using namespace femto;
using namespace femto::tissue;
using femto::test::tissue_box;

// Catches wrong source profiles: a Gaussian beam's 1/e^2 waist w gives <r^2> = w^2 / 2, a
// uniform disc of radius R gives R^2 / 2 (measured on the far face of a clear slab from the
// exitance image, pixel centres plus h^2/6 for the spread inside a pixel), a Gaussian pulse of
// FWHM f gives exit times with standard deviation f / 2.3548 around offset + n d / c, and an
// isotropic point at the centre of a clear cube sends 1/6 of the light through each face.
TEST_CASE("sources have their documented profiles", "[tissue]") {
  const int n = 100;
  const double h = 0.1;
  for (int type = 0; type < 2; ++type) {
    Setup s = tissue_box(n, n, 1, h, TissueOptics{0, 0, 0, 1.0});
    s.source.type = type == 0 ? Source::Type::Gaussian : Source::Type::Disk;
    s.source.waist = 1.0;
    s.source.radius = 2.0;
    s.source.position = {5, 5, -3};
    s.source.fwhm_ps = 10;
    s.source.offset_ps = 50;
    s.time = TimeAxis{0, 100, 1};
    s.faces = true;
    s.fluence = false;
    s.detectors = {{{5, 5, h}, 100.0, 0.0}};
    s.photons = 20000;
    const Result r = simulate(s);
    const std::vector<float>& img = r.face_exitance[5];
    double w = 0, r2 = 0;
    for (int i = 0; i < n; ++i)
      for (int j = 0; j < n; ++j) {
        const double x = (i + 0.5) * h - 5, y = (j + 0.5) * h - 5,
                     e = img[static_cast<size_t>(i * n + j)];
        w += e, r2 += e * (x * x + y * y + h * h / 6);
      }
    r2 /= w;
    const double expected = type == 0 ? 0.5 : 2.0, N = static_cast<double>(s.photons);
    // Var(r^2): exponential (Gaussian beam): mean^2; uniform disc: R^4/12.
    const double se = type == 0 ? expected / std::sqrt(N) : 4.0 / std::sqrt(12 * N);
    INFO((type == 0 ? "gaussian" : "disk")
         << ": <r^2> " << r2 << " expected " << expected << " +- " << se);
    CHECK(std::abs(r2 - expected) <= 4 * se);
    // Pulse: exit times.
    double m = 0, m2 = 0;
    for (double t : r.detected.time_ps) m += t, m2 += t * t;
    const double k = static_cast<double>(r.detected.size());
    REQUIRE(k == N);
    m /= k;
    const double sd = std::sqrt(m2 / k - m * m), sigma = 10 / 2.3548200450309493;
    const double t_flight = (3 + h) / kSpeedOfLight;  // 3 mm of air, then the slab
    CHECK(std::abs(m - (50 + t_flight)) <= 4 * sigma / std::sqrt(k));
    CHECK(std::abs(sd - sigma) <= 4 * sigma / std::sqrt(2 * k));
  }
  Setup s = tissue_box(10, 10, 10, 1.0, TissueOptics{0, 0, 0, 1.0});
  s.source.type = Source::Type::Isotropic;
  s.source.position = {5, 5, 5};
  s.time = TimeAxis{0, 100, 1};
  s.fluence = false;
  s.photons = 60000;
  const Result r = simulate(s);
  const double N = static_cast<double>(s.photons), se = std::sqrt(N * (1.0 / 6) * (5.0 / 6));
  for (double f : r.balance.escaped_faces) CHECK(std::abs(f - N / 6) <= 4 * se);
}

// Catches a spot source that does not follow the camera scenes' spot light: without falloff
// (falloff_start = cone_angle) every photon has weight 1 and directions are uniform in the cone,
// so an NA of sin 15 deg on the far face of a clear slab accepts (1 - cos 15) / (1 - cos 30) of
// them; with a falloff the launch weights average 1 (a mis-normalised weight is off by the
// cone's solid angle), within 4 standard errors bounded by the largest weight.
TEST_CASE("a spot source emits in its cone with unit mean weight", "[tissue]") {
  Setup s = tissue_box(40, 40, 1, 1.0, TissueOptics{0, 0, 0, 1.0});
  s.source = Source{};
  s.source.type = Source::Type::Spot;
  s.source.position = {20, 20, 0};
  s.source.direction = {0, 0, 1};
  s.source.cone_angle_deg = 30;
  s.source.falloff_start_deg = 30;
  s.time = TimeAxis{0, 1000, 1};
  s.fluence = false;
  s.detectors = {{{20, 20, 1}, 30.0, std::sin(kPi / 12)}};
  s.photons = 40000;
  const Result r = simulate(s);
  const double N = static_cast<double>(s.photons);
  CHECK(r.balance.launched == Approx(N).epsilon(1e-12));
  const double p = (1 - std::cos(kPi / 12)) / (1 - std::cos(kPi / 6));
  INFO("accepted " << r.detected_weight[0] / N << " expected " << p);
  CHECK(std::abs(r.detected_weight[0] / N - p) <= 4 * std::sqrt(p * (1 - p) / N));
  s.source.falloff_start_deg = 10;
  const Result f = simulate(s);
  const double w_max =
      (1 - std::cos(kPi / 6)) / (1 - std::cos(kPi / 18));  // falloff >= the inner cone
  INFO("mean launch weight " << f.balance.launched / N);
  CHECK(std::abs(f.balance.launched / N - 1) <= 4 * std::sqrt(w_max / N));
  CHECK(std::abs(f.balance.residual()) <= 1e-12 * f.balance.launched);
}

// Catches emissive-shape sources that do not emit as the camera scenes' emissive shapes do
// (docs/tissue.md, "Sources"): points uniform over the area (a sphere's height uniform in
// [-R, R], a quad's coordinates along its edges uniform in [0, 1]^2), directions cosine-weighted
// about the outward normal (cos^2 uniform in [0, 1]), every weight 1; chi-square tests on 20
// bins each, with the walk's launch inside a clear box that holds the shape.
TEST_CASE("sphere and quad sources emit from their surface as Lambertian emitters", "[tissue]") {
  for (const Source::Type type : {Source::Type::Sphere, Source::Type::Quad}) {
    Setup s = tissue_box(40, 40, 40, 1.0, TissueOptics{0, 0, 0, 1.0});
    s.source.type = type;
    s.source.position = type == Source::Type::Sphere ? Vec3{20, 21, 19} : Vec3{5, 6, 7};
    s.source.radius = 6;
    s.source.edge1 = {20, 5, 0};
    s.source.edge2 = {0, 0, 25};
    const Vec3 quad_n = normalize(cross(s.source.edge1, s.source.edge2));
    const LabelSpace space(s.volume, false);
    const Emitter emitter(s.source);
    const int N = 40000, bins = 20;
    std::vector<double> where(bins, 0), where2(bins, 0), cos2(bins, 0);
    double worst_off = 0, worst_w = 0;
    for (int i = 0; i < N; ++i) {
      Rng rng = Rng::for_sample(7, static_cast<uint64_t>(i), 0);
      Photon p;
      double specular = 0;
      REQUIRE(launch(s, space, emitter, rng, p, specular));  // the shape is inside the box
      worst_w = std::max(worst_w, std::abs(p.w - 1));
      Vec3 n;
      if (type == Source::Type::Sphere) {
        const Vec3 r = p.x - s.source.position;
        worst_off = std::max(worst_off, std::abs(length(r) - 6));
        n = normalize(r);
        where[static_cast<size_t>(std::min(bins - 1, static_cast<int>((n.z + 1) / 2 * bins)))] += 1;
      } else {
        const Vec3 r = p.x - s.source.position;
        worst_off = std::max(worst_off, std::abs(dot(r, quad_n)));
        const double a = dot(r, s.source.edge1) / length_squared(s.source.edge1),
                     b = dot(r, s.source.edge2) / length_squared(s.source.edge2);
        where[static_cast<size_t>(std::clamp(static_cast<int>(a * bins), 0, bins - 1))] += 1;
        where2[static_cast<size_t>(std::clamp(static_cast<int>(b * bins), 0, bins - 1))] += 1;
        n = quad_n;
      }
      const double c = dot(p.d, n);
      REQUIRE(c >= 0);
      cos2[static_cast<size_t>(std::min(bins - 1, static_cast<int>(c * c * bins)))] += 1;
    }
    CHECK(worst_off < 1e-9);
    CHECK(worst_w < 1e-12);
    const std::vector<double> flat(bins, static_cast<double>(N) / bins);
    for (const auto* h : {&where, &cos2}) {
      const stats::Chi2Result t = stats::chi2_test(*h, flat);
      INFO((type == Source::Type::Sphere ? "sphere" : "quad")
           << (h == &where ? " position" : " cos^2") << ": chi2 " << t.chi2 << ", p " << t.p_value);
      CHECK(t.p_value >= 1e-3);
    }
    if (type == Source::Type::Quad) {
      const stats::Chi2Result t = stats::chi2_test(where2, flat);
      INFO("quad, along edge2: chi2 " << t.chi2 << ", p " << t.p_value);
      CHECK(t.p_value >= 1e-3);
    }
  }
}

// Catches box and mesh sources that do not emit as the camera scenes' emissive boxes and meshes:
// every point on the surface, the faces hit in proportion to their areas (chi-square over the
// box's 6 faces and the icosahedron's 20), directions cosine-weighted about the outward normal
// of the face they leave (cos^2 uniform, chi-square), weights 1. data/meshes/icosahedron.obj,
// a convex unit icosahedron: a point's face is the one whose plane it lies on.
TEST_CASE("box and mesh sources emit from their faces as Lambertian emitters", "[tissue]") {
  for (const Source::Type type : {Source::Type::Box, Source::Type::Mesh}) {
    Setup s = tissue_box(40, 40, 40, 1.0, TissueOptics{0, 0, 0, 1.0});
    s.volume.origin = {-20, -20, -20};
    s.source.type = type;
    s.source.box_min = {-3, -1, 2};
    s.source.box_max = {5, 1, 6};
    load_obj((std::filesystem::path(FEMTO_SOURCE_DIR) / "data/meshes/icosahedron.obj").string(),
             s.source.mesh_vertices, s.source.mesh_triangles);
    // Faces as (unit outward normal, a point on it, area).
    std::vector<Vec3> normal, point;
    std::vector<double> area;
    if (type == Source::Type::Box) {
      const Vec3 lo = s.source.box_min, hi = s.source.box_max, e = hi - lo;
      for (int a = 0; a < 3; ++a)
        for (int side = 0; side < 2; ++side) {
          Vec3 n{0, 0, 0};
          n[a] = side ? 1 : -1;
          normal.push_back(n);
          point.push_back(side ? hi : lo);
          area.push_back(e[(a + 1) % 3] * e[(a + 2) % 3]);
        }
    } else {
      for (const auto& t : s.source.mesh_triangles) {
        const Vec3 &a = s.source.mesh_vertices[t[0]], &b = s.source.mesh_vertices[t[1]],
                   &c = s.source.mesh_vertices[t[2]];
        const Vec3 n = cross(b - a, c - a);
        normal.push_back(normalize(n));
        point.push_back(a);
        area.push_back(0.5 * length(n));
      }
    }
    double total_area = 0;
    for (double x : area) total_area += x;
    const LabelSpace space(s.volume, false);
    const Emitter emitter(s.source);
    const int N = 40000, bins = 20;
    std::vector<double> faces(normal.size(), 0), cos2(bins, 0);
    double worst_off = 0, worst_w = 0;
    for (int i = 0; i < N; ++i) {
      Rng rng = Rng::for_sample(9, static_cast<uint64_t>(i), 0);
      Photon p;
      double specular = 0;
      REQUIRE(launch(s, space, emitter, rng, p, specular));
      worst_w = std::max(worst_w, std::abs(p.w - 1));
      // The face whose plane the point lies on: for a convex shape, the largest signed distance.
      size_t f = 0;
      double best = -1e300;
      for (size_t k = 0; k < normal.size(); ++k) {
        const double h = dot(p.x - point[k], normal[k]);
        if (h > best) best = h, f = k;
      }
      worst_off = std::max(worst_off, std::abs(best));
      faces[f] += 1;
      const double c = dot(p.d, normal[f]);
      REQUIRE(c >= 0);
      cos2[static_cast<size_t>(std::min(bins - 1, static_cast<int>(c * c * bins)))] += 1;
    }
    CHECK(worst_off < 1e-9);
    CHECK(worst_w < 1e-12);
    std::vector<double> expected;
    for (double x : area) expected.push_back(N * x / total_area);
    const stats::Chi2Result tf = stats::chi2_test(faces, expected);
    const stats::Chi2Result tc = stats::chi2_test(cos2, std::vector<double>(bins, 1.0 * N / bins));
    INFO((type == Source::Type::Box ? "box" : "mesh")
         << ": faces chi2 " << tf.chi2 << ", p " << tf.p_value << "; cos^2 chi2 " << tc.chi2
         << ", p " << tc.p_value);
    CHECK(tf.p_value >= 1e-3);
    CHECK(tc.p_value >= 1e-3);
  }
}
