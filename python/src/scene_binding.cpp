// femto.load_scene (docs/python.md).
#include "apps/render_record.h"
#include "core/error.h"
#include "core/render.h"
#include "core/scene_loader.h"
#include "core/tissue/scene.h"
#include "python/src/bindings.h"

namespace femto::python {

namespace {

py::dict load_scene_py(const py::object& scene) {
  const SceneText text = scene_text_of(scene);
  if (tissue::is_tissue_scene(text.text))
    throw py::value_error(text.source +
                          ": a tissue scene (docs/tissue.md); femto.load_scene "
                          "checks camera scenes");
  SceneDesc desc;
  try {
    desc = load_scene_string(text.text, text.source, text.base_dir);
  } catch (const InputError& e) {
    throw SceneError(e.what());
  }
  std::string why;
  const IntegratorKind kind = resolve_integrator(desc, desc.integrator.kind, why);
  py::list media;
  for (const MediumDesc& m : desc.media) media.append(m.name);
  py::dict d;
  d["source"] = desc.source;
  d["width"] = desc.camera.width;
  d["height"] = desc.camera.height;
  d["time_axis"] =
      py::dict(py::arg("t_start_ps") = desc.time.t_start_ps,
               py::arg("bin_width_ps") = desc.time.bin_width_ps, py::arg("bins") = desc.time.bins,
               py::arg("t_end_ps") = desc.time.t_end_ps());
  d["spp"] = desc.integrator.spp;
  d["seed"] = desc.integrator.seed;
  d["max_depth"] = desc.integrator.max_depth;
  d["integrator"] = integrator_name(kind);
  d["integrator_why"] = why;
  d["reconstruction"] =
      desc.reconstruction.type == TemporalFilter::Kind::Kernel ? "kernel" : "histogram";
  d["media"] = media;
  // Scene files may hold // comments: parsed as the loader does.
  d["scene"] = py::module_::import("json").attr("loads")(scene_json(text.text).dump());
  return d;
}

}  // namespace

void register_scene(py::module_& m) {
  m.def("load_scene", &load_scene_py, py::arg("scene") = py::none(),
        R"doc(Reads and validates a scene without rendering it.

scene: None (the built-in default scene), a dict, JSON text or a path. Returns a dict: source,
width, height, time_axis, spp, seed, max_depth, integrator (the one auto resolves to) and
integrator_why, reconstruction, media (names) and scene (the JSON as a dict). Raises
femto.SceneError with the message femto render prints: "<file>: <key>: <problem> (got <value>)".)doc");
}

}  // namespace femto::python
