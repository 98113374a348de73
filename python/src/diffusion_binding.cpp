// femto.diffusion (docs/python.md).
#include <pybind11/numpy.h>

#include <optional>

#include "apps/diffusion_flags.h"
#include "core/diffusion/analysis.h"
#include "core/diffusion/models.h"
#include "core/error.h"
#include "python/src/bindings.h"

namespace femto::python {

namespace {

py::array_t<double> array_of(const std::vector<double>& v) {
  py::array_t<double> a(static_cast<py::ssize_t>(v.size()));
  std::copy(v.begin(), v.end(), a.mutable_data());
  return a;
}

/// Per-cell values (index bin * shells + shell) as (T, R).
py::array_t<double> cells_of(const std::vector<double>& v, const diffusion::Grid& g) {
  return array_of(v).attr("reshape")(g.time.bins, g.shells);
}

py::dict transition_of(const diffusion::Transition& t) {
  return py::dict(py::arg("reached") = t.reached, py::arg("from_start") = t.from_start,
                  py::arg("t_ps") = t.t_ps);
}

py::dict diffusion_py(const py::kwargs& kwargs) {
  const Flags flags =
      keyword_flags(kwargs, "diffusion", {"out", "quiet", "q", "help", "h", "plot_times"});
  const std::string command = "femto.diffusion";
  DiffusionRequest request;
  try {
    request = parse_diffusion_args(flags.argv, command);
  } catch (const InputError& e) {
    const std::string what = e.what();
    if (what.find("unknown option") != std::string::npos)
      throw py::type_error("diffusion() got an unexpected keyword argument: " +
                           flags.pythonic(what));
    raise_input_error(e, flags);
  }
  diffusion::DiffusionSetup& setup = request.setup;
  std::atomic<bool> stop{false};
  setup.stop = &stop;
  setup.quiet = true;
  std::optional<diffusion::DiffusionResult> result;
  run_interruptible(
      [&] {
        result.emplace(request.transport ? diffusion::simulate(setup, *request.transport)
                                         : diffusion::simulate(setup));
      },
      stop, nullptr);
  const diffusion::DiffusionResult& r = *result;
  const diffusion::Analysis a = diffusion::analyse(setup, r, request.threshold);
  const diffusion::TransitionConfidence conf = diffusion::transition_confidence(setup, r, a);
  const diffusion::Scales sc = diffusion::scales_of(setup.medium);
  const diffusion::Grid& g = r.grid;

  std::vector<double> t(static_cast<size_t>(g.time.bins)), radius(static_cast<size_t>(g.shells));
  for (int i = 0; i < g.time.bins; ++i) t[static_cast<size_t>(i)] = g.time.bin_center_ps(i);
  for (int i = 0; i < g.shells; ++i) radius[static_cast<size_t>(i)] = g.shell_center(i);
  py::dict d;
  d["time_ps"] = array_of(t);
  d["r_mm"] = array_of(radius);
  d["u"] = cells_of(r.u, g);
  d["u_err"] = cells_of(r.u_err, g);
  d["u_diffusion"] = cells_of(a.u_diffusion, g);
  d["u_paasschens"] = cells_of(a.u_paasschens, g);
  d["energy"] = array_of(r.energy);
  d["energy_err"] = array_of(r.energy_err);
  d["energy_exact"] = array_of(a.energy_exact);
  d["r2"] = array_of(r.r2);
  d["r2_err"] = array_of(r.r2_err);
  d["r2_exact"] = array_of(a.r2_exact);
  d["r4"] = array_of(r.r4);
  d["r4_err"] = array_of(r.r4_err);
  d["unscattered"] = array_of(r.unscattered);
  d["unscattered_err"] = array_of(r.unscattered_err);
  d["unscattered_exact"] = array_of(a.unscattered_exact);
  d["single"] = array_of(r.single);
  d["single_err"] = array_of(r.single_err);
  d["single_exact"] = array_of(a.single_exact);
  d["gaussian_distance"] = array_of(a.gaussian_distance);
  d["gaussian_noise"] = array_of(a.gaussian_noise);
  d["diffusion_distance"] = array_of(a.diffusion_distance);
  d["paasschens_distance"] = array_of(a.paasschens_distance);
  d["threshold"] = request.threshold;
  d["t_star"] = transition_of(a.gaussian);
  d["t_star"]["ci95_ps"] = py::make_tuple(conf.ci_lo_ps, conf.ci_hi_ps);
  d["t_star"]["se_ps"] = conf.se_ps;
  d["t_star"]["noise_limited"] = conf.noise_limited;
  d["t_diffusion"] = transition_of(a.diffusion);
  d["t_paasschens"] = transition_of(a.paasschens);
  d["medium"] =
      py::dict(py::arg("sigma_s") = setup.medium.sigma_s, py::arg("sigma_a") = setup.medium.sigma_a,
               py::arg("g") = setup.medium.g, py::arg("eta") = setup.medium.eta,
               py::arg("mean_free_time_ps") = sc.mean_free_time);
  d["source"] = py::module_::import("json").attr("loads")(request.source.dump());
  d["photons"] = r.photons;
  d["segments"] = r.segments;
  d["seconds"] = r.seconds;
  d["threads"] = r.threads;
  d["stopped_early"] = r.stopped_early;
  return d;
}

}  // namespace

void register_diffusion(py::module_& m) {
  m.def("diffusion", &diffusion_py,
        R"doc(A pulsed isotropic point source in an infinite medium, compared with diffusion theory
(femto diffusion; docs/diffusion.md). Keywords are the command's flags: sigma_s, sigma_a, g, eta,
absorption, t_start, t_end, t_bins, r_max, r_bins, threshold, photons, max_seconds, seed,
batches, threads, and scene, medium, at=(x, y, z) for a source inside a scene's medium.

Returns a dict of NumPy arrays: time_ps (T), r_mm (R), u, u_err, u_diffusion, u_paasschens
(T, R; energy density 1/mm^3), per-bin energy, r2, r4, unscattered, single (with _err and _exact)
and the distances to the Gaussian and the models; t_star (reached, t_ps, ci95_ps, se_ps,
noise_limited), medium, photons, seconds, stopped_early. ValueError for bad values; Ctrl-C
stops after the current round of photons and raises KeyboardInterrupt.)doc");
}

}  // namespace femto::python
