// BSDFs (core/bsdf/): sampling against pdf() by chi-square, sample() against f() and pdf(),
// energy conservation, Fresnel known values, generalised reciprocity and degenerate inputs.
//
// Significance: the chi-square tests expected to pass are held to a family-wise level of 1e-3
// (Bonferroni: each needs p >= 1e-3 / kChi2Tests). Seeds are fixed, so every outcome is
// deterministic; "chi2 has power" shows that slightly wrong pdfs fail by orders of magnitude.
// Expected cell counts: midpoint rule of pdf() on a sub-grid inside each cell (see chi2_bsdf).
// Monte Carlo integrals are checked against their own standard error (at most kSigmas of them).
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <functional>
#include <vector>

#include "core/bsdf/bsdf.h"
#include "core/constants.h"
#include "core/rng.h"
#include "core/sampling.h"
#include "samplers/stats.h"

using femto::Bsdf;
using femto::BsdfSample;
using femto::kPi;
using femto::MaterialDesc;
using femto::RGB;
using femto::Rng;
using femto::TransportMode;
using femto::Vec3;
namespace st = femto::stats;

namespace {

constexpr int kChi2Tests = 28;  // 2 diffuse + 10 rough conductor + 16 rough dielectric
constexpr double kChiSquareAlpha = 1e-3 / kChi2Tests;
constexpr double kSigmas = 5.0;  // two-sided normal tail 6e-7 per check

// ---- materials

Bsdf make(MaterialDesc::Type type, double eta_or_alpha = 0.0, double alpha = 0.0,
          RGB colour = RGB(1.0)) {
  MaterialDesc m;
  m.type = type;
  m.albedo = colour;
  m.reflectance = colour;
  if (type == MaterialDesc::Type::RoughConductor) {
    m.roughness = eta_or_alpha;
  } else {
    m.eta = eta_or_alpha;
    m.roughness = alpha;
  }
  return Bsdf::from_material(m, 1.0);
}
Bsdf diffuse_bsdf(RGB albedo) {
  return make(MaterialDesc::Type::Diffuse, 0, 0, albedo);
}
Bsdf conductor(double alpha, RGB f0 = RGB(1.0)) {
  return make(MaterialDesc::Type::RoughConductor, alpha, 0, f0);
}
Bsdf rough_glass(double eta, double alpha) {
  return make(MaterialDesc::Type::RoughDielectric, eta, alpha);
}
Bsdf glass_bsdf(double eta) {
  return make(MaterialDesc::Type::Dielectric, eta);
}

/// Unit direction in the x-z plane at theta degrees from +z (theta > 90: below the surface).
Vec3 incidence(double theta_deg) {
  const double t = theta_deg * kPi / 180.0;
  return {std::sin(t), 0.0, std::cos(t)};
}

double rel_diff(double a, double b) {
  const double scale = std::max(std::abs(a), std::abs(b));
  return scale > 0.0 ? std::abs(a - b) / scale : 0.0;
}
double rel_diff(const RGB& a, const RGB& b) {
  return std::max({rel_diff(a.r, b.r), rel_diff(a.g, b.g), rel_diff(a.b, b.b)});
}

/// Index of the medium on w's side of an interface with relative index eta (outside = 1).
double eta_side(const Vec3& w, double eta) {
  return w.z > 0.0 ? 1.0 : eta;
}

// ---- chi-square over the sphere

/// Sphere coordinates with pole +y: mu = w.y, phi = atan2(w.z, w.x) in [0, 2 pi). The surface
/// plane z = 0 is phi = 0 and pi (cell edges, where opaque pdfs jump), and the lobes around the
/// normal and the specular directions (all in the x-z plane) lie on the equator, where cells
/// are narrow in both coordinates. Cells of equal (mu, phi) size have equal solid angle.
Vec3 direction(double mu, double phi) {
  const double r = std::sqrt(std::max(0.0, 1.0 - mu * mu));
  return {r * std::cos(phi), mu, r * std::sin(phi)};
}

constexpr int kMu = 40, kPhi = 80, kDraws = 100000;
constexpr int kSub = 8;              // midpoint sub-grid per cell
constexpr int kSubEdge = 48;         // finer sub-grid for cells on an edge of the pdf's support
constexpr double kEdgeFloor = 1e-9;  // expected count of an edge cell where quadrature found none

using PdfFn = std::function<double(const Vec3&)>;

/// Mass of `pdf` over cell (i, j) by the midpoint rule on a sub x sub grid; `mixed` tells
/// whether the pdf was zero at some sub-points and positive at others.
double cell_mass(const PdfFn& pdf, int i, int j, int sub, bool& mixed) {
  const double h_mu = 2.0 / (kMu * sub), h_phi = 2.0 * kPi / (kPhi * sub);
  double m = 0.0;
  int zeros = 0;
  for (int a = 0; a < sub; ++a)
    for (int c = 0; c < sub; ++c) {
      const double p =
          pdf(direction(-1.0 + (i * sub + a + 0.5) * h_mu, (j * sub + c + 0.5) * h_phi));
      m += p;
      zeros += p > 0.0 ? 0 : 1;
    }
  mixed = zeros > 0 && zeros < sub * sub;
  return m * h_mu * h_phi;  // d(omega) = d(mu) d(phi)
}

/// Pearson chi-square of kDraws draws of b.sample(wo) on kMu x kPhi cells plus one cell for
/// failed draws, against kDraws times the cell masses of `pdf` (the failure cell gets 1 - total
/// mass). The rough dielectric's pdf jumps to 0 where the microfacet normal reaches the horizon,
/// so cells on an edge of the support (mixed sub-points, or empty next to a non-empty cell) are
/// integrated again on a finer grid, and if still empty get a tiny expected count: they join the
/// pool of small cells instead of making a few observations "impossible". Observations in cells
/// away from the support still give p = 0.
st::Chi2Result chi2_bsdf(const Bsdf& b, const Vec3& wo, const PdfFn& pdf, uint64_t seed,
                         double* total_mass = nullptr) {
  const auto cells = static_cast<size_t>(kMu * kPhi);
  const auto at = [](int i, int j) { return static_cast<size_t>(i * kPhi + (j + kPhi) % kPhi); };
  std::vector<double> observed(cells + 1, 0.0), mass(cells, 0.0);
  Rng rng(seed, 41);
  int not_unit = 0;
  for (int k = 0; k < kDraws; ++k) {
    const double ul = rng.uniform(), u1 = rng.uniform(), u2 = rng.uniform();
    BsdfSample s;
    if (!b.sample(wo, ul, u1, u2, TransportMode::Radiance, s)) {
      observed[cells] += 1.0;
      continue;
    }
    if (!(std::abs(femto::length(s.wi) - 1.0) < 1e-9)) {
      ++not_unit;
      continue;
    }
    double phi = std::atan2(s.wi.z, s.wi.x);
    if (phi < 0.0) phi += 2.0 * kPi;
    const int i = std::clamp(static_cast<int>(std::floor((s.wi.y + 1.0) * 0.5 * kMu)), 0, kMu - 1);
    const int j = std::clamp(static_cast<int>(std::floor(phi / (2.0 * kPi) * kPhi)), 0, kPhi - 1);
    observed[at(i, j)] += 1.0;
  }
  CHECK(not_unit == 0);
  std::vector<char> edge(cells, 0);
  for (int i = 0; i < kMu; ++i)
    for (int j = 0; j < kPhi; ++j) {
      bool mixed = false;
      mass[at(i, j)] = cell_mass(pdf, i, j, kSub, mixed);
      edge[at(i, j)] = mixed;
    }
  for (int i = 0; i < kMu; ++i)
    for (int j = 0; j < kPhi; ++j) {
      if (mass[at(i, j)] > 0.0) continue;
      for (int di = -1; di <= 1; ++di)
        for (int dj = -1; dj <= 1; ++dj)
          if (i + di >= 0 && i + di < kMu && mass[at(i + di, j + dj)] > 0.0) edge[at(i, j)] = 1;
    }
  std::vector<double> expected(cells + 1, 0.0);
  double total = 0.0;
  for (int i = 0; i < kMu; ++i)
    for (int j = 0; j < kPhi; ++j) {
      double m = mass[at(i, j)];
      bool mixed = false;
      if (edge[at(i, j)]) m = cell_mass(pdf, i, j, kSubEdge, mixed);
      expected[at(i, j)] = edge[at(i, j)] ? std::max(kDraws * m, kEdgeFloor) : kDraws * m;
      total += m;
    }
  expected[cells] = kDraws * std::max(0.0, 1.0 - total);
  if (total_mass) *total_mass = total;
  return st::chi2_test(observed, expected);
}

st::Chi2Result chi2_bsdf(const Bsdf& b, const Vec3& wo, uint64_t seed) {
  double mass = 0.0;
  const st::Chi2Result r = chi2_bsdf(
      b, wo, [&](const Vec3& wi) { return b.pdf(wo, wi); }, seed, &mass);
  INFO("mass of pdf() = " << mass);
  CHECK(mass <= 1.0 + 1e-4);  // a sub-density: the rest is the failure probability
  return r;
}

#define CHECK_CHI2(r)                                                                           \
  do {                                                                                          \
    const st::Chi2Result r_ = (r);                                                              \
    INFO("chi2 = " << r_.chi2 << "  dof = " << r_.dof << "  p = " << r_.p_value                 \
                   << "  pooled = " << r_.cells_pooled << "  threshold = " << kChiSquareAlpha); \
    CHECK(r_.p_value >= kChiSquareAlpha);                                                       \
  } while (false)

// ---- Monte Carlo integrals over the sphere

struct Estimate {
  double mean = 0.0, se = 0.0;
};
struct Furnace {
  Estimate all;        ///< R + T (reflected and transmitted)
  Estimate reflected;  ///< R: the part with wi on wo's side
};

/// Integral over all wi of f(wo, wi, mode).r |wi.z|, in all and over wo's side only, by
/// one-sample MIS (balance heuristic) of b.sample() (probability 0.9) and uniform sphere
/// directions (0.1, so that every direction is covered whatever pdf() says); failed BSDF draws
/// contribute 0, which keeps the estimate unbiased since pdf() is their sub-density. Means and
/// standard errors over n draws.
constexpr double kBsdfShare = 0.9;

Furnace furnace(const Bsdf& b, const Vec3& wo, TransportMode mode, uint64_t seed, int n = 100000) {
  Rng rng(seed, 7);
  double sum[2] = {0.0, 0.0}, sum2[2] = {0.0, 0.0};
  for (int k = 0; k < n; ++k) {
    const double pick = rng.uniform(), ul = rng.uniform(), u1 = rng.uniform(), u2 = rng.uniform();
    Vec3 wi;
    if (pick < kBsdfShare) {
      BsdfSample s;
      if (!b.sample(wo, ul, u1, u2, mode, s)) continue;
      wi = s.wi;
    } else {
      wi = femto::sample_uniform_sphere(u1, u2);
    }
    const double density = kBsdfShare * b.pdf(wo, wi) + (1.0 - kBsdfShare) * femto::kInv4Pi;
    const double x = b.f(wo, wi, mode).r * std::abs(wi.z) / density;
    const double xr = femto::same_side(wo, wi) ? x : 0.0;
    sum[0] += x;
    sum2[0] += x * x;
    sum[1] += xr;
    sum2[1] += xr * xr;
  }
  Estimate e[2];
  for (int i = 0; i < 2; ++i) {
    e[i].mean = sum[i] / n;
    e[i].se = std::sqrt(std::max(0.0, sum2[i] / n - e[i].mean * e[i].mean) / (n - 1));
  }
  return {e[0], e[1]};
}

}  // namespace

