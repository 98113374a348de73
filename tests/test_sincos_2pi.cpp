// Accuracy of sincos_2pi (core/sincos_2pi.h), the sine and cosine of every sampled azimuth, against
// a long-double reference and against std::sin / std::cos, at random fractions of a turn and
// around every eighth of a turn (where the reduction changes quadrant and the polynomials reach
// the ends of their interval).
#include <catch2/catch.hpp>

#include <cmath>
#include <cstdint>
#include <limits>
#include <vector>

#include "core/constants.h"
#include "core/rng.h"
#include "core/sincos_2pi.h"

using femto::sincos_2pi;

namespace {

// Error budget of the cosine polynomial (the larger one), in ulps of results >= cos(pi/4): the
// rounding of z = f^2 (0.29), of C1 + z R(z) times z (0.25), of the product z Q (0.25), of the
// final 1 + z Q (0.5), coefficients and approximation (< 0.05). The sine polynomial stays within
// 0.8 ulp (its leading 1.5 f is exact), but general doubles, whose f has 53 bits, round 1.5 f.
constexpr double kMaxUlps = 1.35;

struct Reference {
  long double sin, cos;
};

/// sin and cos of 2 pi u in long double (64-bit significand on x86-64): the same exact reduction
/// to the nearest quarter turn (t - q is exact in either precision), then sinl / cosl of an
/// angle below pi/4, so the reference is accurate to ~2^-63 relative even next to the zeros.
Reference reference(double u) {
  const long double t = 4.0L * static_cast<long double>(u);
  const long double q = std::floor(t + 0.5L);
  const long double a = (t - q) * 1.5707963267948966192313216916397514L;
  const long double s = std::sin(a), c = std::cos(a);
  switch (static_cast<int>(q) & 3) {
    case 0:
      return {s, c};
    case 1:
      return {c, -s};
    case 2:
      return {-s, -c};
    default:
      return {-c, s};
  }
}

/// |x - r| in units of the spacing of doubles at |r| (r rounded to double); 0 when both are 0.
double ulps(double x, long double r) {
  const double rd = static_cast<double>(r);
  if (rd == 0.0) return x == 0.0 ? 0.0 : std::numeric_limits<double>::infinity();
  const double a = std::fabs(rd);
  const double spacing = std::nextafter(a, std::numeric_limits<double>::infinity()) - a;
  return static_cast<double>(std::fabs(static_cast<long double>(x) - r) / spacing);
}

/// Fractions of a turn: uniform draws, and runs of neighbouring doubles around each k/8 (steps of
/// 2^-53 as Rng::uniform() makes them, and steps of one ulp of k/8 on either side).
std::vector<double> test_fractions() {
  std::vector<double> u;
  femto::Rng rng(2024, 11);
  for (int i = 0; i < 400000; ++i) u.push_back(rng.uniform());
  for (int k = 0; k <= 8; ++k) {
    const double edge = k / 8.0;
    for (int j = -3000; j <= 3000; ++j) {
      const double v = edge + j * 0x1p-53;
      if (v >= 0.0 && v <= 1.0) u.push_back(v);
    }
    double up = edge, down = edge;
    for (int j = 0; j < 200; ++j) {
      up = std::nextafter(up, 2.0);
      down = std::nextafter(down, -1.0);
      if (up <= 1.0) u.push_back(up);
      if (down >= 0.0) u.push_back(down);
    }
  }
  return u;
}

}  // namespace

// Catches a wrong or mistyped polynomial coefficient, a wrong quadrant rotation (sign or swap), a
// reduction that is not exact (errors growing with u) or that breaks at the octant edges.
TEST_CASE("sincos_2pi is within 1.35 ulp of sin and cos of 2 pi u", "[sincos]") {
  REQUIRE(std::numeric_limits<long double>::digits >= 64);  // the reference needs extra bits
  double worst_sin = 0.0, worst_cos = 0.0, u_sin = 0.0, u_cos = 0.0, sum = 0.0;
  const std::vector<double> us = test_fractions();
  for (const double u : us) {
    const femto::SinCos r = sincos_2pi(u);
    const Reference ref = reference(u);
    const double es = ulps(r.sin, ref.sin), ec = ulps(r.cos, ref.cos);
    if (es > worst_sin) worst_sin = es, u_sin = u;
    if (ec > worst_cos) worst_cos = ec, u_cos = u;
    sum += es + ec;
  }
  INFO("max sin error " << worst_sin << " ulp at u = " << u_sin << ", max cos error " << worst_cos
                        << " ulp at u = " << u_cos << ", mean "
                        << sum / (2.0 * static_cast<double>(us.size())));
  CHECK(worst_sin <= kMaxUlps);
  CHECK(worst_cos <= kMaxUlps);
}

