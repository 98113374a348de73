#include "core/diffusion/analysis.h"

#include <algorithm>

#include "core/diffusion/models.h"

namespace femto::diffusion {

double tv_distance(const std::vector<double>& p, const std::vector<double>& q) {
  double sp = 0, sq = 0;
  for (double x : p) sp += x;
  for (double x : q) sq += x;
  if (!(sp > 0) || !(sq > 0) || p.size() != q.size()) return NAN;
  double d = 0;
  for (size_t i = 0; i < p.size(); ++i) d += std::abs(p[i] / sp - q[i] / sq);
  return 0.5 * d;
}

std::vector<double> mc_shell_masses(const DiffusionResult& r, int bin) {
  const Grid& g = r.grid;
  std::vector<double> m(static_cast<size_t>(g.shells) + 1);
  double inside = 0;
  for (int i = 0; i < g.shells; ++i)
    inside += m[static_cast<size_t>(i)] = r.u[r.cell(i, bin)] * g.shell_volume(i);
  m.back() = std::max(0.0, r.energy[static_cast<size_t>(bin)] - inside);  // energy beyond r_max
  return m;
}

Transition transition_time(const TimeAxis& axis, const std::vector<double>& d, double threshold) {
  Transition tr;
  int last_above = -1;
  for (int j = 0; j < static_cast<int>(d.size()); ++j)
    if (!(d[static_cast<size_t>(j)] < threshold)) last_above = j;
  if (last_above == static_cast<int>(d.size()) - 1) return tr;
  tr.reached = true;
  if (last_above < 0) {
    tr.from_start = true;
    tr.t_ps = axis.t_start_ps;
    return tr;
  }
  const double d0 = d[static_cast<size_t>(last_above)], d1 = d[static_cast<size_t>(last_above) + 1];
  const double f = std::isfinite(d0) && d0 > d1 ? (d0 - threshold) / (d0 - d1) : 1.0;
  tr.t_ps = axis.bin_center_ps(last_above) + f * axis.bin_width_ps;
  return tr;
}

Analysis analyse(const DiffusionSetup& setup, const DiffusionResult& r, double threshold) {
  const Grid& g = r.grid;
  const HomogeneousMedium& m = setup.medium;
  const Scales sc = scales_of(m);
  const int bins = g.time.bins;
  const size_t nb = static_cast<size_t>(bins);
  Analysis a;
  a.threshold = threshold;
  for (auto* v :
       {&a.gaussian_distance, &a.gaussian_noise, &a.diffusion_distance, &a.paasschens_distance,
        &a.energy_exact, &a.r2_exact, &a.unscattered_exact, &a.single_exact})
    v->assign(nb, NAN);
  a.u_diffusion.assign(r.u.size(), NAN);
  a.u_paasschens.assign(r.u.size(), NAN);
  double zmax[4] = {NAN, NAN, NAN, NAN};
  // Only well-sampled bins (>= 100 effective photons): with a handful of contributing photons
  // the sample standard error is itself too noisy for a Gaussian z.
  auto track = [](double& z, double mc, double exact, double err) {
    if (err > 1e-6 * std::abs(mc) && mc * mc >= 100 * err * err && std::isfinite(exact))
      z = std::max(std::isnan(z) ? 0.0 : z, std::abs(mc - exact) / err);
  };

  for (int j = 0; j < bins; ++j) {
    const size_t J = static_cast<size_t>(j);
    const double t0 = g.time.bin_start_ps(j), t1 = t0 + g.time.bin_width_ps,
                 dt = g.time.bin_width_ps;
    // Exact references, averaged over the bin with the same survival weighting as the tallies.
    const double S = survival_integral(m, t0, t1);
    auto weighted = [&](auto&& f) {
      return integrate_gl([&](double t) { return std::exp(-m.sigma_a * sc.v * t) * f(t); }, t0, t1,
                          16) /
             S;
    };
    a.energy_exact[J] = S / dt;
    a.r2_exact[J] = weighted([&](double t) { return prw_r2(sc.v, sc.a, t); });
    a.unscattered_exact[J] = weighted([&](double t) { return std::exp(-m.sigma_s * sc.v * t); });
    a.single_exact[J] =
        weighted([&](double t) { return m.sigma_s * sc.v * t * std::exp(-m.sigma_s * sc.v * t); });
    track(zmax[0], r.energy[J], a.energy_exact[J], r.energy_err[J]);
    track(zmax[1], r.r2[J], a.r2_exact[J], r.r2_err[J]);
    track(zmax[2], r.unscattered[J], a.unscattered_exact[J], r.unscattered_err[J]);
    track(zmax[3], r.single[J], a.single_exact[J], r.single_err[J]);

    // Shapes: the MC profile against the Gaussian of its own <r^2> (= int r^2 u dV / E).
    // Distances need a profile resolved by the shells: rms radius >= kMinShellsPerRms shells.
    const std::vector<double> mc = mc_shell_masses(r, j);
    const std::vector<double> md = diffusion_bin_masses(g, j, m),
                              mp = paasschens_bin_masses(g, j, m);
    const double E = r.energy[J], r2_mc = E > 0 ? r.r2[J] * (S / dt) / E : 0.0;
    if (r2_mc >= kMinShellsPerRms * kMinShellsPerRms * g.dr * g.dr) {
      a.gaussian_distance[J] = tv_distance(mc, gaussian_shell_masses(g, r2_mc / 3));
      double noise = 0;  // E|N(0, s^2)| = s sqrt(2 / pi) per shell
      for (int i = 0; i < g.shells; ++i) noise += r.u_err[r.cell(i, j)] * g.shell_volume(i);
      a.gaussian_noise[J] = 0.5 * std::sqrt(2 / kPi) * noise / E;
      a.diffusion_distance[J] = tv_distance(mc, md);
      a.paasschens_distance[J] = tv_distance(mc, mp);
    }
    for (int i = 0; i < g.shells; ++i) {
      a.u_diffusion[r.cell(i, j)] = md[static_cast<size_t>(i)] / g.shell_volume(i);
      a.u_paasschens[r.cell(i, j)] = mp[static_cast<size_t>(i)] / g.shell_volume(i);
    }
  }
  a.energy_max_z = zmax[0], a.r2_max_z = zmax[1], a.unscattered_max_z = zmax[2],
  a.single_max_z = zmax[3];
  a.gaussian = transition_time(g.time, a.gaussian_distance, threshold);
  a.diffusion = transition_time(g.time, a.diffusion_distance, threshold);
  a.paasschens = transition_time(g.time, a.paasschens_distance, threshold);
  return a;
}

}  // namespace femto::diffusion

