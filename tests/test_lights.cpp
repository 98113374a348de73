// Light sampling: pdfs consistent with the MIS evaluation, cones and beams respected.
#include <catch2/catch.hpp>

#include <cmath>
#include <vector>

#include "core/constants.h"
#include "core/lights.h"
#include "core/rng.h"
#include "core/spot_cone.h"
#include "samplers/stats.h"
#include "scene_builders.h"

using namespace femto;
using namespace femto::test;

// Catches: MIS weights computed with a pdf different from the one light sampling used (bias at
// every diffuse/medium vertex that sees an area light), and emission from the back side.
TEST_CASE("area light sample pdf equals pdf_area of the sampled point", "[lights]") {
  SceneDesc d;
  ShapeDesc q = quad({-1, -2, 5}, {0, 2, 0}, {3, 0, 0.5}, diffuse(0.5));  // faces -z, towards x
  q.emissive = true;
  q.emission = RGB(2.0);
  d.shapes.push_back(q);
  ShapeDesc s;
  s.type = ShapeDesc::Type::Sphere;
  s.center = {4, 1, -3};
  s.radius = 1.5;
  s.emissive = true;
  s.emission = RGB(1.0);
  d.shapes.push_back(s);
  const LightSet lights(d);
  REQUIRE(lights.count() == 2);
  Rng rng(7, 1);
  const Vec3 x(0.2, 0.1, 0.3);
  int accepted = 0;
  for (int k = 0; k < 2000; ++k) {
    const int li = k % 2;
    LightSample ls;
    if (!lights.sample(li, x, rng.uniform(), rng.uniform(), ls)) continue;
    ++accepted;
    const Vec3 n = li == 0 ? normalize(cross(Vec3(0, 2, 0), Vec3(3, 0, 0.5))) : normalize(ls.p - s.center);
    REQUIRE(dot(ls.wi, n) < 0);  // the light faces x
    REQUIRE(ls.pdf == Approx(lights.pdf_area(li, x, ls.p, n)).epsilon(1e-9));
    REQUIRE(ls.dist == Approx(length(ls.p - x)).epsilon(1e-12));
  }
  CHECK(accepted > 1000);
  // Light selection is proportional to power pi * area * Le.
  const double p0 = kPi * std::sqrt(9 + 0.25) * 2 * 2.0, p1 = kPi * 4 * kPi * 1.5 * 1.5 * 1.0;
  CHECK(lights.pmf(0) == Approx(p0 / (p0 + p1)).epsilon(1e-12));
}

// Catches: spot lights leaking outside their cone or dimming inside the inner cone.
TEST_CASE("spot light cone and falloff", "[lights]") {
  SceneDesc d;
  LightDesc l;
  l.type = LightDesc::Type::Spot;
  l.position = {0, 0, 0};
  l.direction = {0, 0, -1};
  l.intensity = RGB(10.0);
  l.cone_angle_deg = 30;
  l.falloff_deg = 20;
  d.lights.push_back(l);
  const LightSet lights(d);
  auto at_angle = [&](double deg, LightSample& ls) {
    const double a = deg * kPi / 180;
    return lights.sample(0, Vec3(2 * std::sin(a), 0, -2 * std::cos(a)), 0.5, 0.5, ls);
  };
  LightSample ls;
  REQUIRE(at_angle(10, ls));
  CHECK(ls.Li.r == Approx(10.0 / 4.0));
  REQUIRE(at_angle(25, ls));
  CHECK(ls.Li.r > 0.0);
  CHECK(ls.Li.r < 10.0 / 4.0);
  CHECK_FALSE(at_angle(31, ls));
  CHECK_FALSE(at_angle(120, ls));
}

// Catches: the stretch of a ray inside a spot's cone (core/spot_cone.h) cut too short, which
// would lose the light of the points left out (segment connections sample only that stretch):
// the mirror nappe taken for the spot's, the wrong root kept for rays steeper than the cone, or
// roots swapped. Also that it stays tight where it claims to (convex cones), so the connections'
// gain is real. 4000 random rays and cones (half-angles 5-85 degrees, plus 90-120 where the whole
// range must be kept), each checked at 400 points against the cone test itself.
TEST_CASE("spot cone interval holds every lit point of a ray, and only those", "[lights]") {
  Rng rng(2026, 12);
  int tight_checked = 0;
  for (int k = 0; k < 4000; ++k) {
    Light l;
    l.type = Light::Type::Spot;
    l.position = Vec3(rng.uniform() - 0.5, rng.uniform() - 0.5, rng.uniform() - 0.5) * 20.0;
    l.direction = normalize(Vec3(rng.uniform() - 0.5, rng.uniform() - 0.5, rng.uniform() - 0.5));
    const double half_deg = k % 10 == 0 ? 90 + 30 * rng.uniform() : 5 + 80 * rng.uniform();
    l.cos_cone = std::cos(half_deg * kPi / 180);
    Ray ray{Vec3(rng.uniform() - 0.5, rng.uniform() - 0.5, rng.uniform() - 0.5) * 40.0,
            normalize(Vec3(rng.uniform() - 0.5, rng.uniform() - 0.5, rng.uniform() - 0.5))};
    const double lo0 = 0.0, hi0 = 30.0 + 30.0 * rng.uniform();
    double lo = lo0, hi = hi0;
    const bool any = spot_cone_interval(l, ray, lo, hi);
    for (int i = 0; i < 400; ++i) {
      const double s = lo0 + (hi0 - lo0) * (i + 0.5) / 400;
      const Vec3 v = ray.at(s) - l.position;
      const double cos_t = dot(v, l.direction) / length(v);
      const bool inside = cos_t > l.cos_cone + 1e-9;
      const bool in_range = any && s >= lo && s <= hi;
      if (inside) REQUIRE(in_range);  // no lit point left out
      if (l.cos_cone > 0 && in_range) {
        CHECK(cos_t > l.cos_cone - 1e-6);  // convex cone: nothing far outside is kept
        ++tight_checked;
      }
    }
    if (l.cos_cone <= 0) CHECK((any && lo == lo0 && hi == hi0));
  }
  CHECK(tight_checked > 20000);
}