// ---- Flags

// Catches a material mapped to the wrong family, or flags the integrator relies on being wrong.
TEST_CASE("Bsdf::from_material families and flags", "[bsdf]") {
  const Bsdf d = diffuse_bsdf(RGB(0.5)), m = make(MaterialDesc::Type::Mirror), g = glass_bsdf(1.5),
             rg = rough_glass(1.5, 0.2), rc = conductor(0.2);
  CHECK((d.is_diffuse() && !d.is_delta() && !d.transmits()));
  CHECK((!m.is_diffuse() && m.is_delta() && !m.transmits()));
  CHECK((!g.is_diffuse() && g.is_delta() && g.transmits()));
  CHECK((!rg.is_diffuse() && !rg.is_delta() && rg.transmits()));
  CHECK((!rc.is_diffuse() && !rc.is_delta() && !rc.transmits()));
  CHECK(rg.type() == MaterialDesc::Type::RoughDielectric);
  CHECK(rc.type() == MaterialDesc::Type::RoughConductor);
  // A rough interface between equal indices cannot refract: a delta pass-through.
  MaterialDesc matched;
  matched.type = MaterialDesc::Type::RoughDielectric;
  matched.eta = 1.33;
  const Bsdf pass = Bsdf::from_material(matched, 1.33);
  CHECK((pass.is_delta() && pass.transmits()));
  CHECK(pass.type() == MaterialDesc::Type::RoughDielectric);
  BsdfSample s;
  REQUIRE(pass.sample(incidence(40), 0.5, 0.5, 0.5, TransportMode::Radiance, s));
  CHECK(s.transmitted);
  CHECK(rel_diff(s.wi.x, -incidence(40).x) < 1e-15);
  CHECK(rel_diff(s.wi.z, -incidence(40).z) < 1e-15);
  CHECK(s.weight.r == 1.0);
}

