// Emission aimed at the non-diffuse shapes for photons and caustic beams
// (core/transport/caustic_aim.h): its direction sampler against its own pdf, the flux it carries
// into each shape, which lights and shapes it aims at, and renders with and without it.
#include <catch2/catch.hpp>

#include <cmath>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "agreement.h"
#include "core/constants.h"
#include "core/render.h"
#include "core/rng.h"
#include "core/scene.h"
#include "core/scene_loader.h"
#include "core/transport/caustic_aim.h"
#include "hybrid_scenes.h"
#include "run_femto.h"
#include "samplers/stats.h"
#include "temp_dir.h"

using namespace femto;
using namespace femto::test;

namespace {

SceneDesc scene_with(const std::string& shapes, const std::string& lights) {
  return load_scene_string(R"({
    "camera": { "type": "perspective", "position": [0, 0, 200], "look_at": [0, 0, 0], "fov": 40,
                "resolution": [8, 6] },
    "time": { "t_start": 0, "bin_width": 100, "bins": 4 },
    "media": { "haze": { "type": "homogeneous", "sigma_a": 0, "sigma_s": 0.001 } },
    "shapes": [)" + shapes + R"(],
    "lights": [)" + lights + R"(]
  })",
                           "aim", ".");
}

// Two glass spheres, one behind the other, whose cones from the light overlap, a mirror sphere
// apart from them, and a diffuse sphere and an index-matched box that must not be aimed at.
const char* kShapes = R"(
  { "type": "sphere", "center": [0, 0, -50], "radius": 10, "material": { "type": "dielectric", "eta": 1.5 } },
  { "type": "sphere", "center": [7, 0, -90], "radius": 15, "material": { "type": "dielectric", "eta": 1.5 } },
  { "type": "sphere", "center": [0, 60, 0], "radius": 5, "material": { "type": "mirror" } },
  { "type": "sphere", "center": [0, -40, 0], "radius": 8, "material": { "type": "diffuse", "albedo": 0.5 } },
  { "type": "box", "min": [30, -5, -5], "max": [40, 5, 5], "medium": "haze" })";

/// Directions binned in equal solid angles around `axis` up to half-angle theta_max:
/// `nu` bins in 1 - cos(theta), `nphi` in phi.
struct ConeBins {
  Vec3 axis;
  double one_minus_max;
  int nu, nphi;
  int bin(const Vec3& d) const {
    const Frame f(axis);
    const Vec3 l = f.to_local(d);
    const double u = 1 - l.z;
    if (!(u < one_minus_max)) return -1;
    double phi = std::atan2(l.y, l.x) / (2 * kPi);
    if (phi < 0) phi += 1;
    const int i = std::min(nu - 1, static_cast<int>(u / one_minus_max * nu));
    const int j = std::min(nphi - 1, static_cast<int>(phi * nphi));
    return i * nphi + j;
  }
  // Integral of pdf over each bin by a sub x sub midpoint rule in (1 - cos, phi).
  std::vector<double> integrals(const CausticAim& aim, int light, int sub) const {
    const Frame f(axis);
    std::vector<double> out(static_cast<size_t>(nu * nphi), 0.0);
    const double du = one_minus_max / (nu * sub), dphi = 1.0 / (nphi * sub);
    for (int a = 0; a < nu * sub; ++a)
      for (int b = 0; b < nphi * sub; ++b) {
        const double u = (a + 0.5) * du, cos_t = 1 - u, sin_t = std::sqrt(u * (2 - u));
        const double phi = 2 * kPi * (b + 0.5) * dphi;
        const Vec3 d = f.to_world({sin_t * std::cos(phi), sin_t * std::sin(phi), cos_t});
        out[static_cast<size_t>((a / sub) * nphi + b / sub)] +=
            aim.pdf(light, d) * du * 2 * kPi * dphi;
      }
    return out;
  }
};

double one_minus_cos(double deg) {
  return 1 - std::cos(deg * kPi / 180);
}

}  // namespace

