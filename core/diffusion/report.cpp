#include "core/diffusion/report.h"

#include <algorithm>
#include <cstdio>

#include "core/diffusion/models.h"
#include "core/io/atomic_file.h"
#include "core/io/font.h"
#include "core/io/plot.h"

namespace femto::diffusion {

namespace {

constexpr Rgb8 kBlack{20, 20, 20}, kBlue{31, 119, 180}, kOrange{255, 127, 14}, kGrey{150, 150, 150},
    kRed{214, 39, 40};

// CSV number: 9 significant digits, "nan" for undefined values.
void put(std::string& s, double x, bool last = false) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.9g", x);
  s += buf;
  s += last ? '\n' : ',';
}

std::string fmt(const char* f, double x) {
  char buf[64];
  std::snprintf(buf, sizeof buf, f, x);
  return buf;
}

// JSON number, null when not finite (JSON has no NaN).
nlohmann::json num(double x) {
  return std::isfinite(x) ? nlohmann::json(x) : nlohmann::json(nullptr);
}

nlohmann::json transition_json(const Transition& t, const Scales& sc, const HomogeneousMedium& m) {
  nlohmann::json j = {{"reached", t.reached},
                      {"below_from_window_start", t.from_start},
                      {"t_star_ps", num(t.t_ps)}};
  j["t_star_mean_free_times"] = num(t.t_ps / sc.mean_free_time);
  j["t_star_transport_mean_free_paths"] = num(t.t_ps * sc.v * sc.sigma_tr);
  j["t_star_mean_scatterings"] = num(t.t_ps * sc.v * m.sigma_s);
  return j;
}

// The bin holding t; t = t_end (allowed for plot times) belongs to the last bin.
int bin_for(const Grid& g, double t) {
  const int j = g.time.bin_of(t);
  return j >= 0 ? j : (t >= g.time.t_end_ps() ? g.time.bins - 1 : 0);
}

std::string medium_line(const HomogeneousMedium& m) {
  return "sigma_s = " + fmt("%g", m.sigma_s) + "/mm, sigma_a = " + fmt("%g", m.sigma_a) +
         "/mm, g = " + fmt("%g", m.g) + ", eta = " + fmt("%g", m.eta);
}

void write_fluence_png(const std::string& path, const DiffusionSetup& setup,
                       const DiffusionResult& r, const Analysis& a,
                       const std::vector<double>& times) {
  const Grid& g = r.grid;
  const Scales sc = scales_of(setup.medium);
  const int n = static_cast<int>(times.size());
  const int cols = n <= 3 ? n : (n + 1) / 2, rows = (n + cols - 1) / cols;
  const int pw = 640, ph = 440, header = 40;
  Canvas canvas(cols * pw, rows * ph + header);
  const uint8_t ink[3] = {kBlack.r, kBlack.g, kBlack.b};
  const std::string head = "fluence rate vs radius: " + medium_line(setup.medium);
  font::draw_text(canvas.rgb.data(), canvas.width, canvas.height,
                  (canvas.width - font::text_width(head, 2)) / 2, 12, head, 2, ink);
  for (int k = 0; k < n; ++k) {
    const int j = bin_for(g, times[static_cast<size_t>(k)]);
    Plot p;
    p.log_y = true;
    p.x_label = "r (mm)";
    p.y_label = "fluence rate (1/mm2/ps)";
    p.x_min = 0, p.x_max = g.r_max();
    const double t = g.time.bin_center_ps(j);
    const double d = a.gaussian_distance[static_cast<size_t>(j)];
    p.title = "t = " + fmt("%.3g", t) + " ps = " + fmt("%.3g", t / sc.mean_free_time) + " mft, " +
              (std::isfinite(d) ? "d = " + fmt("%.3g", 100 * d) + "%" : "unresolved");
    PlotSeries mc{"monte carlo", {}, {}, kBlack, PlotSeries::Style::Markers};
    PlotSeries dif{"diffusion", {}, {}, kBlue, PlotSeries::Style::Line};
    PlotSeries paa{"paasschens", {}, {}, kOrange, PlotSeries::Style::Dashed};
    double ymax = 0;  // largest value in the panel
    for (int i = 0; i < g.shells; ++i) {
      const size_t c = r.cell(i, j);
      const double x = g.shell_center(i);
      mc.x.push_back(x), mc.y.push_back(r.u[c] * sc.v);
      dif.x.push_back(x), dif.y.push_back(a.u_diffusion[c] * sc.v);
      paa.x.push_back(x), paa.y.push_back(a.u_paasschens[c] * sc.v);
      ymax = std::max(
          {ymax, mc.y.back(), std::isfinite(dif.y.back()) ? dif.y.back() : 0.0, paa.y.back()});
    }
    if (ymax > 0) {
      p.y_max = 2 * ymax, p.y_min = ymax * 1e-6;
      double reach = 0;  // show radii out to where the MC or a model is still above the axis
      for (int i = 0; i < g.shells; ++i)
        for (const PlotSeries* se : {&mc, &dif, &paa})
          if (se->y[static_cast<size_t>(i)] > p.y_min) reach = std::max(reach, (i + 1) * g.dr);
      p.x_max = std::min(g.r_max(), 1.1 * reach);
    }
    p.series = {mc, dif, paa};  // lines over the markers, so a model hidden by the data still shows
    draw_plot(canvas, (k % cols) * pw, header + (k / cols) * ph, pw, ph, p, 2);
  }
  write_canvas_png(path, canvas);
}

void write_distance_png(const std::string& path, const DiffusionSetup& setup,
                        const DiffusionResult& r, const Analysis& a) {
  const Grid& g = r.grid;
  const Scales sc = scales_of(setup.medium);
  Plot p;
  p.log_y = true;
  p.x_label = "t (ps)";
  p.y_label = "distance (total variation)";
  p.y_min = 1e-3, p.y_max = 1;
  p.x_min = g.time.t_start_ps, p.x_max = g.time.t_end_ps();
  // The 5x7 font has no '*' or '<': spelled out.
  p.title =
      a.gaussian.reached
          ? "gaussian (distance below " + fmt("%g", 100 * a.threshold) +
                "%) from t = " + fmt("%.3g", a.gaussian.t_ps) +
                " ps = " + fmt("%.3g", a.gaussian.t_ps / sc.mean_free_time) + " mean free times"
          : "not gaussian within the window (threshold " + fmt("%g", 100 * a.threshold) + "%)";
  PlotSeries gau{"gaussian, same r2", {}, {}, kBlack, PlotSeries::Style::Line};
  PlotSeries dif{"diffusion green fn", {}, {}, kBlue, PlotSeries::Style::Line};
  PlotSeries paa{"paasschens", {}, {}, kOrange, PlotSeries::Style::Line};
  PlotSeries noi{"mc noise floor", {}, {}, kGrey, PlotSeries::Style::Dashed};
  for (int j = 0; j < g.time.bins; ++j) {
    const double t = g.time.bin_center_ps(j);
    const size_t J = static_cast<size_t>(j);
    gau.x.push_back(t), gau.y.push_back(a.gaussian_distance[J]);
    dif.x.push_back(t), dif.y.push_back(a.diffusion_distance[J]);
    paa.x.push_back(t), paa.y.push_back(a.paasschens_distance[J]);
    noi.x.push_back(t), noi.y.push_back(a.gaussian_noise[J]);
  }
  PlotSeries thr{
      "threshold", {p.x_min, p.x_max}, {a.threshold, a.threshold}, kRed, PlotSeries::Style::Dashed};
  p.series = {noi, paa, dif, gau, thr};
  if (a.gaussian.reached && !a.gaussian.from_start)
    p.series.push_back({"transition",
                        {a.gaussian.t_ps, a.gaussian.t_ps},
                        {p.y_min, p.y_max},
                        kRed,
                        PlotSeries::Style::Line});
  Canvas canvas(1100, 640);
  draw_plot(canvas, 0, 0, canvas.width, canvas.height, p, 2);
  write_canvas_png(path, canvas);
}

}  // namespace