// ---- Microfacet distribution

// Catches a GGX D without its normalisation, or a Smith Lambda inconsistent with D.
TEST_CASE("GGX D and visible-normal densities are normalised", "[bsdf][ggx]") {
  for (const double alpha : {0.05, 0.3, 1.0}) {
    const femto::Ggx ggx{alpha};
    // Isotropic: integral of D(m) cos dm = 2 pi integral over cos theta_m of D cos.
    const double projected =
        2.0 * kPi *
        st::adaptive_simpson(
            [&](double c) { return ggx.D(Vec3(std::sqrt(1.0 - c * c), 0.0, c)) * c; }, 0.0, 1.0,
            1e-11);
    INFO("alpha " << alpha);
    CHECK(projected == Approx(1.0).epsilon(1e-8));
    for (const double theta : {0.0, 60.0, 89.0}) {
      const Vec3 w = incidence(theta);
      const double visible = st::integrate_2d(
          [&](double c, double phi) {
            const double r = std::sqrt(std::max(0.0, 1.0 - c * c));
            return ggx.D_visible(w, Vec3(r * std::cos(phi), r * std::sin(phi), c));
          },
          0.0, 1.0, 0.0, 2.0 * kPi, 1e-7);
      INFO("theta " << theta);
      CHECK(visible == Approx(1.0).epsilon(1e-5));
    }
  }
}

