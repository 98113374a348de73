// The Python module `femto` (docs/python.md).
#include "core/constants.h"
#include "femto_version.h"
#include "python/src/bindings.h"

PYBIND11_MODULE(femto, m) {
  m.doc() =
      "femto: volumetric transient light transport (mm, ps). render() returns the transient "
      "film as NumPy arrays; tissue() runs tissue-optics scenes; diffusion() and uniformity() run "
      "the checks of the femto command.";
  m.attr("__version__") = FEMTO_VERSION;
  m.attr("speed_of_light_mm_per_ps") = femto::kSpeedOfLight;
  femto::python::register_errors(m);
  femto::python::register_scene(m);
  femto::python::register_render(m);
  femto::python::register_diffusion(m);
  femto::python::register_uniformity(m);
  femto::python::register_tissue(m);
}
