#pragma once
// Outputs of `femto diffusion` (docs/diffusion.md): fluence.csv, moments.csv, models.csv,
// fluence_models.csv, summary.json, fluence.png (log fluence vs radius at chosen times: MC,
// diffusion, Paasschens) and distance.png (distances to the models vs time, t*).
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "core/diffusion/analysis.h"

namespace femto::diffusion {

struct ReportOptions {
  std::string dir;                                   ///< output folder (must exist)
  std::vector<double> plot_times;                    ///< ps, inside the time window
  std::vector<double> thresholds{0.02, 0.05, 0.10};  ///< t* table next to the main threshold
  nlohmann::json run;                                ///< version, command, date... (copied)
};

/// summary.json: inputs, derived scales, t* (main threshold and table), model comparisons.
nlohmann::json summary_json(const DiffusionSetup& setup, const DiffusionResult& r,
                            const Analysis& a, const ReportOptions& opt);

/// Writes every output into opt.dir (each file atomically); returns the file names.
std::vector<std::string> write_report(const DiffusionSetup& setup, const DiffusionResult& r,
                                      const Analysis& a, const ReportOptions& opt);

}  // namespace femto::diffusion