// ---- Chi-square of sample() against pdf()

// Catches cosine sampling on the wrong side for wo below the surface, or a pdf without 1/pi.
TEST_CASE("Diffuse sampling matches its pdf", "[bsdf][chi2]") {
  const Bsdf b = diffuse_bsdf(RGB(0.7));
  uint64_t seed = 100;
  for (const double theta : {30.0, 130.0}) {
    INFO("theta = " << theta);
    CHECK_CHI2(chi2_bsdf(b, incidence(theta), seed++));
  }
}

// Catches wrong visible-normal sampling, reflection Jacobian 1/(4 wo.h), G1 or two-sided flip.
TEST_CASE("Rough conductor sampling matches its pdf", "[bsdf][chi2]") {
  uint64_t seed = 200;
  for (const double alpha : {0.05, 0.3, 0.8})
    for (const double theta : {10.0, 50.0, 80.0}) {
      INFO("alpha = " << alpha << "  theta = " << theta);
      CHECK_CHI2(chi2_bsdf(conductor(alpha), incidence(theta), seed++));
    }
  INFO("from below");
  CHECK_CHI2(chi2_bsdf(conductor(0.3), incidence(125.0), seed++));
}

// Catches a wrong refraction Jacobian or lobe choice, eta not inverted inside, or broken TIR.
TEST_CASE("Rough dielectric sampling matches its pdf", "[bsdf][chi2]") {
  uint64_t seed = 300;
  for (const double eta : {1.5, 1.0 / 1.5})
    for (const double alpha : {0.1, 0.5})
      for (const double theta : {30.0, 70.0, 110.0, 150.0}) {
        INFO("eta = " << eta << "  alpha = " << alpha << "  theta = " << theta);
        CHECK_CHI2(chi2_bsdf(rough_glass(eta, alpha), incidence(theta), seed++));
      }
}