// Catches: a cone drawn wider or narrower than the pdf says, cones picked out of proportion to
// their solid angles, a pdf that counts an overlap once (or the drawn cone twice), or a pdf that
// does not integrate to one; and any direction outside every cone.
TEST_CASE("aimed emission matches its own pdf (chi-square)", "[aim][sampler]") {
  const Scene scene(
      scene_with(kShapes, R"({ "type": "point", "position": [0, 0, 0], "intensity": 1 })"));
  const CausticAim aim(scene.desc(), scene.lights());
  REQUIRE(aim.aims(0));
  REQUIRE(aim.cones(0).size() == 3);  // the diffuse sphere and the index-matched box: no cones
  // Around the overlapping pair (their axes 4.4 degrees apart, half-angles 11.5 and 9.6 degrees),
  // and around the mirror sphere.
  const ConeBins pair{normalize(Vec3(3.5, 0, -50)), one_minus_cos(22), 16, 16};
  const ConeBins mirror{Vec3(0, 1, 0), one_minus_cos(5.5), 8, 12};
  const std::vector<double> e_pair = pair.integrals(aim, 0, 24),
                            e_mirror = mirror.integrals(aim, 0, 24);
  double total = 0;
  for (double e : e_pair) total += e;
  for (double e : e_mirror) total += e;
  CHECK(total == Approx(1.0).margin(2e-3));  // the pdf's integral, by quadrature

  const Light& l = scene.lights().light(0);
  const int n = 200000;
  std::vector<double> observed(e_pair.size() + e_mirror.size(), 0.0);
  int outside = 0, weight_mismatch = 0, refused = 0;
  Rng rng = Rng::for_sample(7, 1, 0);
  for (int k = 0; k < n; ++k) {
    LightEmission e;
    const double uc = rng.uniform(), u1 = rng.uniform(), u2 = rng.uniform();
    if (!aim.sample_emission(l, 0, uc, u1, u2, e)) {  // a point light emits everywhere
      ++refused;
      continue;
    }
    const Vec3 d = e.ray.d;
    // The weight is intensity / pdf wherever the pdf is not at a cone's rim.
    const double p = aim.pdf(0, d);
    if (!(p > 0) || std::abs(e.beta.average() * p - 1) > 1e-9) ++weight_mismatch;
    const int b = pair.bin(d), c = mirror.bin(d);
    if (b >= 0)
      observed[static_cast<size_t>(b)] += 1;
    else if (c >= 0)
      observed[e_pair.size() + static_cast<size_t>(c)] += 1;
    else
      ++outside;
  }
  CHECK(refused == 0);
  CHECK(outside == 0);
  CHECK(weight_mismatch <= 2);  // rounding at a rim
  std::vector<double> expected;
  for (double e : e_pair) expected.push_back(e / total * n);
  for (double e : e_mirror) expected.push_back(e / total * n);
  const stats::Chi2Result r = stats::chi2_test(observed, expected);
  INFO("chi2 " << r.chi2 << " over " << r.dof << " dof");
  CHECK(r.p_value > 1e-3);
}

