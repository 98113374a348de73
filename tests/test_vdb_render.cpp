// Rendering through voxel media: time of flight through per-voxel refractive index, agreement
// with the homogeneous medium and with closed forms, and agreement of the distance-sampling
// strategies (mfp, time-uniform, MIS) in a heterogeneous medium.
#include <catch2/catch.hpp>

#include <cmath>
#include <filesystem>
#include <unistd.h>

#include "core/constants.h"
#include "media/phase_hg.h"
#include "media/volume_data.h"
#include "samplers/stats.h"
#include "scene_builders.h"

using namespace femto;
using namespace femto::test;
namespace fs = std::filesystem;

namespace {

std::string temp_path(const std::string& name) {
  const fs::path dir = fs::temp_directory_path() / ("femto_vdb_render_" + std::to_string(getpid()));
  fs::create_directories(dir);
  return (dir / name).string();
}

MediumDesc vdb_medium(const std::string& file, double eta_outside, double g, DistanceSampling sampling,
                      bool trilinear, double albedo = 0.8) {
  MediumDesc m;
  m.name = "vdb";
  m.type = MediumDesc::Type::Vdb;
  m.vdb.file = file;
  m.vdb.sigma_t_scale = 1.0;
  m.vdb.albedo = albedo;
  m.vdb.eta = eta_outside;
  m.vdb.eta_grid = "eta";
  m.vdb.interpolation = trilinear ? VdbMediumDesc::Interpolation::Trilinear : VdbMediumDesc::Interpolation::Nearest;
  m.medium.g = g;
  m.sampling = sampling;
  return m;
}

}  // namespace

// Catches: segment time computed from geometric length instead of OPL, or eta looked up at the
// wrong place: a slab of eta 1.5 and thickness L must delay the view by exactly 0.5 L / c.
TEST_CASE("VDB slab of eta 1.5 delays the ballistic pulse by 0.5 L / c", "[vdb-render]") {
  const double L = 10.0;
  // 20 x 20 x 10 voxels of 1 mm: x, y in [-10, 10], z in [50, 60]; no extinction.
  DenseGrid density(20, 20, 10, 0.0f), eta(20, 20, 10, 1.5f);
  density.update_range();
  eta.update_range();
  const std::string file = temp_path("slab.vdb");
  write_volume(file, density, nullptr, &eta, 1.0, {-10, -10, 50});
  TimeAxis axis;
  axis.bin_width_ps = 2.0;
  const double t_vacuum = (100.0 + 40.0) / kSpeedOfLight;  // camera -> floor -> light
  axis.t_start_ps = t_vacuum - 1.0 - 10 * axis.bin_width_ps;
  axis.bins = 32;
  for (bool trilinear : {false, true}) {
    SceneDesc d;
    d.source = "slab";
    d.camera = ortho_camera({0, 0, 100}, {0, 0, 0}, 1.0, 1, 1);
    d.time = axis;
    d.media.push_back(vdb_medium(file, 1.0, 0.0, DistanceSampling::Mfp, trilinear));
    d.global_medium = 0;
    d.shapes.push_back(quad({-50, -50, 0}, {100, 0, 0}, {0, 100, 0}, diffuse(0.5)));
    LightDesc l;
    l.position = {0, 0, 40};
    l.intensity = RGB(1000.0);
    d.lights.push_back(l);
    const Scene scene(d);
    RenderOptions opt;
    opt.spp = 256;
    opt.quiet = true;
    const TransientFilm film = render(scene, opt).film;
    // With trilinear data the index ramps over the half voxel at each face: the OPL is the same
    // (the ramp is symmetric about the face), so the delay is still exactly 0.5 L / c.
    const int expected_bin = axis.bin_of(t_vacuum + 0.5 * L / kSpeedOfLight);
    REQUIRE(expected_bin == 18);
    for (int i = 0; i < axis.bins; ++i) {
      INFO("trilinear " << trilinear << " bin " << i);
      if (i == expected_bin) REQUIRE(film.transient()[3 * i] > 0.0f);
      else REQUIRE(film.transient()[3 * i] == 0.0f);
    }
  }
}

namespace {
struct SingleScatter {
  double sigma_t, sigma_s, g, eta, h, I;
  TimeAxis axis;
};
// Bin integral of single scattering along x(s) = (0, 0, s) from a point light at (0, h, 0).
double single_scatter_bin(const SingleScatter& p, int bin) {
  auto integrand = [&](double s) {
    const double r = std::sqrt(s * s + p.h * p.h);
    return p.sigma_s * std::exp(-p.sigma_t * (s + r)) * hg_eval(-s / r, p.g) * p.I / (r * r);
  };
  auto s_of_t = [&](double t) {
    const double tau = std::max(t * kSpeedOfLight / p.eta, p.h);
    return (tau * tau - p.h * p.h) / (2.0 * tau);
  };
  const double s0 = s_of_t(p.axis.bin_start_ps(bin)), s1 = s_of_t(p.axis.bin_start_ps(bin + 1));
  return s1 > s0 ? stats::adaptive_simpson(integrand, s0, s1, 1e-12) : 0.0;
}

SceneDesc single_scatter_scene(const MediumDesc& medium, const SingleScatter& p) {
  SceneDesc d;
  d.source = "single scattering";
  d.camera = ortho_camera({0, 0, 0}, {0, 0, 1}, 1e-4, 1, 1);
  d.time = p.axis;
  d.media.push_back(medium);
  d.global_medium = 0;
  LightDesc l;
  l.position = {0, p.h, 0};
  l.intensity = RGB(p.I);
  d.lights.push_back(l);
  return d;
}
}  // namespace