// Proves the chi-square above has power: pdfs that are slightly wrong are rejected.
TEST_CASE("BSDF chi2 has power", "[bsdf][chi2]") {
  const Vec3 wo = incidence(50.0);
  {  // Samples of alpha 0.3 against the pdf of alpha 0.33.
    const Bsdf b = conductor(0.3), wrong = conductor(0.33);
    const st::Chi2Result r = chi2_bsdf(
        b, wo, [&](const Vec3& wi) { return wrong.pdf(wo, wi); }, 900);
    INFO("alpha 0.3 vs 0.33: chi2 = " << r.chi2 << "  dof = " << r.dof << "  p = " << r.p_value);
    CHECK(r.p_value < 1e-9);
  }
  {  // Samples of eta 1.5 against the pdf of eta 1.4 (transmission lobe slightly shifted).
    const Bsdf b = rough_glass(1.5, 0.3), wrong = rough_glass(1.4, 0.3);
    const st::Chi2Result r = chi2_bsdf(
        b, wo, [&](const Vec3& wi) { return wrong.pdf(wo, wi); }, 901);
    INFO("eta 1.5 vs 1.4: chi2 = " << r.chi2 << "  dof = " << r.dof << "  p = " << r.p_value);
    CHECK(r.p_value < 1e-9);
  }
  {  // The right pdf scaled by 1.1 where it is above 1 (a 10% error in the peak only).
    const Bsdf b = conductor(0.3);
    const st::Chi2Result r = chi2_bsdf(
        b, wo,
        [&](const Vec3& wi) {
          const double p = b.pdf(wo, wi);
          return p > 1.0 ? 1.1 * p : p;
        },
        902);
    INFO("peak x 1.1: chi2 = " << r.chi2 << "  dof = " << r.dof << "  p = " << r.p_value);
    CHECK(r.p_value < 1e-9);
  }
}

// ---- sample() agrees with f() and pdf()

// Catches sample() weights or pdfs that disagree with f() and pdf(), or f > 0 where pdf() = 0.
TEST_CASE("BSDF sample weight and pdf equal f |cos| / pdf and pdf()", "[bsdf]") {
  const std::vector<Bsdf> bsdfs = {diffuse_bsdf(RGB(0.2, 0.5, 0.9)),
                                   conductor(0.05, RGB(0.9, 0.6, 0.3)),
                                   conductor(0.3),
                                   conductor(0.8),
                                   rough_glass(1.5, 0.05),
                                   rough_glass(1.5, 0.3),
                                   rough_glass(1.0 / 1.5, 0.3),
                                   rough_glass(2.4, 0.8)};
  Rng rng(5, 9);
  for (size_t k = 0; k < bsdfs.size(); ++k) {
    const Bsdf& b = bsdfs[k];
    double worst_weight = 0.0, worst_pdf = 0.0, worst_len = 0.0;
    int wrong_flags = 0, accepted = 0, transmitted = 0, uncovered = 0;
    for (int n = 0; n < 20000; ++n) {
      const Vec3 wo = femto::sample_uniform_sphere(rng.uniform(), rng.uniform());
      const TransportMode mode = n % 2 ? TransportMode::Importance : TransportMode::Radiance;
      const double ul = rng.uniform(), u1 = rng.uniform(), u2 = rng.uniform();
      // Coverage: wherever f > 0, pdf > 0 (needed by MIS and by the furnace estimates).
      const Vec3 w_any = femto::sample_uniform_sphere(rng.uniform(), rng.uniform());
      if (!b.f(wo, w_any, mode).is_black() && !(b.pdf(wo, w_any) > 0.0)) ++uncovered;
      BsdfSample s;
      if (!b.sample(wo, ul, u1, u2, mode, s)) continue;
      ++accepted;
      transmitted += s.transmitted;
      worst_len = std::max(worst_len, std::abs(femto::length(s.wi) - 1.0));
      if (s.delta || s.transmitted != (wo.z * s.wi.z < 0.0)) ++wrong_flags;
      const double pdf = b.pdf(wo, s.wi);
      worst_pdf = std::max(worst_pdf, rel_diff(s.pdf, pdf));
      worst_weight = std::max(worst_weight,
                              rel_diff(s.weight, b.f(wo, s.wi, mode) * (std::abs(s.wi.z) / pdf)));
    }
    INFO("bsdf " << k << "  accepted = " << accepted << "  transmitted = " << transmitted);
    CHECK(accepted > 10000);
    if (b.transmits())
      CHECK(transmitted > 1000);
    else
      CHECK(transmitted == 0);
    CHECK(worst_len < 1e-12);
    CHECK(wrong_flags == 0);
    CHECK(worst_pdf < 1e-9);
    CHECK(worst_weight < 1e-9);
    CHECK(uncovered == 0);
  }
}

// ---- Energy

// Catches a Lambertian f without 1/pi, or f non-zero on the far side.
TEST_CASE("Diffuse white furnace integral equals the albedo", "[bsdf][energy]") {
  for (const double albedo : {0.2, 0.9}) {
    const Bsdf b = diffuse_bsdf(RGB(albedo));
    for (const double theta : {0.0, 60.0, 140.0}) {
      const Estimate e = furnace(b, incidence(theta), TransportMode::Radiance, 11).all;
      INFO("albedo " << albedo << " theta " << theta << ": " << e.mean << " +- " << e.se);
      CHECK(std::abs(e.mean - albedo) < kSigmas * e.se + 1e-12);
    }
  }
}

