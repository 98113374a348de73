#pragma once
// Monte Carlo of an isotropic delta-pulse point source at the origin at t = 0: exact
// track-length tallies of energy density, energy, <r^2>, <r^4> and low scattering orders over
// radial shells and time bins, with per-photon standard errors. Multi-threaded (oneTBB) and
// bit-identical for any thread count: photon i always uses Rng::for_sample(seed, i, 0), photons
// are summed in order within fixed batches and batches are reduced in order.
#include <atomic>
#include <cstdint>
#include <vector>

#include "core/diffusion/tally.h"
#include "core/diffusion/transport.h"
#include "media/homogeneous.h"

namespace femto::distributed {
class Comm;
}
namespace femto::diffusion {

struct DiffusionSetup {
  HomogeneousMedium medium;
  Absorption absorption = Absorption::Weighted;
  Grid grid;
  uint64_t photons = 1000000;
  uint64_t seed = 1;
  int threads = 0;    ///< 0 = all cores
  bool quiet = true;  ///< no progress on stderr
  /// Normalise <r^2>, <r^4> and the scattering-order fractions by the Monte Carlo energy in each
  /// bin instead of the exact exp(-sigma_a v t) of `medium` (for heterogeneous media, where no
  /// closed form exists; a ratio estimator, consistent, with errors combined as independent).
  bool normalise_by_energy = false;
  /// Ends the run early, between rounds of batches, with the photons traced so far (an unbiased
  /// estimate from fewer photons): a flag set from outside (Ctrl-C), and a time budget.
  const std::atomic<bool>* stop = nullptr;
  double max_seconds = 0;  ///< 0: no limit
  /// Independent batches (contiguous photon ranges) kept apart for confidence intervals of
  /// derived values such as t* (jackknife); 1: none.
  int batches = 10;
  /// The processes sharing the run (core/distributed/comm.h; nullptr: this one alone): each round
  /// of work units is cut into one contiguous range per rank, folded in unit order on rank 0.
  const distributed::Comm* comm = nullptr;
};

/// Means and standard errors per unit emitted energy. Per-bin values are averages over the bin.
struct DiffusionResult {
  Grid grid;
  /// Energy density averaged over shell and bin, 1/mm^3, index bin * shells + shell.
  std::vector<double> u, u_err;
  /// Energy in the medium (all radii).
  std::vector<double> energy, energy_err;
  /// int r^2 u dV and int r^4 u dV divided by the exact mean energy exp(-sigma_a v t) (both
  /// averaged over the bin): unbiased estimates of <r^2> (mm^2) and <r^4> (mm^4) in both
  /// absorption modes, since absorption does not change the normalised distribution.
  std::vector<double> r2, r2_err, r4, r4_err;
  /// Fractions of the (exact mean) energy present that are unscattered and singly scattered.
  std::vector<double> unscattered, unscattered_err, single, single_err;
  uint64_t photons = 0, segments = 0;  ///< photons traced (fewer than asked when stopped early)
  /// Per batch: the sums of the per-photon integrals (TallyLayout order) and the photons traced.
  std::vector<std::vector<double>> batch_sum;
  std::vector<uint64_t> batch_photons;
  bool stopped_early = false;
  int threads = 0;
  double seconds = 0;

  size_t cell(int shell, int bin) const { return static_cast<size_t>(bin) * grid.shells + shell; }
};

/// Runs setup.photons photons through `transport` (the source sits at the origin at t = 0);
/// per-bin normalisations use setup.medium's absorption.
DiffusionResult simulate(const DiffusionSetup& setup, const PhotonTransport& transport);
/// The infinite homogeneous medium setup.medium with setup.absorption.
DiffusionResult simulate(const DiffusionSetup& setup);

/// Means and standard errors from sums over photons (what simulate returns, without timing
/// and batches); with the photons of one batch removed, a jackknife replicate.
DiffusionResult estimate(const DiffusionSetup& setup, const TallySums& sums);

}  // namespace femto::diffusion