namespace femto::diffusion {

std::vector<double> gaussian_distances(const DiffusionSetup& setup, const DiffusionResult& r) {
  const Grid& g = r.grid;
  std::vector<double> d(static_cast<size_t>(g.time.bins), NAN);
  for (int j = 0; j < g.time.bins; ++j) {
    const size_t J = static_cast<size_t>(j);
    const double t0 = g.time.bin_start_ps(j), dt = g.time.bin_width_ps;
    const double S = survival_integral(setup.medium, t0, t0 + dt);
    const double E = r.energy[J], r2_mc = E > 0 ? r.r2[J] * (S / dt) / E : 0.0;
    if (r2_mc >= kMinShellsPerRms * kMinShellsPerRms * g.dr * g.dr)
      d[J] = tv_distance(mc_shell_masses(r, j), gaussian_shell_masses(g, r2_mc / 3));
  }
  return d;
}

double student_t95(int dof) {
  static const double kTable[30] = {12.706, 4.303, 3.182, 2.776, 2.571, 2.447, 2.365, 2.306,
                                    2.262,  2.228, 2.201, 2.179, 2.160, 2.145, 2.131, 2.120,
                                    2.110,  2.101, 2.093, 2.086, 2.080, 2.074, 2.069, 2.064,
                                    2.060,  2.056, 2.052, 2.048, 2.045, 2.042};
  if (dof < 1) return NAN;
  return dof <= 30 ? kTable[dof - 1] : 1.96 + 2.4 / dof;  // within 0.3% above 30
}

TransitionConfidence transition_confidence(const DiffusionSetup& setup, const DiffusionResult& r,
                                           const Analysis& a) {
  TransitionConfidence c;
  const TimeAxis& axis = r.grid.time;
  // Noise-floor diagnostics.
  std::vector<double> sub(a.gaussian_distance.size(), NAN);
  for (size_t j = 0; j < sub.size(); ++j)
    if (std::isfinite(a.gaussian_distance[j]))
      sub[j] = std::max(0.0, a.gaussian_distance[j] - (std::isfinite(a.gaussian_noise[j]) ? a.gaussian_noise[j] : 0.0));
  c.floor_subtracted = transition_time(axis, sub, a.threshold);
  if (a.gaussian.reached) {
    const double u = (a.gaussian.t_ps - axis.t_start_ps) / axis.bin_width_ps - 0.5;
    const int j0 = std::clamp(static_cast<int>(std::floor(u)), 0, axis.bins - 1);
    const int j1 = std::min(j0 + 1, axis.bins - 1);
    const double f = std::clamp(u - j0, 0.0, 1.0);
    const double n0 = a.gaussian_noise[static_cast<size_t>(j0)], n1 = a.gaussian_noise[static_cast<size_t>(j1)];
    c.noise_at_t_star = std::isfinite(n0) && std::isfinite(n1) ? (1 - f) * n0 + f * n1 : NAN;
    const bool floor_high = std::isfinite(c.noise_at_t_star) && c.noise_at_t_star >= 0.5 * a.threshold;
    const bool moves = !c.floor_subtracted.reached ||
                       a.gaussian.t_ps - c.floor_subtracted.t_ps > 0.25 * (a.gaussian.t_ps - axis.t_start_ps);
    c.noise_limited = floor_high || moves;
  } else {
    c.noise_limited = true;  // no t*: nothing to trust
  }
  // Jackknife: leave each batch out, recompute the distances and t*.
  const size_t B = r.batch_sum.size();
  c.batches = static_cast<int>(B);
  if (B < 2 || !a.gaussian.reached) return c;
  const TallyLayout layout{r.grid.shells, r.grid.time.bins};
  std::vector<double> all(layout.size(), 0.0);
  for (const auto& bs : r.batch_sum)
    for (size_t i = 0; i < all.size(); ++i) all[i] += bs[i];
  std::vector<double> t_rep;
  for (size_t b = 0; b < B; ++b) {
    TallySums rest;
    rest.reset(layout.size());
    for (size_t i = 0; i < all.size(); ++i) rest.sum(i) = all[i] - r.batch_sum[b][i];
    rest.photons = r.photons - r.batch_photons[b];
    const DiffusionResult rb = estimate(setup, rest);
    const Transition tb = transition_time(axis, gaussian_distances(setup, rb), a.threshold);
    if (tb.reached) t_rep.push_back(tb.t_ps);
  }
  c.replicates_reached = static_cast<int>(t_rep.size());
  if (t_rep.size() != B) return c;  // some replicate never settles: no interval
  double mean = 0;
  for (double t : t_rep) mean += t;
  mean /= static_cast<double>(B);
  double ss = 0;
  for (double t : t_rep) ss += (t - mean) * (t - mean);
  c.se_ps = std::sqrt((static_cast<double>(B) - 1) / static_cast<double>(B) * ss);
  const double q = student_t95(static_cast<int>(B) - 1);
  c.ci_lo_ps = std::max(axis.t_start_ps, a.gaussian.t_ps - q * c.se_ps);  // t* lies in the window
  c.ci_hi_ps = std::min(axis.t_end_ps(), a.gaussian.t_ps + q * c.se_ps);
  return c;
}

}  // namespace femto::diffusion