// Catches the same faults for fractions that are not multiples of 2^-53 (tiny ones included),
// whose f has a full 53-bit significand.
TEST_CASE("sincos_2pi is accurate for any double in [0, 1]", "[sincos]") {
  REQUIRE(std::numeric_limits<long double>::digits >= 64);
  femto::Rng rng(7, 3);
  double worst = 0.0, worst_u = 0.0;
  for (int i = 0; i < 200000; ++i) {
    // A random 53-bit significand at a random scale 2^-1 .. 2^-60.
    const double m = 1.0 + rng.uniform();
    const double u = std::ldexp(m, -1 - static_cast<int>(rng.uniform() * 60.0));
    const femto::SinCos r = sincos_2pi(u);
    const Reference ref = reference(u);
    const double e = std::fmax(ulps(r.sin, ref.sin), ulps(r.cos, ref.cos));
    if (e > worst) worst = e, worst_u = u;
  }
  for (const double u : {1e-300, 4.9e-324, std::nextafter(1.0, 0.0), 1.0}) {
    const femto::SinCos r = sincos_2pi(u);
    const Reference ref = reference(u);
    worst = std::fmax(worst, std::fmax(ulps(r.sin, ref.sin), ulps(r.cos, ref.cos)));
  }
  INFO("max error " << worst << " ulp at u = " << worst_u);
  CHECK(worst <= kMaxUlps);
}

// Catches disagreement with the standard library beyond what the rounding of its argument
// 2 pi u (relative 2^-52 at most: kPi's representation and the product) and its own ulp explain.
TEST_CASE("sincos_2pi agrees with std::sin and std::cos of 2 pi u", "[sincos]") {
  double worst = 0.0, worst_u = 0.0;
  for (const double u : test_fractions()) {
    const femto::SinCos r = sincos_2pi(u);
    const double phi = 2.0 * femto::kPi * u;
    const double s = std::sin(phi), c = std::cos(phi);
    const double arg = std::fabs(phi) * 0x1p-52;  // bound on |phi - 2 pi u|
    const auto spacing = [](double x) {
      const double a = std::fabs(x);
      return std::nextafter(a, 2.0) - a;
    };
    const double tol_s = (kMaxUlps + 1.0) * spacing(s) + arg;
    const double tol_c = (kMaxUlps + 1.0) * spacing(c) + arg;
    const double e = std::fmax(std::fabs(r.sin - s) / tol_s, std::fabs(r.cos - c) / tol_c);
    if (e > worst) worst = e, worst_u = u;
  }
  INFO("max error / tolerance " << worst << " at u = " << worst_u);
  CHECK(worst <= 1.0);
}

// Catches quarter turns that are not exact (a reduction through a rounded 2 pi u gives
// sin(pi) = 1.2e-16) and directions that drift off the unit circle.
TEST_CASE("sincos_2pi: exact quarter turns, sin^2 + cos^2 = 1 to 1e-15", "[sincos]") {
  const double quarter[5][3] = {
      {0.0, 0.0, 1.0}, {0.25, 1.0, 0.0}, {0.5, 0.0, -1.0}, {0.75, -1.0, 0.0}, {1.0, 0.0, 1.0}};
  for (const auto& q : quarter) {
    INFO("u = " << q[0]);
    CHECK(sincos_2pi(q[0]).sin == q[1]);
    CHECK(sincos_2pi(q[0]).cos == q[2]);
  }
  double worst = 0.0;
  for (const double u : test_fractions()) {
    const femto::SinCos r = sincos_2pi(u);
    const long double s = r.sin, c = r.cos;
    worst = std::fmax(worst, static_cast<double>(std::fabs(s * s + c * c - 1.0L)));
  }
  INFO("max |sin^2 + cos^2 - 1| = " << worst);
  CHECK(worst <= 1e-15);
}
