#pragma once
// Comparison of a diffusion Monte Carlo run with the analytic references: per time bin, the
// distance between the MC radial profile and the Gaussian (diffusion profile) of the same
// <r^2>, the distances to the diffusion Green's function and to Paasschens' solution, the exact
// values of energy, <r^2> and scattering orders, and the transition time t*.
#include <cmath>
#include <vector>

#include "core/diffusion/simulate.h"

namespace femto::diffusion {

/// Total-variation distance 1/2 sum |p_i - q_i| between two radial distributions given as shell
/// masses (the last entry: beyond r_max), each first normalised to unit sum; NaN if either sum
/// is not positive. 0 for equal shapes, 1 for disjoint ones.
double tv_distance(const std::vector<double>& p, const std::vector<double>& q);

/// MC shell masses of bin j (energy averaged over the bin, per shell, then beyond r_max).
std::vector<double> mc_shell_masses(const DiffusionResult& r, int bin);

struct Transition {
  bool reached = false;     ///< the distance ends (and stays) below the threshold in the window
  bool from_start = false;  ///< below the threshold in every bin
  double t_ps = NAN;  ///< t*: where the last upward crossing ends, interpolated between bin centres
};
/// The time after which d (one value per bin, NaN counting as above) stays below `threshold`.
Transition transition_time(const TimeAxis& axis, const std::vector<double>& d, double threshold);

/// Distances are computed only where the MC rms radius spans at least this many shells
/// (NaN before: an unresolved profile sits in the first shells and would look Gaussian).
constexpr double kMinShellsPerRms = 3;

struct Analysis {
  // Per time bin.
  std::vector<double> gaussian_distance;    ///< MC vs Gaussian of the MC's own <r^2>
  std::vector<double> gaussian_noise;       ///< expected distance from MC noise alone (noise floor)
  std::vector<double> diffusion_distance;   ///< MC vs the diffusion Green's function (shapes)
  std::vector<double> paasschens_distance;  ///< MC vs Paasschens (shapes)
  std::vector<double> energy_exact, r2_exact, unscattered_exact, single_exact;
  /// Models averaged over the MC's cells, energy density 1/mm^3, index bin * shells + shell.
  std::vector<double> u_diffusion, u_paasschens;
  double threshold = 0.05;
  Transition gaussian, diffusion, paasschens;  ///< t* of each distance at `threshold`
  /// Largest |MC - exact| / stderr over well-sampled bins ((value / stderr)^2 >= 100, i.e. at
  /// least ~100 effective photons; rounding-level errors of exact quantities excluded); NaN if
  /// none.
  double energy_max_z = NAN, r2_max_z = NAN, unscattered_max_z = NAN, single_max_z = NAN;
};

Analysis analyse(const DiffusionSetup& setup, const DiffusionResult& r, double threshold);

/// Per bin: the distance between the MC radial profile and the Gaussian of the same <r^2>
/// (NaN where the rms radius spans fewer than kMinShellsPerRms shells).
std::vector<double> gaussian_distances(const DiffusionSetup& setup, const DiffusionResult& r);

/// t* with its uncertainty and the role of Monte Carlo noise.
struct TransitionConfidence {
  int batches = 0;         ///< jackknife replicates (batches of the run); < 2: no interval
  int replicates_reached = 0;  ///< replicates whose distance settles below the threshold
  double se_ps = NAN;      ///< jackknife standard error of t*
  double ci_lo_ps = NAN, ci_hi_ps = NAN;  ///< 95% interval, t* -+ t_{B-1} se (Student), clipped to the window
  double noise_at_t_star = NAN;  ///< noise floor of the distance at t* (interpolated)
  /// t* of the distance minus its noise floor (clamped at 0): subtracting the floor
  /// over-corrects, so this is an early bound and the plain t* a late one.
  Transition floor_subtracted;
  /// The noise floor decides t*: at t* it is at least half the threshold, or t* moves by more
  /// than a quarter of itself between the two bounds. Such a t* is flagged, not trusted.
  bool noise_limited = false;
};

/// Jackknife over the run's batches (each replicate leaves one batch out and recomputes t*),
/// and the noise-floor diagnostics of a.gaussian.
TransitionConfidence transition_confidence(const DiffusionSetup& setup, const DiffusionResult& r,
                                           const Analysis& a);

/// Two-sided 95% quantile of Student's t with `dof` degrees of freedom (1.96 for large dof).
double student_t95(int dof);

}  // namespace femto::diffusion
