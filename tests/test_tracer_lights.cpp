// Lights, dielectrics and pulse shapes against closed-form answers.
#include <catch2/catch.hpp>

#include <cmath>

#include "core/constants.h"
#include "core/temporal_filter.h"
#include "media/phase_hg.h"
#include "samplers/stats.h"
#include "scene_builders.h"

using namespace femto;
using namespace femto::test;

// Catches: Gaussian pulses losing or creating energy, or being centred on the wrong time.
TEST_CASE("Gaussian pulse deposit integrates exactly over bins", "[film]") {
  TimeAxis axis;
  axis.t_start_ps = 0;
  axis.bin_width_ps = 1.0;
  axis.bins = 100;
  const TemporalFilter filter(axis, TemporalFilter::Kind::Histogram);
  std::vector<double> bins(300, 0.0);
  const double t = 40.3, sigma = 2.5;
  const DepositSplit split = filter.deposit(t, sigma, RGB(1.0), bins.data());
  double sum = 0, mean = 0;
  for (int i = 0; i < axis.bins; ++i) {
    sum += bins[3 * i];
    mean += bins[3 * i] * axis.bin_center_ps(i);
    const double expected = TemporalFilter::gaussian_cdf((i + 1 - t) / sigma) -
                            TemporalFilter::gaussian_cdf((i - t) / sigma);
    REQUIRE(bins[3 * i] == Approx(expected).margin(1e-15));
  }
  CHECK(sum == Approx(1.0).epsilon(1e-12));
  CHECK(mean / sum == Approx(t).epsilon(1e-9));
  CHECK(split.before + split.inside + split.after == Approx(1.0).epsilon(1e-12));
  // A pulse straddling the window end splits its energy.
  std::vector<double> b2(300, 0.0);
  const DepositSplit s2 = filter.deposit(100.0, 3.0, RGB(2.0), b2.data());
  CHECK(s2.after == Approx(0.5).epsilon(1e-12));
  CHECK(s2.inside == Approx(0.5).epsilon(1e-9));
  // A delta deposit lands in exactly one bin.
  std::vector<double> b3(300, 0.0);
  filter.deposit(12.999, 0.0, RGB(1.0), b3.data());
  CHECK(b3[3 * 12] == 1.0);
}

// Catches: laser beams lighting points outside the cylinder, wrong irradiance P / (pi R^2),
// wrong attenuation along the beam, wrong time of flight from the emitting disc.
TEST_CASE("laser beam single scattering seen from the side", "[tracer][analytic]") {
  const double sigma_a = 0.02, sigma_s = 0.08, g = 0.6, eta = 1.33, R = 1.0, P = 50.0;
  const double X = 20.0, Z0 = 10.0, y0 = 0.4;  // camera ray (X, y0, s - Z0) crosses the beam
  SceneDesc d;
  d.source = "laser";
  d.camera = ortho_camera({X, y0, -Z0}, {X, y0, 0}, 1e-4, 1, 1);
  d.camera.up = {0, 1, 0};
  d.time.t_start_ps = eta * (X + Z0 - 2.0) / kSpeedOfLight;
  d.time.bin_width_ps = 2.0;
  d.time.bins = 20;
  d.media.push_back(medium("m", sigma_a, sigma_s, g, eta));
  d.global_medium = 0;
  d.lights.push_back(laser_along_x(R, P));
  const auto films = render_batches(d, 20000, 16, /*max_depth=*/1);
  const double st = sigma_a + sigma_s, E = P / (kPi * R * R), half = std::sqrt(R * R - y0 * y0);
  double total_mc = 0;
  std::vector<double> totals;
  for (const auto& f : films) totals.push_back(f.total_steady().r);
  const MeanSE m = mean_se(totals);
  // L = sigma_s p(90 deg) E exp(-sigma_t X) * integral over the chord of exp(-sigma_t s).
  const double chord = (std::exp(-st * (Z0 - half)) - std::exp(-st * (Z0 + half))) / st;
  const double expected = sigma_s * hg_eval(0.0, g) * E * std::exp(-st * X) * chord;
  INFO("MC " << m.mean << " +- " << m.se << " expected " << expected);
  CHECK(std::abs(m.mean - expected) < 4.0 * m.se);
  CHECK(m.se < 0.02 * expected);
  // Arrival times: eta (X + s) / c for s over the chord; nothing outside those bins.
  const TransientFilm& f0 = films[0];
  for (int i = 0; i < d.time.bins; ++i) {
    const double t0 = d.time.bin_start_ps(i), t1 = t0 + d.time.bin_width_ps;
    const double ta = eta * (X + Z0 - half) / kSpeedOfLight, tb = eta * (X + Z0 + half) / kSpeedOfLight;
    if (t1 < ta || t0 > tb) REQUIRE(f0.transient()[3 * i] == 0.0f);
    total_mc += f0.transient()[3 * i];
  }
  CHECK(total_mc > 0);
}

