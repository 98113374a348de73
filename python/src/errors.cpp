// Python exceptions for femto's errors (python/src/bindings.h).
#include "core/error.h"
#include "python/src/bindings.h"

namespace femto::python {

void raise_input_error(const std::exception& e, const Flags& flags) {
  throw py::value_error(flags.pythonic(e.what()));
}

void register_errors(py::module_& m) {
  // Bad input that reaches Python without a keyword to name (e.g. a mesh file that fails while
  // the scene is built) is still a ValueError; failures of the machine are RuntimeErrors.
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const InputError& e) {
      PyErr_SetString(PyExc_ValueError, e.what());
    }
  });
  py::register_exception<SceneError>(m, "SceneError", PyExc_ValueError);
}

}  // namespace femto::python