// Catches: weights that do not carry each shape's own flux (a point light's I x solid angle, a
// spot's falloff integrated over the cone): e.g. an overlap of two cones counted twice, a spot's
// falloff left out, or cones of a spot that reach outside it weighted as inside.
TEST_CASE("aimed emission carries the flux each shape receives", "[aim][statistical]") {
  const std::string point = R"({ "type": "point", "position": [0, 0, 0], "intensity": 3 })";
  // A spot pointed near the mirror sphere (17 degrees off), whose cone's edge (falloff from 40
  // degrees, nothing beyond 70) cuts across the pair (62-85 degrees off).
  const std::string spot = R"({ "type": "spot", "position": [0, 0, 0], "direction": [0, 1, -0.3],
      "intensity": 3, "cone_angle": 70, "falloff_start": 40 })";
  for (const std::string& light : {point, spot}) {
    const Scene scene(scene_with(kShapes, light));
    const CausticAim aim(scene.desc(), scene.lights());
    REQUIRE(aim.aims(0));
    const Light& l = scene.lights().light(0);
    const Vec3 centres[3] = {{0, 0, -50}, {7, 0, -90}, {0, 60, 0}};
    const double radii[3] = {10, 15, 5};
    // Exact flux into each sphere: intensity x falloff integrated over its cone (quadrature).
    double exact[3];
    for (int s = 0; s < 3; ++s) {
      const Vec3 axis = normalize(centres[s]);
      const double sin_max = radii[s] / length(centres[s]);
      const double um = 1 - std::sqrt(1 - sin_max * sin_max);
      const Frame f(axis);
      const int m = 400;
      double sum = 0;
      for (int a = 0; a < m; ++a)
        for (int b = 0; b < m; ++b) {
          const double u = (a + 0.5) * um / m, sin_t = std::sqrt(u * (2 - u));
          const double phi = 2 * kPi * (b + 0.5) / m;
          const Vec3 d = f.to_world({sin_t * std::cos(phi), sin_t * std::sin(phi), 1 - u});
          const double falloff =
              l.type == Light::Type::Spot ? spot_falloff(l, dot(d, l.direction)) : 1.0;
          sum += 3 * falloff * um / m * 2 * kPi / m;
        }
      exact[s] = sum;
    }
    const int n = 100000;
    std::vector<double> flux[3];
    for (auto& v : flux) v.assign(n, 0.0);
    Rng rng = Rng::for_sample(11, 2, 0);
    for (int k = 0; k < n; ++k) {
      LightEmission e;
      const double uc = rng.uniform(), u1 = rng.uniform(), u2 = rng.uniform();
      if (!aim.sample_emission(l, 0, uc, u1, u2, e)) continue;  // outside the spot: no light
      for (int s = 0; s < 3; ++s) {
        const Vec3 oc = centres[s];
        const double along = dot(oc, e.ray.d);
        if (along > 0 && length_squared(oc - e.ray.d * along) < radii[s] * radii[s])
          flux[s][static_cast<size_t>(k)] = e.beta.average();
      }
    }
    for (int s = 0; s < 3; ++s) {
      const MeanSE f = mean_se(flux[s]);
      INFO("light " << light << ", sphere " << s << ": " << f.mean << " +- " << f.se << ", exact "
                    << exact[s]);
      CHECK(std::abs(f.mean - exact[s]) < 4 * f.se);
      CHECK(f.se < 0.02 * exact[s]);  // resolves a 8% error
    }
  }
}

