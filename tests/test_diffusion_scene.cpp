// femto diffusion with the source inside a voxel medium: a constant grid must reproduce the
// infinite homogeneous medium's energy decay and exact <r^2>(t).
#include <catch2/catch.hpp>

#include <cmath>

#include "core/constants.h"
#include "core/diffusion/analysis.h"
#include "core/diffusion/simulate.h"
#include "core/diffusion/transport.h"
#include "media/volume_data.h"

using namespace femto;
using namespace femto::diffusion;

// Catches: voxel transport with the wrong speed (time from distance instead of optical path
// length), wrong albedo or collision rate, or moments mis-normalised by the measured energy.
TEST_CASE("voxel-medium source reproduces the homogeneous energy decay and <r^2>", "[diffusion]") {
  const double sigma_t = 2.5, albedo = 0.8, g = 0.5, eta = 1.1;
  const int n = 40;  // 40 mm cube of 1 mm voxels around the source
  VolumeData v{};
  v.density = DenseGrid(n, n, n, static_cast<float>(sigma_t));
  const double g2w[12] = {1, 0, 0, -20, 0, 1, 0, -20, 0, 0, 1, -20};
  const double w2g[12] = {1, 0, 0, 20, 0, 1, 0, 20, 0, 0, 1, 20};
  std::copy(g2w, g2w + 12, v.grid_to_world);
  std::copy(w2g, w2g + 12, v.world_to_grid);
  for (bool trilinear : {false, true}) {
    VdbMediumDesc desc;
    desc.sigma_t_scale = 1.0;
    desc.albedo = albedo;
    desc.eta = eta;
    desc.interpolation = trilinear ? VdbMediumDesc::Interpolation::Trilinear : VdbMediumDesc::Interpolation::Nearest;
    const GridMedium grid(v, desc);
    const VoxelTransport transport(grid, g, Vec3(0.3, -0.2, 0.1));
    DiffusionSetup s;
    s.medium = HomogeneousMedium{(1 - albedo) * sigma_t, albedo * sigma_t, g, eta};
    s.absorption = Absorption::Analog;
    s.normalise_by_energy = true;
    const double vel = kSpeedOfLight / eta;
    const double t_tr = 1 / (s.medium.sigma_s * (1 - g) * vel);
    s.grid.time = TimeAxis{0.0, 6 * t_tr / 12, 12};  // light stays within ~7 mm of the source
    s.grid.shells = 10;
    s.grid.dr = 1.0;
    s.photons = 20000;
    s.seed = 5;
    const DiffusionResult r = simulate(s, transport);
    const Analysis a = analyse(s, r, 0.05);
    const double k = s.medium.sigma_a * vel;
    for (int j = 0; j < s.grid.time.bins; ++j) {
      const double t0 = s.grid.time.bin_start_ps(j), t1 = t0 + s.grid.time.bin_width_ps;
      const double energy = (std::exp(-k * t0) - std::exp(-k * t1)) / (k * (t1 - t0));
      INFO("trilinear " << trilinear << " bin " << j << ": E " << r.energy[j] << " +- " << r.energy_err[j]
                        << " exact " << energy << "; r2 " << r.r2[j] << " +- " << r.r2_err[j] << " exact "
                        << a.r2_exact[j]);
      REQUIRE(r.energy_err[j] > 0);
      CHECK(std::abs(r.energy[j] - energy) <= 4 * r.energy_err[j]);
      CHECK(std::abs(r.r2[j] - a.r2_exact[j]) <= 4 * r.r2_err[j]);
    }
  }
}
