// femto.tissue (docs/python.md): a tissue-optics scene run in the process, its outputs as NumPy
// arrays with the names and units of the files `femto render` writes for the same scene.
#include <pybind11/numpy.h>

#include <chrono>
#include <cmath>
#include <optional>

#include "apps/cli.h"
#include "core/error.h"
#include "core/tissue/outputs.h"
#include "core/tissue/scene.h"
#include "core/tissue/simulate.h"
#include "python/src/bindings.h"

namespace femto::python {

namespace {

template <class T, class U>
py::array_t<T> array_of(const std::vector<U>& v, std::vector<py::ssize_t> shape) {
  py::array_t<T> a(shape);
  std::copy(v.begin(), v.end(), a.mutable_data());
  return a;
}

// A keyword that must be a whole number in [lo, hi] (bool is not one).
std::optional<uint64_t> whole(const py::object& value, const char* name, double lo, double hi) {
  if (value.is_none()) return std::nullopt;
  if (py::isinstance<py::bool_>(value) ||
      !(py::isinstance<py::int_>(value) || py::isinstance<py::float_>(value)))
    throw py::type_error(std::string("tissue(): ") + name + ": expected a whole number");
  const double x = value.cast<double>();
  if (!(x >= lo && x <= hi) || x != std::floor(x))
    throw py::value_error(std::string(name) + ": must be a whole number in [" +
                          py::repr(py::float_(lo)).cast<std::string>() + ", " +
                          py::repr(py::float_(hi)).cast<std::string>() + "] (got " +
                          py::repr(value).cast<std::string>() + ")");
  return static_cast<uint64_t>(x);
}

py::object json_to_python(const nlohmann::json& j) {
  return py::module_::import("json").attr("loads")(j.dump());
}

py::dict tissue_py(const py::object& scene, const py::object& photons, const py::object& seed,
                   const py::object& threads, const py::object& progress, bool quiet) {
  const std::optional<uint64_t> n = whole(photons, "photons", 1, 1e12);
  const std::optional<uint64_t> sd = whole(seed, "seed", 0, 9007199254740992.0);
  const std::optional<uint64_t> th = whole(threads, "threads", 0, 4096);
  if (!progress.is_none() && !PyCallable_Check(progress.ptr()))
    throw py::type_error("tissue(): progress: expected a callable (done, total)");
  if (scene.is_none())
    throw py::type_error("tissue(): scene: expected a dict, JSON text or a path");
  const SceneText text = scene_text_of(scene);
  if (!tissue::is_tissue_scene(text.text))
    throw py::value_error(text.source +
                          ": not a tissue scene (no \"tissue\" section; docs/tissue.md); camera "
                          "scenes go to femto.render");
  tissue::Setup s;
  try {
    s = tissue::load_tissue_scene(text.text, text.source, text.base_dir);
  } catch (const InputError& e) {
    throw SceneError(e.what());
  }
  if (n) s.photons = *n;
  if (sd) s.seed = *sd;
  if (th) s.threads = static_cast<int>(*th);
  s.quiet = quiet;
  // The command's memory policy at its default --max-memory (75% of physical memory).
  const uint64_t max_memory = cli::physical_memory_bytes() / 4 * 3;
  const uint64_t need = tissue::memory_bytes(s, tissue::threads_for(s));
  if (need > max_memory)
    throw py::value_error("femto.tissue: the run needs " + cli::format_bytes(need) +
                          ", more than 75% of this machine's memory (" +
                          cli::format_bytes(max_memory) +
                          "); lower the fluence resolution, the gates or the threads");

  std::atomic<bool> stop{false};
  std::atomic<uint64_t> done{0};
  s.stop = &stop;
  s.photons_done = &done;
  uint64_t reported = ~uint64_t{0};
  auto last_call = std::chrono::steady_clock::now();
  const auto poll = [&] {
    if (progress.is_none()) return;
    const uint64_t d = done.load();
    const auto now = std::chrono::steady_clock::now();
    // Throttled: at most 5 calls a second, and always the last one.
    if (d == reported || (d < s.photons && now - last_call < std::chrono::milliseconds(200)))
      return;
    progress(d, s.photons);
    reported = d;
    last_call = now;
  };
  std::optional<tissue::Result> result;
  run_interruptible(
      [&] {
        try {
          result.emplace(tissue::simulate(s));
        } catch (const tissue::Stopped&) {  // the pending Python exception is raised instead
        }
      },
      stop, poll);
  if (!result) throw py::error_already_set();  // not reached: run_interruptible raised
  const tissue::Result& r = *result;

  const py::ssize_t T = r.gates;
  py::dict d;
  std::vector<double> centers(static_cast<size_t>(T)), edges(static_cast<size_t>(T) + 1);
  for (int g = 0; g < r.gates; ++g) centers[static_cast<size_t>(g)] = s.time.bin_center_ps(g);
  for (int g = 0; g <= r.gates; ++g) edges[static_cast<size_t>(g)] = s.time.bin_start_ps(g);
  d["time_ps"] = array_of<double>(centers, {T});
  d["time_edges_ps"] = array_of<double>(edges, {T + 1});
  if (s.fluence) {
    const tissue::FluenceGrid& fg = s.fluence_grid;
    const std::vector<py::ssize_t> shape{fg.n[0], fg.n[1], fg.n[2], T};
    d["fluence"] = array_of<float>(r.fluence, shape);
    std::vector<float> rate(r.fluence);
    const float per_ps = static_cast<float>(1.0 / s.time.bin_width_ps);
    for (float& x : rate) x *= per_ps;  // as fluence_rate.npy
    d["fluence_rate"] = array_of<float>(rate, shape);
    d["fluence_stderr"] =
        s.fluence_stderr ? py::object(array_of<float>(r.fluence_err, shape)) : py::none();
    d["fluence_grid"] =
        py::dict(py::arg("shape") = py::make_tuple(fg.n[0], fg.n[1], fg.n[2]),
                 py::arg("origin_mm") = py::make_tuple(fg.origin.x, fg.origin.y, fg.origin.z),
                 py::arg("size_mm") = py::make_tuple(fg.size.x, fg.size.y, fg.size.z));
  } else {
    for (const char* k : {"fluence", "fluence_rate", "fluence_stderr", "fluence_grid"})
      d[k] = py::none();
  }
  const py::ssize_t D = static_cast<py::ssize_t>(s.detectors.size());
  d["tpsf"] = array_of<double>(r.tpsf, {D, T});
  d["tpsf_stderr"] = array_of<double>(r.tpsf_err, {D, T});
  if (D > 0 && s.save_detected) {
    const tissue::DetectedPhotons& dp = r.detected;
    const py::ssize_t N = static_cast<py::ssize_t>(dp.size());
    d["detected"] = py::dict(py::arg("detector") = array_of<int32_t>(dp.detector, {N}),
                             py::arg("scatterings") = array_of<int32_t>(dp.scatterings, {N}),
                             py::arg("weight") = array_of<double>(dp.weight, {N}),
                             py::arg("time_ps") = array_of<double>(dp.time_ps, {N}),
                             py::arg("ppath") = array_of<double>(dp.ppath, {N, dp.labels}),
                             py::arg("exit") = array_of<double>(dp.exit, {N, 6}));
  } else {
    d["detected"] = py::none();
  }
  if (s.faces) {
    static const char* kFaces[6] = {"xmin", "xmax", "ymin", "ymax", "zmin", "zmax"};
    py::dict faces;
    for (size_t f = 0; f < 6; ++f)
      faces[kFaces[f]] =
          array_of<float>(r.face_exitance[f], {r.face_shape[f][0], r.face_shape[f][1], T});
    d["exitance"] = faces;
  } else {
    d["exitance"] = py::none();
  }
  d["absorbed_per_label"] = array_of<double>(
      r.absorbed_per_label, {static_cast<py::ssize_t>(r.absorbed_per_label.size())});
  d["summary"] = json_to_python(tissue::summary_json(s, r));
  return d;
}

}  // namespace

void register_tissue(py::module_& m) {
  m.def("tissue", &tissue_py, py::arg("scene"), py::kw_only(), py::arg("photons") = py::none(),
        py::arg("seed") = py::none(), py::arg("threads") = py::none(),
        py::arg("progress") = py::none(), py::arg("quiet") = true,
        R"doc(Runs a tissue-optics scene (a scene with a "tissue" section; docs/tissue.md) and
returns its outputs as a dict, bit for bit what `femto render SCENE` writes:

time_ps (T gate centres), time_edges_ps (T + 1); fluence (X, Y, Z, T float32, fluence per gate
per unit launched energy, 1/mm^2), fluence_rate (1/(mm^2 ps)), fluence_stderr (or None),
fluence_grid (shape, origin_mm, size_mm); tpsf and tpsf_stderr (D, T exitance through each
detector, 1/(mm^2 ps)); detected (dict of detector, scatterings, weight, time_ps, ppath (N,
labels) in mm, exit (N, 6): exit point and direction; None without detectors); exitance (face
name -> (A, B, T) float32, or None); absorbed_per_label (label 0 first); summary (summary.json).

scene: a dict, JSON text or a path. photons, seed, threads override the scene as the command's
flags do. progress: a callable (done, total) called from this thread, at most 5 times a second.
Raises femto.SceneError for a bad scene, ValueError for a bad keyword value, KeyboardInterrupt
on Ctrl-C (within a chunk of 1024 photons per thread). The GIL is released while the photons run.)doc");
}

}  // namespace femto::python
