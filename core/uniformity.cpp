#include "core/uniformity.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <nlohmann/json.hpp>

#include "core/constants.h"
#include "core/error.h"
#include "core/io/atomic_file.h"
#include "core/io/plot.h"
#include "core/rng.h"
#include "femto_version.h"
#include "samplers/angular.h"
#include "samplers/distance.h"
#include "samplers/equiangular.h"
#include "samplers/line_to_point.h"
#include "samplers/medium_distance.h"

namespace femto::uniformity {

namespace {


std::string fmt(const char* f, double x) {
  char buf[64];
  std::snprintf(buf, sizeof buf, f, x);
  return buf;
}

// Collects the times of one strategy inside [lo, hi]; values within rounding of an end are
// snapped onto it (a sampler mapping u = 0 to lo may land 1 ulp outside).
struct Collector {
  double lo, hi;
  std::vector<double> times;
  void add(double t) {
    const double slack = 1e-12 * std::max(std::abs(lo), std::abs(hi));
    if (t < lo - slack || t > hi + slack || !std::isfinite(t)) return;
    times.push_back(std::clamp(t, lo, hi));
  }
};

// Groups adjacent bins so that each cell expects at least 5 of the n times: with fewer than
// 5 x bins times the chi-square test would otherwise pool every bin into a single cell.
void merge_bins(const std::vector<double>& counts, double n, std::vector<double>& observed,
                std::vector<double>& expected) {
  const size_t bins = counts.size();
  const size_t per = std::max<size_t>(1, static_cast<size_t>(std::ceil(5.0 * static_cast<double>(bins) / n)));
  const size_t cells = bins / per;  // the last cell takes the remainder
  observed.assign(cells, 0.0);
  expected.assign(cells, 0.0);
  for (size_t b = 0; b < bins && cells > 0; ++b) {
    const size_t k = std::min(b / per, cells - 1);
    observed[k] += counts[b];
    expected[k] += n / static_cast<double>(bins);
  }
}

void fill_statistics(const Config& c, Result& r, const std::vector<double>& times) {
  r.in_range = times.size();
  r.counts.assign(static_cast<size_t>(c.bins), 0.0);
  const double width = r.range_hi_ps - r.range_lo_ps;
  for (double t : times) {
    const int k = std::min(c.bins - 1, static_cast<int>((t - r.range_lo_ps) / width * c.bins));
    r.counts[static_cast<size_t>(std::max(0, k))] += 1.0;
  }
  r.expected_per_bin = static_cast<double>(times.size()) / c.bins;
  if (times.size() < 2) {
    r.note = "fewer than 2 times inside the range: not tested";
    r.chi2 = {NAN, 0, NAN, 0, 0};
    r.ks_d = r.ks_p = NAN;
    r.pass = false;
    return;
  }
  r.ks_d = stats::ks_statistic_uniform(times, r.range_lo_ps, r.range_hi_ps);
  r.ks_p = stats::ks_p_value(r.ks_d, times.size());
  std::vector<double> observed, expected;
  merge_bins(r.counts, static_cast<double>(times.size()), observed, expected);
  if (observed.size() < 2) {
    r.note += std::string(r.note.empty() ? "" : "; ") +
              "fewer than 10 times inside the range: too few for the chi-square test";
    r.chi2 = {NAN, 0, NAN, 0, 0};
    r.pass = false;
    return;
  }
  if (observed.size() < r.counts.size())
    r.note += std::string(r.note.empty() ? "" : "; ") + "adjacent bins merged into " +
              std::to_string(observed.size()) +
             " cells for the chi-square test (at least 5 expected times each)";
  r.chi2 = stats::chi2_test(observed, expected);
  r.pass = r.chi2.p_value >= c.alpha && r.ks_p >= c.alpha;
}

Rng rng_for(const Config& c, Strategy s) {
  return Rng(mix64(c.seed), 1 + static_cast<uint64_t>(s));
}

// Vertex times of subpaths whose segments are exponential with `rate_opl` per mm of optical
// path length (a Poisson process in time: seed 000 Supp. D.1); each subpath runs to t_end.
void subpath_vertex_times(const Config& c, Strategy s, double rate_opl, Result& r) {
  r.range_lo_ps = c.t_start_ps;
  r.range_hi_ps = c.t_end_ps;
  r.valid = true;
  Collector col{r.range_lo_ps, r.range_hi_ps, {}};
  Rng rng = rng_for(c, s);
  // time_uniform goes through the renderer's sampler (rate lambda per mm of OPL); mfp through
  // the exponential of samplers/distance.h with rate sigma_t per mm of distance.
  const DistanceStrategy tu{DistanceSampling::TimeUniform, rate_opl, MisHeuristic::Balance};
  for (uint64_t i = 0; i < c.samples; ++i) {
    double opl = 0;  // mm from the subpath start
    for (;;) {
      if (s == Strategy::TimeUniform) {
        ConstantSegments medium(c.sigma_t, c.eta, kInf);
        opl += sample_distance(medium, tu, rng.uniform()).opl;
      } else {
        opl += c.eta * sample_exponential(c.sigma_t, rng.uniform());
      }
      const double t = opl / kSpeedOfLight;
      if (!(t <= c.t_end_ps)) break;
      col.add(t);
    }
  }
  r.drawn = c.samples;
  fill_statistics(c, r, col.times);
}

}  // namespace

const std::vector<Strategy>& all_strategies() {
  static const std::vector<Strategy> all = {Strategy::Mfp, Strategy::TimeUniform,
                                            Strategy::LineToPoint, Strategy::Angular,
                                            Strategy::Equiangular};
  return all;
}

const char* strategy_name(Strategy s) {
  switch (s) {
    case Strategy::Mfp:
      return "mfp";
    case Strategy::TimeUniform:
      return "time_uniform";
    case Strategy::LineToPoint:
      return "line_to_point";
    case Strategy::Angular:
      return "angular";
    case Strategy::Equiangular:
      return "equiangular";
  }
  return "?";
}

bool parse_strategy(const std::string& name, Strategy& out) {
  for (Strategy s : all_strategies())
    if (name == strategy_name(s)) {
      out = s;
      return true;
    }
  return false;
}

double default_lambda(const Config& c) {
  return 3.5 / (kSpeedOfLight * c.t_end_ps);
}

double expected_vertices(const Config& c, Strategy s) {
  const double opl_end = kSpeedOfLight * c.t_end_ps;
  if (s == Strategy::TimeUniform) return (c.lambda > 0 ? c.lambda : default_lambda(c)) * opl_end;
  if (s == Strategy::Mfp && c.mfp_time == MfpTime::Vertices) return c.sigma_t / c.eta * opl_end;
  return 0.0;
}

double Result::min_p() const {
  return std::fmin(chi2.p_value, ks_p);
}

Result run(const Config& c, Strategy s) {
  if (!(c.sigma_t > 0) || !(c.eta >= 1) || !(c.t_end_ps > c.t_start_ps) || c.samples == 0 ||
      c.bins < 2 || !(c.alpha > 0 && c.alpha < 1) || !(length(c.dir) > 0) || !(c.segment_mm >= 0))
    throw InputError("uniformity: invalid configuration");
  Result r;
  r.strategy = s;
  r.drawn = c.samples;
  const Vec3 w = normalize(c.dir);
  const LineToPointSampler connection(c.sensor, w, c.light, c.eta);
  const LineToPointSampler::Window win = connection.window(c.t_start_ps, c.t_end_ps, 0.0, kInf);
  const auto connection_range = [&](Result& res) {
    res.valid = win.valid;
    // Clamped so that a window end that binds is reproduced exactly (not c t / eta * eta / c).
    res.range_lo_ps = std::max(c.t_start_ps, c.eta * win.L_a / kSpeedOfLight);
    res.range_hi_ps = std::min(c.t_end_ps, c.eta * win.L_b / kSpeedOfLight);
    if (!win.valid)
      res.note = "no vertex on the sensor ray has a connection time inside the window";
  };
  const char* connection_time =
      "sensor -> vertex on the sensor ray -> light, eta (s + |sensor + s dir - light|) / c";

  switch (s) {
    case Strategy::Mfp:
      if (c.mfp_time == MfpTime::Vertices) {
        r.time_definition = "every vertex time of a subpath, eta (s_1 + ... + s_k) / c, to t_end";
        r.pdf = "segments sigma_t exp(-sigma_t s) (Poisson process in time, rate sigma_t c / eta)";
        subpath_vertex_times(c, s, c.sigma_t / c.eta, r);
        return r;
      }
      r.time_definition = connection_time;
      r.pdf = "sigma_t exp(-sigma_t s), s in [0, inf)";
      break;
    case Strategy::TimeUniform:
      r.time_definition = "every vertex time of a subpath, eta (s_1 + ... + s_k) / c, to t_end";
      r.pdf = "segments lambda eta exp(-lambda eta s) (Poisson process in time, rate lambda c)";
      subpath_vertex_times(c, s, c.lambda > 0 ? c.lambda : default_lambda(c), r);
      return r;
    case Strategy::LineToPoint:
      r.time_definition = connection_time;
      r.pdf = "(dL/ds) / (L_b - L_a), L(s) = s + |sensor + s dir - light|";
      break;
    case Strategy::Equiangular:
      r.time_definition = connection_time;
      r.pdf = "h / ((theta_b - theta_a) (h^2 + (s - Delta)^2)) on the window's [s_a, s_b]";
      break;
    case Strategy::Angular: {
      r.time_definition =
          "light -> light + r w -> sensor, eta (r + |light + r w - sensor|) / c, r = --segment";
      r.pdf = "max(r, l) / (4 pi d) per steradian about light -> sensor (window-clipped)";
      const Vec3 to_sensor = c.sensor - c.light;
      const double l = length(to_sensor);
      const AngularTimeSampler ang(c.segment_mm, l, c.eta);
      const AngularTimeSampler::Window aw = ang.window(c.t_start_ps, c.t_end_ps);
      if (!aw.valid || ang.degenerate() || !(l > 0)) {
        r.valid = false;
        r.range_lo_ps = ang.t_min(), r.range_hi_ps = ang.t_max();
        fill_statistics(c, r, {});
        r.note = ang.degenerate() ? "r = 0 or light at the sensor: a single connection time"
                                  : "the window misses the connection times of this segment";
        return r;
      }
      r.valid = true;
      const double gap = std::abs(l - c.segment_mm);
      r.range_lo_ps = std::max(c.t_start_ps, c.eta * (c.segment_mm + gap + aw.e_a) / kSpeedOfLight);
      r.range_hi_ps = std::min(c.t_end_ps, c.eta * (c.segment_mm + gap + aw.e_b) / kSpeedOfLight);
      const Vec3 axis = to_sensor / l;
      Collector col{r.range_lo_ps, r.range_hi_ps, {}};
      Rng rng = rng_for(c, s);
      for (uint64_t i = 0; i < c.samples; ++i) {
        const double u1 = rng.uniform(), u2 = rng.uniform();
        const Vec3 dir = ang.sample_direction(axis, aw, u1, u2);
        // The time from the geometry, not from the sampler's own d: an independent check.
        const Vec3 y = c.light + c.segment_mm * dir;
        col.add(c.eta * (c.segment_mm + length(c.sensor - y)) / kSpeedOfLight);
      }
      fill_statistics(c, r, col.times);
      return r;
    }
  }

  // The distance strategies on the sensor ray, timed by the connection through the vertex.
  connection_range(r);
  if (!r.valid) {
    fill_statistics(c, r, {});
    r.note = "no vertex on the sensor ray has a connection time inside the window";
    return r;
  }
  const EquiangularSampler equi(c.sensor, w, c.light, win.s_a, win.s_b);
  if (s == Strategy::Equiangular && !equi.valid()) {
    r.valid = false;
    fill_statistics(c, r, {});
    r.note = "the light lies on the sensor ray inside the range: no equiangular density";
    return r;
  }
  Collector col{r.range_lo_ps, r.range_hi_ps, {}};
  Rng rng = rng_for(c, s);
  for (uint64_t i = 0; i < c.samples; ++i) {
    const double u = rng.uniform();
    double dist = 0;
    if (s == Strategy::Mfp)
      dist = sample_exponential(c.sigma_t, u);
    else if (s == Strategy::LineToPoint)
      dist = connection.sample(win, u);
    else
      dist = equi.sample(u);
    col.add(connection.time(dist));
  }
  fill_statistics(c, r, col.times);
  return r;
}

std::string format_table(const std::vector<Result>& results) {
  std::string out;
  char line[256];
  std::snprintf(line, sizeof line, "%-14s %10s %10s %21s %11s %4s %9s %8s %9s  %s\n", "strategy",
                "N", "in range", "range (ps)", "chi2", "dof", "p", "KS D", "p", "result");
  out += line;
  for (const Result& r : results) {
    char range[64];
    std::snprintf(range, sizeof range, "%.4g..%.4g", r.range_lo_ps, r.range_hi_ps);
    std::snprintf(line, sizeof line, "%-14s %10llu %10llu %21s %11.4g %4d %9.3g %8.4f %9.3g  %s\n",
                  strategy_name(r.strategy), static_cast<unsigned long long>(r.drawn),
                  static_cast<unsigned long long>(r.in_range), range, r.chi2.chi2, r.chi2.dof,
                  r.chi2.p_value, r.ks_d, r.ks_p,
                  r.pass ? "uniform" : (r.valid && r.chi2.dof > 0 ? "NOT uniform" : "untested"));
    out += line;
  }
  return out;
}

namespace {

nlohmann::json num(double x) {
  return std::isfinite(x) ? nlohmann::json(x) : nlohmann::json();
}

void write_png(const std::string& path, const Config& c, const std::vector<Result>& results) {
  const Rgb8 black{20, 20, 20}, blue{31, 119, 180}, red{214, 39, 40};
  const int n = static_cast<int>(results.size());
  const int cols = n <= 3 ? n : 3, rows = (n + cols - 1) / cols;
  const int pw = 560, ph = 400;
  Canvas canvas(cols * pw, rows * ph);
  for (int k = 0; k < n; ++k) {
    const Result& r = results[static_cast<size_t>(k)];
    Plot p;
    p.x_label = "t (ps)";
    p.y_label = "samples per bin";
    p.title = std::string(strategy_name(r.strategy)) + ": " +
              (r.in_range >= 2
                   ? "chi2 p = " + fmt("%.2g", r.chi2.p_value) + ", ks p = " + fmt("%.2g", r.ks_p)
                   : std::string("untested"));
    p.x_min = r.range_lo_ps, p.x_max = r.range_hi_ps;
    p.y_min = 0;
    PlotSeries hist{"histogram", {}, {}, r.pass ? blue : red, PlotSeries::Style::Line};
    const double width = (r.range_hi_ps - r.range_lo_ps) / c.bins;
    double ymax = r.expected_per_bin;
    for (int b = 0; b < c.bins && !r.counts.empty(); ++b) {  // a step line
      const double y = r.counts[static_cast<size_t>(b)];
      hist.x.push_back(r.range_lo_ps + b * width), hist.y.push_back(y);
      hist.x.push_back(r.range_lo_ps + (b + 1) * width), hist.y.push_back(y);
      ymax = std::max(ymax, y);
    }
    p.y_max = ymax > 0 ? 1.15 * ymax : 1.0;
    PlotSeries uni{"uniform",
                   {r.range_lo_ps, r.range_hi_ps},
                   {r.expected_per_bin, r.expected_per_bin},
                   black,
                   PlotSeries::Style::Dashed};
    p.series = {hist, uni};
    if (!(r.range_hi_ps > r.range_lo_ps)) p.x_min = p.x_max = NAN;
    draw_plot(canvas, (k % cols) * pw, (k / cols) * ph, pw, ph, p, 2);
  }
  write_canvas_png(path, canvas);
}

}  // namespace

std::vector<std::string> write_report(const std::string& dir_in, const Config& c,
                                      const std::vector<Result>& results,
                                      const std::string& command_line) {
  const std::string dir = dir_in.empty() || dir_in.back() == '/' ? dir_in : dir_in + "/";
  std::vector<std::string> files;
  nlohmann::json strategies = nlohmann::json::array();
  for (const Result& r : results) {
    const std::string name = std::string("hist_") + strategy_name(r.strategy) + ".csv";
    std::string csv = "bin,t_lo_ps,t_hi_ps,count,expected\n";
    const double width = (r.range_hi_ps - r.range_lo_ps) / c.bins;
    for (size_t b = 0; b < r.counts.size(); ++b) {
      char line[160];
      std::snprintf(line, sizeof line, "%zu,%.10g,%.10g,%.0f,%.10g\n", b,
                    r.range_lo_ps + static_cast<double>(b) * width,
                    r.range_lo_ps + static_cast<double>(b + 1) * width, r.counts[b],
                    r.expected_per_bin);
      csv += line;
    }
    write_text_atomically(dir + name, csv);
    files.push_back(name);
    strategies.push_back({{"strategy", strategy_name(r.strategy)},
                          {"time", r.time_definition},
                          {"pdf", r.pdf},
                          {"valid", r.valid},
                          {"note", r.note},
                          {"range_ps", {num(r.range_lo_ps), num(r.range_hi_ps)}},
                          {"drawn", r.drawn},
                          {"in_range", r.in_range},
                          {"expected_vertices_per_subpath", expected_vertices(c, r.strategy)},
                          {"bins", c.bins},
                          {"expected_per_bin", r.expected_per_bin},
                          {"chi2", num(r.chi2.chi2)},
                          {"chi2_dof", r.chi2.dof},
                          {"chi2_cells_pooled", r.chi2.cells_pooled},
                          {"chi2_p", num(r.chi2.p_value)},
                          {"ks_d", num(r.ks_d)},
                          {"ks_p", num(r.ks_p)},
                          {"uniform", r.pass},
                          {"histogram", name}});
  }
  const nlohmann::json summary = {
      {"femto_version", FEMTO_VERSION},
      {"command", command_line},
      {"config",
       {{"sigma_t_per_mm", c.sigma_t},
        {"eta", c.eta},
        {"t_start_ps", c.t_start_ps},
        {"t_end_ps", c.t_end_ps},
        {"sensor_mm", {c.sensor.x, c.sensor.y, c.sensor.z}},
        {"dir", {c.dir.x, c.dir.y, c.dir.z}},
        {"light_mm", {c.light.x, c.light.y, c.light.z}},
        {"segment_mm", c.segment_mm},
        {"lambda_per_mm_opl", c.lambda > 0 ? c.lambda : default_lambda(c)},
        {"mfp_time", c.mfp_time == MfpTime::Vertices ? "vertices" : "connection"},
        {"samples", c.samples},
        {"seed", c.seed},
        {"bins", c.bins},
        {"alpha", c.alpha},
        {"mean_free_time_ps", c.eta / (c.sigma_t * kSpeedOfLight)}}},
      {"test",
       "chi-square of the bin counts against in_range / bins each (cells with expected < 5 "
       "pooled; dof = cells - 1) and Kolmogorov-Smirnov against U(range); uniform when both "
       "p-values >= alpha"},
      {"strategies", strategies}};
  write_text_atomically(dir + "summary.json", summary.dump(2) + "\n");
  files.push_back("summary.json");
  write_png(dir + "histograms.png", c, results);
  files.push_back("histograms.png");
  return files;
}

}  // namespace femto::uniformity