// Catches: a light aimed from inside a shape's bounding sphere (directions to the rest of the
// shape would be lost), aiming where the cones cover most of the emission, a spot aimed at shapes
// outside its cone, bounding spheres of triangle shapes that miss a vertex, or lights that cannot
// be aimed (lasers, area lights) treated as aimed.
TEST_CASE("what aimed emission aims at", "[aim]") {
  SECTION("a light inside a bounding sphere is not aimed") {
    const Scene s(
        scene_with(kShapes, R"({ "type": "point", "position": [0, 2, -50], "intensity": 1 })"));
    CHECK_FALSE(CausticAim(s.desc(), s.lights()).aims(0));
  }
  SECTION("cones covering more than half the emission are not aimed") {
    const std::string big = R"(
      { "type": "sphere", "center": [12, 0, 0], "radius": 10, "material": { "type": "mirror" } },
      { "type": "sphere", "center": [-12, 0, 0], "radius": 10, "material": { "type": "mirror" } })";
    const Scene two(
        scene_with(big, R"({ "type": "point", "position": [0, 0, 0], "intensity": 1 })"));
    const CausticAim a2(two.desc(), two.lights());
    REQUIRE(a2.aims(0));  // each cone 2 pi (1 - cos 56.4 deg): 0.45 of the sphere together
    CHECK(a2.solid_angle_ratio(0) == Approx(1 - std::sqrt(1 - 100.0 / 144)).epsilon(1e-5));
    const Scene three(scene_with(big + R"(,
      { "type": "sphere", "center": [0, 12, 0], "radius": 10, "material": { "type": "mirror" } })",
                                 R"({ "type": "point", "position": [0, 0, 0], "intensity": 1 })"));
    CHECK_FALSE(CausticAim(three.desc(), three.lights()).aims(0));
  }
  SECTION("a spot aims only at shapes its cone reaches, and at nothing if none") {
    const Scene s(scene_with(kShapes, R"({ "type": "spot", "position": [0, 0, 0],
        "direction": [0, 0, -1], "intensity": 1, "cone_angle": 30, "falloff_start": 20 })"));
    const CausticAim a(s.desc(), s.lights());
    REQUIRE(a.aims(0));
    CHECK(a.cones(0).size() == 2);  // the pair; the mirror sphere lies at 90 degrees
    const Scene away(scene_with(kShapes, R"({ "type": "spot", "position": [0, 0, 0],
        "direction": [0, 0, 1], "intensity": 1, "cone_angle": 30, "falloff_start": 20 })"));
    const CausticAim b(away.desc(), away.lights());
    REQUIRE(b.aims(0));
    CHECK(b.cones(0).empty());
    LightEmission e;
    CHECK_FALSE(b.sample_emission(away.lights().light(0), 0, 0.5, 0.5, 0.5, e));
  }
  SECTION("a quad's cone holds each of its corners; lasers and area lights are not aimed") {
    const Scene s(scene_with(R"(
      { "type": "quad", "corner": [-20, 30, -10], "edge1": [50, 0, 0], "edge2": [0, 5, -30],
        "material": { "type": "rough_conductor", "roughness": 0.2 } },
      { "type": "sphere", "center": [0, -60, 0], "radius": 3, "emission": 5,
        "material": { "type": "diffuse", "albedo": 0 } })",
                             R"({ "type": "point", "position": [0, 0, 0], "intensity": 1 },
      { "type": "laser", "position": [0, 0, 5], "direction": [0, 1, 0], "radius": 1, "power": 1 })"));
    const CausticAim a(s.desc(), s.lights());
    REQUIRE(s.lights().count() == 3);
    REQUIRE(a.aims(0));
    REQUIRE(a.cones(0).size() == 1);
    for (const Vec3& v : s.desc().shapes[0].vertices) CHECK(a.pdf(0, normalize(v)) > 0);
    CHECK_FALSE(a.aims(1));  // laser
    CHECK_FALSE(a.aims(2));  // the emissive sphere
  }
}

// Catches: aiming not reaching photons or caustic beams (the point of it: from a point light 51
// mm from a glass sphere of radius 12, 1.4% of the directions reach the glass), default counts
// not scaled by that share, or aimed renders that lose or gain light: the same scene with and
// without aiming must agree cell by cell. The hybrid's light-tracing checks of this scene
// (tests/test_hybrid_light_tracing.cpp) run aimed.
TEST_CASE("aimed photons and caustic beams: many more stored, the same image",
          "[aim][hybrid][statistical]") {
  const Scene scene(
      glass_in_fog(R"({ "type": "point", "position": [-30, 80, 0], "intensity": 3000 })", ""));
  RenderOptions opt;
  opt.integrator = IntegratorKind::Hybrid;
  opt.spp = 2;
  opt.threads = 2;
  opt.quiet = true;
  opt.photons.per_pass = 5000;
  const RenderResult on = render(scene, opt);
  opt.photons.aim = false;
  const RenderResult off = render(scene, opt);
  INFO("beams " << on.stats.beams_stored << " / " << off.stats.beams_stored << ", photons "
                << on.stats.photons_stored << " / " << off.stats.photons_stored);
  CHECK(on.photons.aim);
  REQUIRE(on.photons.aim_share.size() == 1);
  CHECK(on.photons.aim_share[0] == Approx(0.0138).epsilon(0.01));
  CHECK_FALSE(off.photons.aim);
  CHECK(on.stats.beams_stored > 30 * off.stats.beams_stored);
  CHECK(on.stats.photons_stored > 30 * off.stats.photons_stored);
  // Chosen counts are emitted as they are; default counts shrink by the share, to the 100 paths
  // a pass at least.
  CHECK(on.photons.per_pass == 5000);
  CHECK(on.photons.aim_paths_scale == 1);
  opt.photons = PhotonDesc{};
  const RenderResult scaled = render(scene, opt);
  const double share = on.photons.aim_share[0];
  CHECK(scaled.photons.aim_paths_scale == share);
  CHECK(scaled.photons.per_pass ==
        std::llround(static_cast<double>(default_hybrid_photons_per_pass(16 * 12)) * share));
  CHECK(scaled.photons.beam_paths == 100);  // 500 x 0.0138, raised to 100

  // Unaimed, 20x the paths per pass for a comparable resolution of the caustic light.
  PhotonDesc pd = progressive(500, 0.8, 1.0);
  const auto aimed = cells(batches(scene, IntegratorKind::Hybrid, 32, 24, 2100, pd), 4, 2);
  pd.per_pass = 10000;
  pd.aim = false;
  const auto plain = cells(batches(scene, IntegratorKind::Hybrid, 32, 24, 2200, pd), 4, 2);
  require_agreement(aimed, plain, 12, 0.03);
}