// Catches a rough conductor that creates energy, or loses too much of it at low roughness.
TEST_CASE("Rough conductor with F0 = 1 conserves energy", "[bsdf][energy]") {
  uint64_t seed = 20;
  for (const double alpha : {0.05, 0.3, 0.8})
    for (const double theta : {0.0, 45.0, 80.0, 135.0}) {
      const Estimate e =
          furnace(conductor(alpha), incidence(theta), TransportMode::Radiance, seed++).all;
      INFO("alpha " << alpha << " theta " << theta << ": " << e.mean << " +- " << e.se);
      CHECK(e.mean <= 1.0 + kSigmas * e.se);
      // Single scattering loses little at low roughness, away from grazing.
      if (alpha == 0.05 && theta != 80.0) CHECK(e.mean > 0.99 - kSigmas * e.se);
      if (alpha == 0.05 && theta == 80.0) CHECK(e.mean > 0.95 - kSigmas * e.se);
    }
}

// Catches R + T > 1 (wrong Jacobian or eta^2 factor), or Fresnel with the wrong side's eta.
TEST_CASE("Rough dielectric conserves energy and tends to Fresnel", "[bsdf][energy]") {
  uint64_t seed = 40;
  for (const double eta : {1.5, 1.0 / 1.5})
    for (const double theta : {0.0, 45.0, 75.0, 120.0, 160.0}) {
      const Vec3 wo = incidence(theta);
      const double F = femto::fresnel_dielectric(std::abs(wo.z), wo.z > 0 ? eta : 1.0 / eta).R;
      for (const double alpha : {0.01, 0.1, 0.5}) {
        const Bsdf b = rough_glass(eta, alpha);
        const Furnace fu = furnace(b, wo, TransportMode::Importance, seed++);
        const Estimate &e = fu.all, &r = fu.reflected;
        INFO("eta " << eta << " theta " << theta << " alpha " << alpha << ": R+T = " << e.mean
                    << " +- " << e.se << "  R = " << r.mean << " +- " << r.se << "  F = " << F);
        CHECK(e.mean <= 1.0 + kSigmas * e.se);
        if (alpha == 0.01) {
          CHECK(e.mean > 0.99 - kSigmas * e.se);
          CHECK(std::abs(r.mean - F) < 0.01 + kSigmas * r.se);
        }
      }
    }
}

// Catches a wrong Fresnel formula (normal, Brewster and critical angles) or R + T != 1.
TEST_CASE("Smooth dielectric Fresnel and lobe probabilities", "[bsdf][energy]") {
  const double eta = 1.5;
  const Bsdf b = glass_bsdf(eta);
  BsdfSample r, t;
  const auto lobes = [&](const Vec3& wo) {
    REQUIRE(b.sample(wo, 0.0, 0.5, 0.5, TransportMode::Radiance, r));
    REQUIRE(b.sample(wo, std::nextafter(1.0, 0.0), 0.5, 0.5, TransportMode::Radiance, t));
  };
  // Normal incidence from either side: ((eta - 1) / (eta + 1))^2.
  for (const double theta : {0.0, 180.0}) {
    lobes(incidence(theta));
    CHECK(r.pdf == Approx(0.04).epsilon(1e-12));
    CHECK(t.pdf == Approx(0.96).epsilon(1e-12));
  }
  // Brewster angle tan(theta_B) = eta: the p-polarised half vanishes.
  lobes(incidence(std::atan(eta) * 180.0 / kPi));
  const double rs = (eta * eta - 1.0) / (eta * eta + 1.0);
  CHECK(r.pdf == Approx(0.5 * rs * rs).epsilon(1e-12));
  // Everywhere: reflection and refraction probabilities add up to one.
  for (double theta = 0.0; theta < 180.0; theta += 7.0) {
    lobes(incidence(theta));
    if (r.transmitted || !t.transmitted) {
      // total internal reflection: both draws reflect
      CHECK(r.pdf == 1.0);
      CHECK(t.pdf == 1.0);
    } else {
      CHECK(r.pdf + t.pdf == Approx(1.0).epsilon(1e-14));
    }
  }
  // Total internal reflection just beyond the critical angle asin(1/eta) = 41.81 deg, not before.
  const double critical = std::asin(1.0 / eta) * 180.0 / kPi;
  lobes(incidence(180.0 - (critical + 0.01)));
  CHECK((!t.transmitted && t.pdf == 1.0));
  lobes(incidence(180.0 - (critical - 0.01)));
  CHECK(t.transmitted);
  CHECK(t.pdf > 0.0);
}

