#pragma once
// Pieces shared by the Python bindings (docs/python.md): keyword arguments turned into the
// command's flags, scenes given as dict, JSON text or path, errors mapped to Python exceptions,
// and long runs with the GIL released that Ctrl-C and a progress callback can reach.
#include <pybind11/pybind11.h>

#include <atomic>
#include <functional>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

namespace femto::python {

namespace py = pybind11;

/// A scene that cannot be read or validated: raised in Python as femto.SceneError (a ValueError)
/// with the loader's "<file>: <key>: <problem> (got <value>)" message.
struct SceneError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

/// Keyword arguments as the command's flags: name_with_underscores=value becomes
/// "--name-with-underscores=value" (a trailing underscore is dropped: lambda_ -> --lambda).
/// True becomes the bare flag and False or None leave it out; sequences become "a,b,c"; floats
/// keep every digit (repr). Keywords in `reserved` raise TypeError (not accepted here).
struct Flags {
  std::vector<std::string> argv;
  std::vector<std::pair<std::string, std::string>> names;  ///< (--flag, keyword)
  /// `message` with each flag written as its keyword, for Python users.
  std::string pythonic(std::string message) const;
};
Flags keyword_flags(const py::kwargs& kwargs, const std::string& function,
                    const std::vector<std::string>& reserved);
/// Appends one keyword (as keyword_flags does).
void add_flag(Flags& flags, const std::string& keyword, const py::handle& value);

/// A scene argument: None (the built-in default scene), a dict, JSON text or a path.
struct SceneText {
  std::string text, source, base_dir;  ///< as load_scene_string takes them
  std::string path;                    ///< the file, when given as a path
};
/// Reads a path (size-limited); a missing or unreadable file is a SceneError.
SceneText scene_text_of(const py::object& scene);

/// Runs `work` on a worker thread with the GIL released. Every `tick` seconds the calling thread
/// takes the GIL, lets Python handle pending signals (Ctrl-C) and calls `poll`; when either
/// raises, `stop` is set, the work is left to finish (it checks `stop` between passes) and the
/// Python exception is raised after it returns. Exceptions from `work` are rethrown.
void run_interruptible(const std::function<void()>& work, std::atomic<bool>& stop,
                       const std::function<void()>& poll, double tick = 0.05);

/// A C++ exception from femto as the Python exception it stands for: SceneError ->
/// femto.SceneError, InputError (bad keyword values) -> ValueError with `flags.pythonic`.
[[noreturn]] void raise_input_error(const std::exception& e, const Flags& flags);

void register_errors(py::module_& m);
void register_render(py::module_& m);
void register_scene(py::module_& m);
void register_diffusion(py::module_& m);
void register_uniformity(py::module_& m);
void register_tissue(py::module_& m);

}  // namespace femto::python