// Catches: a constant voxel medium behaving differently from the homogeneous one (wrong
// sigma_t scale, albedo or eta lookup, time-uniform or MIS weights that are biased).
TEST_CASE("constant VDB medium matches the homogeneous medium and the closed form, every strategy",
          "[vdb-render]") {
  SingleScatter p{0.06, 0.048, 0.4, 1.2, 30.0, 1000.0, {}};
  p.axis.t_start_ps = 100;
  p.axis.bin_width_ps = 20;
  p.axis.bins = 20;
  // sigma_t = 0.06 in a 200 mm cube of 5 mm voxels around the scene; index 1.2 everywhere.
  DenseGrid density(40, 40, 40, 0.06f), eta(40, 40, 40, 1.2f);
  density.update_range();
  eta.update_range();
  const std::string file = temp_path("constant.vdb");
  write_volume(file, density, nullptr, &eta, 5.0, {-100, -100, -100});
  // The homogeneous medium with the same coefficients, for a direct bin-by-bin comparison.
  MediumDesc hom;
  hom.name = "homogeneous";
  hom.medium = HomogeneousMedium{p.sigma_t - p.sigma_s, p.sigma_s, p.g, p.eta};
  const auto hom_films = render_batches(single_scatter_scene(hom, p), 4000, 16, /*max_depth=*/1);
  for (bool trilinear : {false, true}) {
    for (DistanceSampling sampling : {DistanceSampling::Mfp, DistanceSampling::TimeUniform, DistanceSampling::Mis}) {
      const MediumDesc m = vdb_medium(file, 1.2, p.g, sampling, trilinear, p.sigma_s / p.sigma_t);
      const auto films = render_batches(single_scatter_scene(m, p), 4000, 16, /*max_depth=*/1);
      int checked = 0;
      for (int i = 0; i < p.axis.bins; ++i) {
        std::vector<double> v;
        for (const auto& f : films) v.push_back(f.transient()[3 * i]);
        const MeanSE ms = mean_se(v);
        const double expected = single_scatter_bin(p, i);
        INFO("trilinear " << trilinear << " sampling " << static_cast<int>(sampling) << " bin " << i << ": "
                          << ms.mean << " +- " << ms.se << " expected " << expected);
        if (expected == 0.0) {
          CHECK(ms.mean == 0.0);
          continue;
        }
        CHECK(std::abs(ms.mean - expected) < 4.0 * ms.se + 1e-9 * expected);
        std::vector<double> h;
        for (const auto& f : hom_films) h.push_back(f.transient()[3 * i]);
        const MeanSE mh = mean_se(h);
        CHECK(std::abs(ms.mean - mh.mean) < 4.0 * std::sqrt(ms.se * ms.se + mh.se * mh.se));
        ++checked;
      }
      CHECK(checked >= 15);
    }
  }
}

// Catches: strategy-dependent bias in a heterogeneous medium with varying index (pdfs of the
// other strategy not exact, OPL mapped back to distance wrongly, time stamps differing).
// [statistical]: a long agreement test, left out of the sanitizer run (31 s there); the case
// above runs every strategy through a voxel medium under the sanitizers.
TEST_CASE("mfp, time-uniform and MIS agree in a heterogeneous medium with varying eta",
          "[vdb-render][statistical]") {
  const int n = 24;
  DenseGrid density(n, n, n), eta(n, n, n);
  Rng rng(2024, 7);
  for (int k = 0; k < n; ++k)
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i) {
        const double x = (i - 11.5) / 12, y = (j - 11.5) / 12, z = (k - 11.5) / 12;
        density.at(i, j, k) = static_cast<float>(0.08 * (1.2 + std::sin(5 * x) * std::cos(4 * y + z)) * rng.uniform());
        eta.at(i, j, k) = static_cast<float>(1.0 + 0.5 * (0.5 + 0.5 * std::sin(3 * x + 2 * z)));
      }
  density.update_range();
  eta.update_range();
  const std::string file = temp_path("hetero.vdb");
  write_volume(file, density, nullptr, &eta, 2.5, {-30, -30, -30});
  SingleScatter p{0, 0, 0.3, 1.0, 12.0, 1000.0, {}};
  p.axis.t_start_ps = 0;
  p.axis.bin_width_ps = 25;
  p.axis.bins = 16;
  for (bool trilinear : {false, true}) {
    std::vector<std::vector<double>> means, ses;
    for (DistanceSampling sampling : {DistanceSampling::Mfp, DistanceSampling::TimeUniform, DistanceSampling::Mis}) {
      const MediumDesc m = vdb_medium(file, 1.0, p.g, sampling, trilinear, 0.9);
      const SceneDesc d = single_scatter_scene(m, p);
      const auto films = render_batches(d, 4000, 16, /*max_depth=*/3);
      std::vector<double> mu, se;
      for (int i = 0; i < p.axis.bins; ++i) {
        std::vector<double> v;
        for (const auto& f : films) v.push_back(f.transient()[3 * i]);
        const MeanSE ms = mean_se(v);
        mu.push_back(ms.mean);
        se.push_back(ms.se);
      }
      means.push_back(mu);
      ses.push_back(se);
    }
    int nonzero = 0;
    for (int i = 0; i < p.axis.bins; ++i) {
      if (means[0][i] > 0) ++nonzero;
      for (int a = 0; a < 3; ++a)
        for (int b = a + 1; b < 3; ++b) {
          const double tol = 4.0 * std::sqrt(ses[a][i] * ses[a][i] + ses[b][i] * ses[b][i]);
          INFO("trilinear " << trilinear << " bin " << i << ": strategy " << a << " " << means[a][i] << " +- "
                            << ses[a][i] << " vs strategy " << b << " " << means[b][i] << " +- " << ses[b][i]);
          CHECK(std::abs(means[a][i] - means[b][i]) <= tol + 1e-12);
        }
    }
    CHECK(nonzero >= 8);
  }
}