// Catches the 1/eta^2 radiance factor in the wrong mode or inverted, or refraction off Snell.
TEST_CASE("Smooth dielectric sample weights in both modes", "[bsdf]") {
  const double eta = 1.5;
  const Bsdf b = glass_bsdf(eta);
  for (const double theta : {25.0, 155.0}) {
    const Vec3 wo = incidence(theta);
    const bool outside = wo.z > 0.0;
    const double eta_o = outside ? 1.0 : eta, eta_i = outside ? eta : 1.0;
    for (const TransportMode mode : {TransportMode::Radiance, TransportMode::Importance}) {
      BsdfSample r, t;
      REQUIRE(b.sample(wo, 0.0, 0.3, 0.7, mode, r));
      REQUIRE(b.sample(wo, 0.999, 0.3, 0.7, mode, t));
      CHECK((r.delta && t.delta && !r.transmitted && t.transmitted));
      CHECK(r.weight.r == 1.0);
      CHECK(r.wi.x == -wo.x);
      CHECK(r.wi.z == wo.z);
      const double expected =
          mode == TransportMode::Radiance ? (eta_o / eta_i) * (eta_o / eta_i) : 1.0;
      INFO("theta " << theta << " radiance " << (mode == TransportMode::Radiance));
      CHECK(t.weight.r == Approx(expected).epsilon(1e-14));
      CHECK(t.weight.g == t.weight.r);
      // Snell: eta_o sin(theta_o) = eta_i sin(theta_i), tangential parts opposite.
      CHECK(eta_i * t.wi.x == Approx(-eta_o * wo.x).epsilon(1e-14));
      CHECK(t.wi.y == 0.0);
      CHECK(femto::length(t.wi) == Approx(1.0).epsilon(1e-14));
      CHECK(wo.z * t.wi.z < 0.0);
    }
  }
  // Camera ray from air into glass: 1 / 2.25.
  BsdfSample t;
  REQUIRE(b.sample(incidence(0.0), 0.999, 0.5, 0.5, TransportMode::Radiance, t));
  CHECK(t.weight.r == Approx(1.0 / 2.25).epsilon(1e-14));
  // Mirror: the colour, with probability 1.
  BsdfSample m;
  REQUIRE(make(MaterialDesc::Type::Mirror, 0, 0, RGB(0.9, 0.5, 0.1))
              .sample(incidence(140.0), 0.7, 0.5, 0.5, TransportMode::Radiance, m));
  CHECK((m.delta && !m.transmitted && m.pdf == 1.0 && m.weight.g == 0.5));
  CHECK((m.wi.x == -incidence(140.0).x && m.wi.z == incidence(140.0).z));
  CHECK(make(MaterialDesc::Type::Mirror)
            .f(incidence(20), incidence(-20), TransportMode::Radiance)
            .is_black());
}

// ---- Reciprocity