nlohmann::json summary_json(const DiffusionSetup& setup, const DiffusionResult& r,
                            const Analysis& a, const ReportOptions& opt) {
  const HomogeneousMedium& m = setup.medium;
  const Scales sc = scales_of(m);
  const Grid& g = r.grid;
  nlohmann::json j = opt.run;
  j["inputs"] = {
      {"medium",
       {{"sigma_s_per_mm", m.sigma_s}, {"sigma_a_per_mm", m.sigma_a}, {"g", m.g}, {"eta", m.eta}}},
      {"source",
       "isotropic delta pulse at the origin at t = 0, unit energy, infinite homogeneous medium"},
      {"absorption", setup.absorption == Absorption::Analog ? "analog" : "weighted"},
      {"photons", setup.photons},
      {"seed", setup.seed},
      {"time",
       {{"t_start_ps", g.time.t_start_ps},
        {"t_end_ps", g.time.t_end_ps()},
        {"bins", g.time.bins},
        {"bin_width_ps", g.time.bin_width_ps}}},
      {"radius", {{"r_max_mm", g.r_max()}, {"shells", g.shells}, {"shell_width_mm", g.dr}}},
      {"threshold", a.threshold},
      {"plot_times_ps", opt.plot_times}};
  j["scales"] = {{"speed_mm_per_ps", sc.v},
                 {"sigma_t_per_mm", sc.sigma_t},
                 {"albedo", m.albedo()},
                 {"mean_free_path_mm", num(1 / sc.sigma_t)},
                 {"mean_free_time_ps", num(sc.mean_free_time)},
                 {"transport_mean_free_path_mm", num(1 / sc.sigma_tr)},
                 {"diffusion_coefficient_mm2_per_ps", num(sc.D)}};
  auto table = [&](const std::vector<double>& d) {  // t* for each of opt.thresholds
    nlohmann::json rows = nlohmann::json::array();
    for (double th : opt.thresholds) {
      nlohmann::json row = transition_json(transition_time(g.time, d, th), sc, m);
      row["threshold"] = th;
      rows.push_back(row);
    }
    return rows;
  };
  j["transition"] = transition_json(a.gaussian, sc, m);
  j["transition"]["definition"] =
      "t* = time after which the total-variation distance between the MC radial energy profile and "
      "the "
      "Gaussian (diffusion) profile of the same <r^2> stays below the threshold; linear "
      "interpolation "
      "between bin centres. Bins whose rms radius spans fewer than 3 shells count as above.";
  j["transition"]["threshold"] = a.threshold;
  j["transition"]["by_threshold"] = table(a.gaussian_distance);
  {
    const TransitionConfidence c = transition_confidence(setup, r, a);
    j["transition"]["confidence"] = {
        {"batches", c.batches},
        {"replicates_reached", c.replicates_reached},
        {"t_star_jackknife_se_ps", num(c.se_ps)},
        {"t_star_ci95_ps", {num(c.ci_lo_ps), num(c.ci_hi_ps)}},
        {"t_star_ci95_mean_free_times", {num(c.ci_lo_ps / sc.mean_free_time), num(c.ci_hi_ps / sc.mean_free_time)}},
        {"noise_floor_at_t_star", num(c.noise_at_t_star)},
        {"t_star_noise_subtracted_ps", num(c.floor_subtracted.t_ps)},
        {"noise_limited", c.noise_limited},
        {"method",
         "95% interval t* -+ t(B-1) se, se from the jackknife over B batches (each replicate "
         "leaves one batch out and recomputes t*). The noise floor (the distance MC noise alone "
         "gives) biases the distance upward, so t* is late; t_star_noise_subtracted_ps uses the "
         "distance minus the floor (an over-correction, so an early bound). noise_limited: the "
         "floor is at least half the threshold at t*, or the two differ by more than a quarter of "
         "t*: then the noise, not the medium, decides t*; run more photons or a larger threshold"}};
  }

  double gmin = NAN, noise_max = 0;
  for (size_t k = 0; k < a.gaussian_distance.size(); ++k) {
    if (std::isfinite(a.gaussian_distance[k]))
      gmin = std::isnan(gmin) ? a.gaussian_distance[k] : std::min(gmin, a.gaussian_distance[k]);
    if (std::isfinite(a.gaussian_noise[k])) noise_max = std::max(noise_max, a.gaussian_noise[k]);
  }
  j["transition"]["smallest_distance"] = num(gmin);
  j["transition"]["largest_noise_floor"] = noise_max;

  j["models"] = {
      {"persistent_random_walk",
       {{"formula", "<r^2>(t) = 2 v^2 (t/a - (1 - exp(-a t))/a^2), a = sigma_s (1 - g) v (exact)"},
        {"r2_max_abs_z", num(a.r2_max_z)}}},
      {"diffusion",
       {{"formula",
         "u = exp(-sigma_a v t) (4 pi D t)^(-3/2) exp(-r^2 / (4 D t)), D = v / (3 sigma_s (1 - "
         "g))"},
        {"why_this_D",
         "the exact <r^2> grows as 6 D t at late times with this D, independent of sigma_a"},
        {"distance_below_threshold", transition_json(a.diffusion, sc, m)},
        {"distance_below_threshold_by_threshold", table(a.diffusion_distance)}}},
      {"paasschens",
       {{"formula",
         "Paasschens 1997 3-D interpolation, mean free path ell = 1 / (sigma_s (1 - g)), times "
         "exp(-sigma_a v t)"},
        {"exact_for",
         "isotropic scattering (g = 0) up to the interpolation's ~2% error; g != 0 is an "
         "approximation"},
        {"distance_below_threshold", transition_json(a.paasschens, sc, m)},
        {"distance_below_threshold_by_threshold", table(a.paasschens_distance)}}},
      {"scattering_orders",
       {{"unscattered", "exp(-sigma_s v t)"},
        {"single", "sigma_s v t exp(-sigma_s v t)"},
        {"unscattered_max_abs_z", num(a.unscattered_max_z)},
        {"single_max_abs_z", num(a.single_max_z)}}},
      {"energy",
       {{"formula", "exp(-sigma_a v t)"},
        {"max_abs_z", num(a.energy_max_z)},
        {"note", setup.absorption == Absorption::Analog
                     ? "Monte Carlo estimate (analog absorption)"
                     : "exact by construction with weighted absorption"}}}};
  j["models"]["z_scores"] =
      "max |MC - exact| / stderr over bins with >= 100 effective photons "
      "((value / stderr)^2); null when no bin qualifies or the value is exact";
  nlohmann::json at = nlohmann::json::array();
  for (double t : opt.plot_times) {
    const size_t J = static_cast<size_t>(bin_for(g, t));
    at.push_back(
        {{"t_ps", g.time.bin_center_ps(static_cast<int>(J))},
         {"mean_free_times", g.time.bin_center_ps(static_cast<int>(J)) / sc.mean_free_time},
         {"gaussian_distance", num(a.gaussian_distance[J])},
         {"diffusion_distance", num(a.diffusion_distance[J])},
         {"paasschens_distance", num(a.paasschens_distance[J])},
         {"r2_mm2", r.r2[J]},
         {"r2_exact_mm2", a.r2_exact[J]}});
  }
  j["at_plot_times"] = at;
  j["run"] = {
      {"photons", r.photons},
      {"segments", r.segments},
      {"threads", r.threads},
      {"seconds", r.seconds},
      {"photons_per_second", r.seconds > 0 ? static_cast<double>(r.photons) / r.seconds : 0.0}};
  return j;
}