// Catches: the scene key or the flag not reaching the render, or bad values accepted.
TEST_CASE("photon aim: scene key, flag and render.json", "[aim][cli]") {
  TempDir tmp("femto_aim");
  const std::string scene = R"({
    "camera": { "type": "perspective", "position": [0, 20, 120], "look_at": [0, 10, 0], "fov": 40,
                "resolution": [8, 6] },
    "time": { "t_start": 200, "bin_width": 100, "bins": 4 },
    "shapes": [ { "type": "quad", "corner": [-50, 0, 50], "edge1": [100, 0, 0], "edge2": [0, 0, -100],
                  "material": { "type": "diffuse", "albedo": 0.7 } },
                { "type": "sphere", "center": [0, 20, 0], "radius": 8,
                  "material": { "type": "dielectric", "eta": 1.5 } } ],
    "lights": [ { "type": "point", "position": [-20, 60, 0], "intensity": 100 } ],
    "render": { "integrator": "photons", "photons": { "per_pass": 1000, AIM } }
  })";
  auto with = [&](const std::string& aim) {
    std::string s = scene;
    s.replace(s.find("AIM"), 3, aim);
    return s;
  };
  write_file(tmp.dir / "on.json", with(R"("radius": 2)"));
  write_file(tmp.dir / "off.json", with(R"("aim": false)"));
  write_file(tmp.dir / "bad.json", with(R"("aim": 1)"));
  auto aim_of = [&](const std::string& out) {
    const auto j = nlohmann::json::parse(read_file(tmp.dir / out / "render.json"));
    return j["settings"]["integrator"]["aim"];
  };
  REQUIRE(run_femto({"render", "on.json", "--spp", "1", "--out", "a", "--quiet"}, tmp.dir).code ==
          0);
  CHECK(aim_of("a")["enabled"] == true);
  CHECK(aim_of("a")["lights"][0]["aimed"] == true);
  REQUIRE(run_femto({"render", "off.json", "--spp", "1", "--out", "b", "--quiet"}, tmp.dir).code ==
          0);
  CHECK(aim_of("b")["enabled"] == false);
  REQUIRE(
      run_femto({"render", "on.json", "--spp", "1", "--out", "c", "--quiet", "--photon-aim", "off"},
                tmp.dir)
          .code == 0);
  CHECK(aim_of("c")["enabled"] == false);

  const Run bad = run_femto({"render", "bad.json", "--out", "d", "--quiet"}, tmp.dir);
  CHECK(bad.code == 2);
  CHECK(bad.err.find("/render/photons/aim") != std::string::npos);
  CHECK_FALSE(std::filesystem::exists(tmp.dir / "d"));
  const Run flag =
      run_femto({"render", "on.json", "--out", "e", "--quiet", "--photon-aim", "yes"}, tmp.dir);
  CHECK(flag.code == 2);
  CHECK(flag.err.find("--photon-aim") != std::string::npos);
  CHECK_FALSE(std::filesystem::exists(tmp.dir / "e"));
  const Run path = run_femto(
      {"render", "on.json", "--out", "f", "--quiet", "--integrator", "path", "--photon-aim", "on"},
      tmp.dir);
  CHECK(path.code == 2);
  CHECK(path.err.find("--photon-aim") != std::string::npos);
}
