// femto.render and femto.RenderResult (docs/python.md).
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <chrono>
#include <memory>
#include <optional>
#include <thread>

#include "apps/cli.h"
#include "apps/render_flags.h"
#include "apps/render_record.h"
#include "core/error.h"
#include "core/render.h"
#include "core/scene.h"
#include "core/scene_loader.h"
#include "core/tissue/scene.h"
#include "python/src/bindings.h"

namespace femto::python {

namespace {

/// A finished render: the film (which the result's arrays view) and its render.json record.
struct RenderOutput {
  RenderResult result;
  nlohmann::json meta;
};

py::object json_to_python(const nlohmann::json& j) {
  return py::module_::import("json").attr("loads")(j.dump());
}

/// A float32 view of film memory; `owner` (the Python RenderResult) keeps the film alive.
py::array_t<float> film_view(const py::object& owner, const float* data,
                             std::vector<py::ssize_t> shape) {
  std::vector<py::ssize_t> strides(shape.size());
  py::ssize_t stride = sizeof(float);
  for (size_t i = shape.size(); i-- > 0;) {
    strides[i] = stride;
    stride *= shape[i];
  }
  return py::array_t<float>(shape, strides, data, owner);
}

py::dict time_axis_of(const RenderOutput& out) {
  const TimeAxis& axis = out.result.film.axis();
  py::dict d = json_to_python(out.meta["time_axis"]);
  py::array_t<double> centers(axis.bins), edges(axis.bins + 1);
  auto c = centers.mutable_unchecked<1>();
  auto e = edges.mutable_unchecked<1>();
  for (int i = 0; i < axis.bins; ++i) c(i) = axis.bin_center_ps(i);
  for (int i = 0; i <= axis.bins; ++i) e(i) = axis.bin_start_ps(i);
  d["centers_ps"] = centers;
  d["edges_ps"] = edges;
  // OPL = c t, as the time_axis record's *_opl_mm entries.
  d["centers_opl_mm"] = centers.attr("__mul__")(kSpeedOfLight);
  d["edges_opl_mm"] = edges.attr("__mul__")(kSpeedOfLight);
  return d;
}

const std::vector<std::string> kCommandOnly = {"out",        "frames",     "no_previews",
                                               "max_memory", "checkpoint", "checkpoint_every",
                                               "resume",     "help",       "h"};

std::shared_ptr<RenderOutput> render_py(const py::object& scene, const py::object& spp,
                                        const py::object& threads, const py::object& seed,
                                        const py::object& progress, bool quiet,
                                        const py::kwargs& overrides) {
  const std::string command = "femto.render";
  Flags flags = keyword_flags(overrides, "render", kCommandOnly);
  add_flag(flags, "spp", spp);
  add_flag(flags, "threads", threads);
  add_flag(flags, "seed", seed);
  if (overrides.contains("no_onset_reflection") &&
      !py::isinstance<py::bool_>(overrides["no_onset_reflection"]))
    throw py::type_error("render(): no_onset_reflection: expected True or False");
  if (!progress.is_none() && !PyCallable_Check(progress.ptr()))
    throw py::type_error("render(): progress: expected a callable (done, total)");

  RenderOverrides o;
  try {
    cli::Args args(command, flags.argv);
    while (!args.done()) {
      const std::string a = args.next();
      if (!parse_render_flag(args, a, o))
        throw py::type_error("render() got an unexpected keyword argument '" + flags.pythonic(a) +
                             "'");
    }
  } catch (const InputError& e) {
    raise_input_error(e, flags);
  }

  const SceneText text = scene_text_of(scene);
  if (tissue::is_tissue_scene(text.text))
    throw py::value_error(text.source +
                          ": a tissue scene (docs/tissue.md); femto.render takes camera scenes, "
                          "run tissue scenes with femto.tissue");
  SceneDesc desc;
  try {
    desc = load_scene_string(text.text, text.source, text.base_dir);
  } catch (const InputError& e) {
    throw SceneError(e.what());
  }
  RenderSetup setup;
  try {
    setup = apply_render_overrides(desc, o, command, text.path.empty() ? command : text.path);
  } catch (const InputError& e) {
    raise_input_error(e, flags);
  }
  RenderOptions& opt = setup.options;
  opt.quiet = quiet;
  // Shorter passes than the command's (1 s): Ctrl-C and progress react sooner. Passes do not
  // change the result's bits (core/render.h).
  opt.pass_seconds = 0.25;

  // The command's memory policy at its default --max-memory (75% of physical memory).
  const uint64_t max_memory = cli::physical_memory_bytes() / 4 * 3;
  const CameraDesc& cam = desc.camera;
  const int hardware = static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  const int threads_used = opt.threads > 0 ? std::min(opt.threads, hardware) : hardware;
  const RenderMemory mem =
      render_memory(cam.width, cam.height, desc.time.bins, opt, threads_used,
                    desc.reconstruction.type == TemporalFilter::Kind::Kernel,
                    desc.reconstruction.first_pass_spp, false, has_scattering_medium(desc));
  if (mem.peak() > max_memory)
    throw py::value_error(command + ": the render needs " + cli::format_bytes(mem.peak()) +
                          ", more than 75% of this machine's memory (" +
                          cli::format_bytes(max_memory) +
                          "); lower the resolution, the number of bins or photons per pass");
  for (MediumDesc& m : desc.media) m.vdb.max_dense_bytes = (max_memory - mem.peak()) / 2;

  std::unique_ptr<Scene> built;
  try {
    py::gil_scoped_release release;  // volumes and meshes can take a while
    built = std::make_unique<Scene>(std::move(desc));
  } catch (const InputError& e) {
    throw SceneError(e.what());
  }

  std::atomic<bool> stop{false};
  std::atomic<int64_t> done{0}, total{0};
  opt.stop = &stop;
  opt.after_pass = [&](const RenderState& state, bool) {
    total.store(state.units_total);
    done.store(state.units_done);
  };
  int64_t reported = -1;
  auto last_call = std::chrono::steady_clock::now();
  const auto poll = [&] {
    if (progress.is_none()) return;
    const int64_t d = done.load(), t = total.load();
    const auto now = std::chrono::steady_clock::now();
    // Throttled: at most 5 calls a second, and always the last one.
    if (t == 0 || d == reported || (d < t && now - last_call < std::chrono::milliseconds(200)))
      return;
    progress(d, t);
    reported = d;
    last_call = now;
  };
  std::optional<RenderResult> result;
  run_interruptible([&] { result.emplace(render(*built, opt)); }, stop, poll);

  auto out = std::shared_ptr<RenderOutput>(new RenderOutput{std::move(*result), {}});
  const uint64_t nonfinite = out->result.film.zero_nonfinite();  // as the command's outputs
  out->meta = render_info(*built, text.text, setup, o.max_depth.has_value(), out->result, nonfinite,
                          nullptr);
  std::string call = command + "(" + (text.path.empty() ? text.source : "'" + text.path + "'");
  for (const std::string& a : flags.argv) call += ", " + flags.pythonic(a);
  out->meta["command"] = call + ")";
  out->meta["date_utc"] = cli::utc_now();
  return out;
}

}  // namespace

void register_render(py::module_& m) {
  py::class_<RenderOutput, std::shared_ptr<RenderOutput>>(
      m, "RenderResult",
      "A finished render. Its arrays view the film without copying; the film lives as long as "
      "this object or any of its arrays.")
      .def_property_readonly(
          "transient",
          [](const py::object& self) {
            const TransientFilm& f = self.cast<const RenderOutput&>().result.film;
            return film_view(self, f.transient(), {f.height(), f.width(), f.bins(), 3});
          },
          "float32 (H, W, T, 3): radiance integrated over each time bin (transient.npy)")
      .def_property_readonly(
          "steady",
          [](const py::object& self) {
            const TransientFilm& f = self.cast<const RenderOutput&>().result.film;
            return film_view(self, f.steady(), {f.height(), f.width(), 3});
          },
          "float32 (H, W, 3): the sum over the bins (steady.exr)")
      .def_property_readonly(
          "before_window",
          [](const py::object& self) {
            const TransientFilm& f = self.cast<const RenderOutput&>().result.film;
            return film_view(self, f.before(), {f.height(), f.width(), 3});
          },
          "float32 (H, W, 3): light arriving before the window (before_window.exr)")
      .def_property_readonly(
          "after_window",
          [](const py::object& self) {
            const TransientFilm& f = self.cast<const RenderOutput&>().result.film;
            return film_view(self, f.after(), {f.height(), f.width(), 3});
          },
          "float32 (H, W, 3): light arriving after the window (after_window.exr)")
      .def_property_readonly(
          "peak_time",
          [](const RenderOutput& out) {
            const TransientFilm& f = out.result.film;
            const std::vector<float> p = f.peak_time();
            py::array_t<float> a({f.height(), f.width()});
            std::copy(p.begin(), p.end(), a.mutable_data());
            return a;
          },
          "float32 (H, W): time (ps, bin centre) of each pixel's brightest bin; NaN where dark "
          "(peak_time.exr)")
      .def_property_readonly(
          "kernel_bandwidth_ps",
          [](const py::object& self) -> py::object {
            const RenderOutput& out = self.cast<const RenderOutput&>();
            if (out.result.final_bandwidth_ps.empty()) return py::none();
            const TransientFilm& f = out.result.film;
            return film_view(self, out.result.final_bandwidth_ps.data(), {f.height(), f.width()});
          },
          "float32 (H, W): kernel film only, each pixel's final temporal bandwidth (ps); None "
          "for the histogram film")
      .def_property_readonly(
          "time_axis", [](const RenderOutput& out) { return time_axis_of(out); },
          "dict: render.json's time_axis (ps and OPL mm) plus the arrays centers_ps, edges_ps, "
          "centers_opl_mm and edges_opl_mm")
      .def_property_readonly(
          "meta", [](const RenderOutput& out) { return json_to_python(out.meta); },
          "dict: what render.json holds for the same render")
      .def_property_readonly(
          "complete", [](const RenderOutput& out) { return out.result.complete; },
          "True: every sample was rendered")
      .def("__repr__", [](const RenderOutput& out) {
        const TransientFilm& f = out.result.film;
        return "<femto.RenderResult " + std::to_string(f.height()) + " x " +
               std::to_string(f.width()) + " pixels x " + std::to_string(f.bins()) + " bins>";
      });

  m.def("render", &render_py, py::arg("scene") = py::none(), py::kw_only(),
        py::arg("spp") = py::none(), py::arg("threads") = py::none(), py::arg("seed") = py::none(),
        py::arg("progress") = py::none(), py::arg("quiet") = true,
        R"doc(Renders a scene; returns a RenderResult.

scene: None (the built-in default scene), a dict, JSON text or a path to a scene file.
spp, threads, seed and every other keyword override the scene as the femto render flags of
the same name do (distance_sampling='mis' is --distance-sampling mis). progress: a callable
(done, total) called from this thread, at most 5 times a second. Raises femto.SceneError for a
bad scene, ValueError for a bad keyword value, KeyboardInterrupt on Ctrl-C (after the current
pass). The GIL is released while rendering.)doc");
}

}  // namespace femto::python
