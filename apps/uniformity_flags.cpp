#include "apps/uniformity_flags.h"

#include <cmath>
#include <cstdio>

#include "apps/cli.h"
#include "core/error.h"

namespace femto {

UniformityRequest parse_uniformity_args(const std::vector<std::string>& argv,
                                        const std::string& command) {
  UniformityRequest r;
  cli::Args args(command, argv);
  uniformity::Config c;
  std::vector<uniformity::Strategy> chosen = uniformity::all_strategies();
  std::string out_dir = "femto-uniformity";
  bool expect_uniform = false, quiet = false;
  double t_end_given = NAN;
  while (!args.done()) {
    const std::string a = args.next();
    if (a == "--help" || a == "-h") {
      r.help = true;
      return r;
    } else if (a == "--strategy") {
      const std::string v = args.value();
      uniformity::Strategy s;
      if (v == "all")
        chosen = uniformity::all_strategies();
      else if (uniformity::parse_strategy(v, s))
        chosen = {s};
      else
        args.fail("expected mfp, time_uniform, line_to_point, angular, equiangular or all", v);
    } else if (a == "--sigma-t" || a == "--sigma_t") {
      c.sigma_t = args.number_in(0, 1e6, true, false, "in (0, 1e6] (1/mm)");
    } else if (a == "--eta") {
      c.eta = args.number_in(1, 100, false, false, "in [1, 100]");
    } else if (a == "--t-start") {
      c.t_start_ps = args.number_in(0, 1e9, false, false, "in [0, 1e9] ps");
    } else if (a == "--t-end") {
      t_end_given = args.number_in(0, 1e9, true, false, "in (0, 1e9] ps");
    } else if (a == "--sensor") {
      c.sensor = args.xyz_value();
    } else if (a == "--light") {
      c.light = args.xyz_value();
    } else if (a == "--dir") {
      c.dir = args.xyz_value(true);
    } else if (a == "--segment") {
      c.segment_mm = args.number_in(0, 1e9, false, false, "in [0, 1e9] mm");
    } else if (a == "--lambda") {
      c.lambda = args.number_in(0, 1e9, true, false, "in (0, 1e9] per mm of optical path length");
    } else if (a == "--mfp-time") {
      const std::string v = args.value();
      if (v == "connection")
        c.mfp_time = uniformity::MfpTime::Connection;
      else if (v == "vertices")
        c.mfp_time = uniformity::MfpTime::Vertices;
      else
        args.fail("expected connection or vertices", v);
    } else if (a == "--samples") {
      c.samples = args.count_value(1, 1e7);
    } else if (a == "--seed") {
      c.seed = args.uint_value();
    } else if (a == "--bins") {
      c.bins = static_cast<int>(args.int_value(2, 10000));
    } else if (a == "--alpha") {
      c.alpha = args.number_in(0, 1, true, true, "in (0, 1)");
    } else if (a == "--out") {
      out_dir = args.value();
      if (out_dir.empty()) args.fail("expects a folder", "");
    } else if (a == "--expect") {
      const std::string v = args.value();
      if (v != "uniform") args.fail("expected 'uniform'", v);
      expect_uniform = true;
    } else if (a == "--quiet" || a == "-q") {
      quiet = true;
    } else {
      args.fail("unknown option (see femto uniformity --help)", a);
    }
  }

  // Cross-flag checks, all before anything is written.
  auto fail = [&command](const std::string& flag, const std::string& problem, double got) {
    char buf[64];
    std::snprintf(buf, sizeof buf, "%g", got);
    throw InputError(command + ": " + flag + ": " + problem + " (got '" + buf + "')");
  };
  if (std::isfinite(t_end_given)) c.t_end_ps = t_end_given;
  if (!(c.t_end_ps > c.t_start_ps)) {
    char start[64];
    std::snprintf(start, sizeof start, "%g", c.t_start_ps);
    fail("--t-end", std::string("must be greater than --t-start (") + start + " ps)", c.t_end_ps);
  }
  for (uniformity::Strategy s : chosen) {
    const double stored = uniformity::expected_vertices(c, s) * static_cast<double>(c.samples);
    if (stored > 5e7)
      fail("--samples",
           std::string("the ") + uniformity::strategy_name(s) + " subpaths would store about " +
               std::to_string(static_cast<long long>(stored)) +
               " vertex times (limit 5e7); lower --samples, the window or the rate",
           static_cast<double>(c.samples));
  }

  r.config = c;
  r.strategies = chosen;
  r.out_dir = out_dir;
  r.expect_uniform = expect_uniform;
  r.quiet = quiet;
  return r;
}

}  // namespace femto
