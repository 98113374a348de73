#pragma once
// `femto uniformity`: how uniformly in time do the distance, line-to-point, angular and
// equiangular samplers place their samples? Each strategy draws samples in a canonical
// configuration (a sensor ray through a homogeneous medium and a point light), histograms the
// time each sample produces over its valid range inside the window, and tests it against the
// uniform distribution with chi-square and Kolmogorov-Smirnov (docs/uniformity.md).
#include <cstdint>
#include <string>
#include <vector>

#include "core/vec3.h"
#include "samplers/stats.h"

namespace femto::uniformity {

enum class Strategy { Mfp, TimeUniform, LineToPoint, Angular, Equiangular };
/// All strategies, in the order they are run and reported.
const std::vector<Strategy>& all_strategies();
const char* strategy_name(Strategy s);
/// False for an unknown name.
bool parse_strategy(const std::string& name, Strategy& out);

/// Which time the mfp strategy histograms: the sensor -> vertex -> light connection time of one
/// vertex on the sensor ray (default), or every vertex time of a subpath (the Poisson view of
/// seed 000 Supp. D.1, in which any exponential rate, sigma_t included, is time-uniform).
enum class MfpTime { Connection, Vertices };

struct Config {
  double sigma_t = 0.1;  ///< extinction, 1/mm (mfp rate)
  double eta = 1.0;      ///< refractive index of the medium
  double t_start_ps = 0, t_end_ps = 1000;
  Vec3 sensor{0, 0, 0}, dir{0, 0, 1};  ///< the sensor ray (dir need not be unit length)
  Vec3 light{20, 0, 10};
  double segment_mm = 10;  ///< angular: segment length r from the light
  double lambda = 0;       ///< time_uniform rate per mm of optical path length; 0 = default_lambda
  MfpTime mfp_time = MfpTime::Connection;
  uint64_t samples = 100000;  ///< samples (or subpaths) drawn per strategy
  uint64_t seed = 1;
  int bins = 50;
  double alpha = 0.01;  ///< significance of the uniformity tests
};

/// 3.5 / (c t_end): about 3.5 vertices per subpath before the window end (as in render).
double default_lambda(const Config& c);
/// Expected number of vertex times a subpath strategy stores per subpath (0 for the others).
double expected_vertices(const Config& c, Strategy s);

struct Result {
  Strategy strategy;
  std::string time_definition;  ///< which time is histogrammed
  std::string pdf;              ///< the sampling density, in words
  bool valid = false;           ///< false: the valid range is empty (see note)
  std::string note;
  double range_lo_ps = 0, range_hi_ps = 0;  ///< histogram range: window x reachable times
  uint64_t drawn = 0;                       ///< samples (or subpaths) drawn
  uint64_t in_range = 0;        ///< times inside the range (all vertex times for subpaths)
  std::vector<double> counts;   ///< per bin
  double expected_per_bin = 0;  ///< in_range / bins
  stats::Chi2Result chi2{};     ///< against uniform; dof = cells - 1
  double ks_d = 0, ks_p = 0;
  bool pass = false;  ///< valid, at least 2 times, and chi-square and KS p-values >= alpha
  double min_p() const;
};

/// Runs one strategy (deterministic for a given config). Throws InputError for a config that
/// the command line would reject.
Result run(const Config& c, Strategy s);

/// Files written into dir (created by the caller): hist_<strategy>.csv per result,
/// summary.json and histograms.png, each atomically. Returns their names.
std::vector<std::string> write_report(const std::string& dir, const Config& c,
                                      const std::vector<Result>& results,
                                      const std::string& command_line);

/// The printed table: strategy, N, in range, range, chi2, dof, p, KS D, p, result.
std::string format_table(const std::vector<Result>& results);

}  // namespace femto::uniformity