// Catches f breaking generalised reciprocity, or an Importance mode that is not the adjoint.
TEST_CASE("BSDF generalised reciprocity", "[bsdf]") {
  // Veach (thesis, ch. 5): in Radiance mode f(wo, wi) / eta_wo^2 = f(wi, wo) / eta_wi^2, with
  // eta_w the index on w's side; Importance mode is the adjoint, f_imp(wo, wi) = f_rad(wi, wo).
  // Opaque BSDFs are symmetric and mode-independent.
  Rng rng(77, 1);
  for (const double eta : {1.5, 1.0 / 1.5})
    for (const double alpha : {0.05, 0.4}) {
      const Bsdf b = rough_glass(eta, alpha);
      double worst = 0.0;
      int nonzero_t = 0, nonzero_r = 0;
      for (int n = 0; n < 20000; ++n) {
        const Vec3 wo = femto::sample_uniform_sphere(rng.uniform(), rng.uniform());
        Vec3 wi = femto::sample_uniform_sphere(rng.uniform(), rng.uniform());
        BsdfSample s;  // half the pairs from sampling, so most of them have f > 0
        if (n % 2 &&
            b.sample(wo, rng.uniform(), rng.uniform(), rng.uniform(), TransportMode::Radiance, s))
          wi = s.wi;
        const double f_oi = b.f(wo, wi, TransportMode::Radiance).r;
        const double f_io = b.f(wi, wo, TransportMode::Radiance).r;
        const double imp_oi = b.f(wo, wi, TransportMode::Importance).r;
        const double eo = eta_side(wo, eta), ei = eta_side(wi, eta);
        worst =
            std::max({worst, rel_diff(f_oi / (eo * eo), f_io / (ei * ei)), rel_diff(imp_oi, f_io)});
        if (f_oi > 0.0) (wo.z * wi.z < 0.0 ? nonzero_t : nonzero_r) += 1;
      }
      INFO("eta " << eta << " alpha " << alpha << ": transmission pairs " << nonzero_t
                  << ", reflection pairs " << nonzero_r);
      CHECK(worst < 1e-9);
      CHECK(nonzero_t > 2000);
      CHECK(nonzero_r > 1000);
    }
  for (const Bsdf& b :
       {diffuse_bsdf(RGB(0.6)), conductor(0.05, RGB(0.9, 0.6, 0.3)), conductor(0.5)}) {
    double worst = 0.0;
    for (int n = 0; n < 20000; ++n) {
      const Vec3 wo = femto::sample_uniform_sphere(rng.uniform(), rng.uniform());
      Vec3 wi = femto::sample_uniform_sphere(rng.uniform(), rng.uniform());
      BsdfSample s;
      if (n % 2 &&
          b.sample(wo, rng.uniform(), rng.uniform(), rng.uniform(), TransportMode::Radiance, s))
        wi = s.wi;
      const RGB f = b.f(wo, wi, TransportMode::Radiance);
      worst = std::max({worst, rel_diff(f, b.f(wi, wo, TransportMode::Radiance)),
                        rel_diff(f, b.f(wo, wi, TransportMode::Importance))});
    }
    CHECK(worst < 1e-12);
  }
}

// ---- Degenerate inputs

// Catches NaN or inf from divisions at grazing, polar or denormal directions and extreme u.
TEST_CASE("BSDFs stay finite at degenerate inputs", "[bsdf]") {
  const double tiny[] = {0.0, 5e-324, 1e-300, 1e-160, 1e-12, 1e-6};
  std::vector<Vec3> dirs = {{0, 0, 1}, {0, 0, -1}, {1, 0, 0}, {0, -1, 0}};
  for (const double z : tiny)
    for (const double sign : {1.0, -1.0})
      dirs.push_back({std::sqrt(1.0 - z * z) * 0.6, std::sqrt(1.0 - z * z) * 0.8, sign * z});
  const double us[] = {0.0, 1e-300, 0.5, std::nextafter(1.0, 0.0)};
  const std::vector<Bsdf> bsdfs = {diffuse_bsdf(RGB(0.5)),
                                   make(MaterialDesc::Type::Mirror),
                                   glass_bsdf(1.5),
                                   conductor(1e-4),
                                   conductor(1.0),
                                   rough_glass(1.5, 1e-4),
                                   rough_glass(1.5, 1.0),
                                   rough_glass(1.0 / 1.5, 0.1),
                                   rough_glass(1.0 + 1e-12, 0.1)};
  int bad = 0, checked = 0;
  for (const Bsdf& b : bsdfs)
    for (const Vec3& wo : dirs) {
      for (const Vec3& wi : dirs)
        for (const TransportMode mode : {TransportMode::Radiance, TransportMode::Importance}) {
          const RGB f = b.f(wo, wi, mode);
          const double p = b.pdf(wo, wi);
          ++checked;
          if (!f.is_finite() || !(f.r >= 0.0) || !std::isfinite(p) || !(p >= 0.0)) ++bad;
        }
      for (const double ul : us)
        for (const double u1 : us)
          for (const double u2 : us) {
            BsdfSample s;
            ++checked;
            if (!b.sample(wo, ul, u1, u2, TransportMode::Radiance, s)) continue;
            if (!femto::is_finite(s.wi) || std::abs(femto::length(s.wi) - 1.0) > 1e-9 ||
                !s.weight.is_finite() || !(s.pdf > 0.0) || !std::isfinite(s.pdf))
              ++bad;
          }
      if (wo.z == 0.0) {  // no side to scatter from
        BsdfSample s;
        CHECK_FALSE(b.sample(wo, 0.5, 0.5, 0.5, TransportMode::Radiance, s));
      }
    }
  INFO(checked << " evaluations");
  CHECK(bad == 0);
}
