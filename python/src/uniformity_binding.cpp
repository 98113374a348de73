// femto.uniformity (docs/python.md).
#include <pybind11/numpy.h>

#include "apps/uniformity_flags.h"
#include "core/error.h"
#include "python/src/bindings.h"

namespace femto::python {

namespace {

py::dict uniformity_py(const py::kwargs& kwargs) {
  const Flags flags =
      keyword_flags(kwargs, "uniformity", {"out", "quiet", "q", "help", "h", "expect"});
  UniformityRequest request;
  try {
    request = parse_uniformity_args(flags.argv, "femto.uniformity");
  } catch (const InputError& e) {
    const std::string what = e.what();
    if (what.find("unknown option") != std::string::npos)
      throw py::type_error("uniformity() got an unexpected keyword argument: " +
                           flags.pythonic(what));
    raise_input_error(e, flags);
  }
  std::vector<uniformity::Result> results;
  {
    py::gil_scoped_release release;
    for (uniformity::Strategy s : request.strategies)
      results.push_back(uniformity::run(request.config, s));
  }
  py::dict d;
  for (const uniformity::Result& r : results) {
    py::array_t<double> counts(static_cast<py::ssize_t>(r.counts.size()));
    std::copy(r.counts.begin(), r.counts.end(), counts.mutable_data());
    py::dict e;
    e["counts"] = counts;
    e["range_ps"] = py::make_tuple(r.range_lo_ps, r.range_hi_ps);
    e["expected_per_bin"] = r.expected_per_bin;
    e["drawn"] = r.drawn;
    e["in_range"] = r.in_range;
    e["chi2"] = r.chi2.chi2;
    e["chi2_dof"] = r.chi2.dof;
    e["chi2_p"] = r.chi2.p_value;
    e["ks_d"] = r.ks_d;
    e["ks_p"] = r.ks_p;
    e["passed"] = r.pass;
    e["valid"] = r.valid;
    e["time_definition"] = r.time_definition;
    e["pdf"] = r.pdf;
    e["note"] = r.note;
    d[uniformity::strategy_name(r.strategy)] = e;
  }
  return d;
}

}  // namespace

void register_uniformity(py::module_& m) {
  m.def("uniformity", &uniformity_py,
        R"doc(How uniformly in time the samplers place their samples (femto uniformity;
docs/uniformity.md). Keywords are the command's flags: strategy ('all' or one of mfp,
time_uniform, line_to_point, angular, equiangular), sigma_t, eta, t_start, t_end,
sensor=(x, y, z), light=(x, y, z), dir=(x, y, z), segment, lambda_, mfp_time, samples, seed,
bins, alpha.

Returns {strategy name: dict} with counts (bins, NumPy), range_ps, expected_per_bin, drawn,
in_range, chi2, chi2_dof, chi2_p, ks_d, ks_p, passed (both p-values >= alpha), valid,
time_definition, pdf, note. ValueError for bad values.)doc");
}

}  // namespace femto::python