// Catches: refraction at normal incidence not transmitting (1 - R)^2, wrong Fresnel R, wrong
// time inside the glass (eta_glass * thickness / c), radiance scaling that does not cancel.
TEST_CASE("glass slab delays and attenuates the view of a lit floor", "[tracer][analytic]") {
  const double n = 1.5, thickness = 10.0;
  SceneDesc d;
  d.source = "slab";
  d.camera = ortho_camera({0, 0, 100}, {0, 0, 0}, 0.5, 1, 1);
  d.time.bin_width_ps = 4.0;
  const double t_direct = (30 + n * thickness + 60 + 40) / kSpeedOfLight;  // camera->floor->light
  d.time.t_start_ps = t_direct - 2.0 - 10 * d.time.bin_width_ps;           // mid-bin 10
  d.time.bins = 64;
  d.shapes.push_back(quad({-50, -50, 0}, {100, 0, 0}, {0, 100, 0}, diffuse(0.5)));
  MaterialDesc glass;
  glass.type = MaterialDesc::Type::Dielectric;
  glass.eta = n;
  d.shapes.push_back(quad({-100, -100, 70}, {200, 0, 0}, {0, 200, 0}, glass));   // top, normal +z
  d.shapes.push_back(quad({-100, -100, 60}, {0, 200, 0}, {200, 0, 0}, glass));   // bottom, -z
  LightDesc l;
  l.position = {0, 0, 40};
  l.intensity = RGB(1000.0);
  d.lights.push_back(l);
  const int spp = 200000;
  const Scene scene(d);
  RenderOptions opt;
  opt.spp = spp;
  opt.quiet = true;
  const TransientFilm film = render(scene, opt).film;
  const double R = std::pow((n - 1) / (n + 1), 2), T2 = (1 - R) * (1 - R);
  const double L_floor = 0.5 / kPi * 1000.0 / (40.0 * 40.0);  // footprint is 0.5 mm: cos ~ 1
  // Direct view through the slab: each sample is 0 or ~L_floor, so SE = L sqrt(p(1-p)/N).
  const double direct = film.transient()[3 * 10];
  const double se_direct = L_floor * std::sqrt(T2 * (1 - T2) / spp);
  INFO("direct " << direct << " expected " << T2 * L_floor << " se " << se_direct);
  CHECK(std::abs(direct - T2 * L_floor) < 4 * se_direct + 1e-4 * L_floor);
  // One round trip inside the glass: later by 2 n thickness / c (= 100.07 ps, bin 10 + 25),
  // weighted (1 - R)^2 R^2.
  const int echo_bin = d.time.bin_of(t_direct + 2 * n * thickness / kSpeedOfLight);
  REQUIRE(echo_bin == 35);
  const double p_echo = T2 * R * R;
  const double echo = film.transient()[3 * echo_bin];
  const double se_echo = L_floor * std::sqrt(p_echo * (1 - p_echo) / spp);
  INFO("echo " << echo << " expected " << p_echo * L_floor << " se " << se_echo);
  CHECK(std::abs(echo - p_echo * L_floor) < 4 * se_echo + 1e-4 * L_floor);
  for (int i = 0; i < d.time.bins; ++i)
    if (i != 10 && i != 35 && i != 60) REQUIRE(film.transient()[3 * i] == 0.0f);
}