// Catches: spot emission directions that are not uniform over the cone's solid angle (a wrong
// cos theta warp, or an azimuth that is not uniform, e.g. a wrong quadrant of its sine/cosine).
// Chi-square over 10 bands of cos theta x 16 azimuth sectors, fixed seed, reject when p < 1e-3.
TEST_CASE("spot light emission is uniform over its cone", "[lights]") {
  SceneDesc d;
  LightDesc l;
  l.type = LightDesc::Type::Spot;
  l.position = {1, 2, 3};
  l.direction = normalize(Vec3(0.3, -0.4, 0.8));
  l.intensity = RGB(1.0);
  l.cone_angle_deg = 40;
  l.falloff_deg = 25;
  d.lights.push_back(l);
  const LightSet lights(d);
  const Frame frame(l.direction);
  const double cos_cone = std::cos(40.0 * kPi / 180.0);
  const int n_mu = 10, n_phi = 16, n = 160000;
  std::vector<double> observed(n_mu * n_phi, 0.0);
  Rng rng(41, 9);
  int rejected = 0, off_cone = 0;
  for (int k = 0; k < n; ++k) {
    LightEmission e;
    const double u1 = rng.uniform(), u2 = rng.uniform();
    if (!lights.sample_emission(0, u1, u2, 0.5, 0.5, e)) {
      ++rejected;
      continue;
    }
    const Vec3 w = frame.to_local(e.ray.d);
    if (w.z < cos_cone - 1e-12 || std::abs(length(e.ray.d) - 1.0) > 1e-15) {
      ++off_cone;
      continue;
    }
    double phi = std::atan2(w.y, w.x);
    if (phi < 0) phi += 2.0 * kPi;
    const int i = std::min(n_mu - 1, static_cast<int>((1.0 - w.z) / (1.0 - cos_cone) * n_mu));
    const int j = std::min(n_phi - 1, static_cast<int>(phi / (2.0 * kPi) * n_phi));
    observed[static_cast<size_t>(i * n_phi + j)] += 1.0;
  }
  CHECK(rejected == 0);
  CHECK(off_cone == 0);
  const std::vector<double> expected(observed.size(), static_cast<double>(n) / (n_mu * n_phi));
  const stats::Chi2Result r = stats::chi2_test(observed, expected);
  INFO("chi2 = " << r.chi2 << "  dof = " << r.dof << "  p = " << r.p_value);
  CHECK(r.p_value >= 1e-3);
}

// Catches: laser irradiance or geometry errors (points behind the source or outside the beam).
TEST_CASE("laser beam cylinder", "[lights]") {
  SceneDesc d;
  LightDesc l;
  l.type = LightDesc::Type::Laser;
  l.position = {1, 1, 1};
  l.direction = normalize(Vec3(1, 1, 0));
  l.radius = 0.5;
  l.power = RGB(3.0);
  d.lights.push_back(l);
  const LightSet lights(d);
  LightSample ls;
  const Vec3 inside = l.position + l.direction * 10 + Vec3(0, 0, 0.4);
  REQUIRE(lights.sample(0, inside, 0.1, 0.9, ls));
  CHECK(ls.Li.g == Approx(3.0 / (kPi * 0.25)));
  CHECK(ls.dist == Approx(10.0));
  CHECK(ls.wi.x == Approx(-l.direction.x));
  CHECK(ls.is_delta);
  CHECK_FALSE(lights.sample(0, l.position + l.direction * 10 + Vec3(0, 0, 0.6), 0.1, 0.9, ls));
  CHECK_FALSE(lights.sample(0, l.position - l.direction * 1 + Vec3(0, 0, 0.1), 0.1, 0.9, ls));
}