std::vector<std::string> write_report(const DiffusionSetup& setup, const DiffusionResult& r,
                                      const Analysis& a, const ReportOptions& opt) {
  const Grid& g = r.grid;
  const Scales sc = scales_of(setup.medium);
  const std::string dir = opt.dir + "/";
  std::string fl =
      "t_ps,r_mm,energy_density,energy_density_stderr,fluence_rate,fluence_rate_stderr\n";
  std::string fm = "t_ps,r_mm,fluence_rate_diffusion,fluence_rate_paasschens\n";
  std::string mo =
      "t_ps,energy,energy_stderr,r2_mm2,r2_stderr,r4_mm4,r4_stderr,unscattered,single,gaussian_"
      "distance\n";
  std::string md =
      "t_ps,energy_exact,r2_exact_mm2,r2_diffusion_mm2,unscattered_exact,unscattered_stderr,"
      "single_exact,single_stderr,gaussian_distance_noise,diffusion_distance,paasschens_distance\n";
  for (int j = 0; j < g.time.bins; ++j) {
    const double t = g.time.bin_center_ps(j);
    const size_t J = static_cast<size_t>(j);
    for (int i = 0; i < g.shells; ++i) {
      const size_t c = r.cell(i, j);
      put(fl, t), put(fl, g.shell_center(i)), put(fl, r.u[c]), put(fl, r.u_err[c]);
      put(fl, r.u[c] * sc.v), put(fl, r.u_err[c] * sc.v, true);
      put(fm, t), put(fm, g.shell_center(i)), put(fm, a.u_diffusion[c] * sc.v),
          put(fm, a.u_paasschens[c] * sc.v, true);
    }
    put(mo, t), put(mo, r.energy[J]), put(mo, r.energy_err[J]), put(mo, r.r2[J]),
        put(mo, r.r2_err[J]);
    put(mo, r.r4[J]), put(mo, r.r4_err[J]), put(mo, r.unscattered[J]), put(mo, r.single[J]);
    put(mo, a.gaussian_distance[J], true);
    put(md, t), put(md, a.energy_exact[J]), put(md, a.r2_exact[J]), put(md, 6 * sc.D * t);
    put(md, a.unscattered_exact[J]), put(md, r.unscattered_err[J]), put(md, a.single_exact[J]);
    put(md, r.single_err[J]), put(md, a.gaussian_noise[J]), put(md, a.diffusion_distance[J]);
    put(md, a.paasschens_distance[J], true);
  }
  write_text_atomically(dir + "fluence.csv", fl);
  write_text_atomically(dir + "fluence_models.csv", fm);
  write_text_atomically(dir + "moments.csv", mo);
  write_text_atomically(dir + "models.csv", md);
  write_text_atomically(dir + "summary.json", summary_json(setup, r, a, opt).dump(2) + "\n");
  std::vector<std::string> files = {"fluence.csv", "fluence_models.csv", "moments.csv",
                                    "models.csv", "summary.json"};
  if (!opt.plot_times.empty()) {
    write_fluence_png(dir + "fluence.png", setup, r, a, opt.plot_times);
    files.push_back("fluence.png");
  }
  write_distance_png(dir + "distance.png", setup, r, a);
  files.push_back("distance.png");
  return files;
}

}  // namespace femto::diffusion
