// Keyword arguments as command flags (python/src/bindings.h).
#include <algorithm>
#include <cctype>

#include "python/src/bindings.h"

namespace femto::python {

namespace {
std::string text_of(const py::handle& v) {
  // repr keeps every digit of a float (the shortest text that reads back to the same double).
  if (py::isinstance<py::float_>(v)) return py::repr(v).cast<std::string>();
  return py::str(v).cast<std::string>();
}
}  // namespace

void add_flag(Flags& flags, const std::string& keyword, const py::handle& value) {
  std::string name = keyword;
  if (!name.empty() && name.back() == '_') name.pop_back();
  std::replace(name.begin(), name.end(), '_', '-');
  const std::string flag = "--" + name;
  flags.names.emplace_back(flag, keyword);
  if (value.is_none()) return;
  if (py::isinstance<py::bool_>(value)) {
    if (value.cast<bool>()) flags.argv.push_back(flag);
    return;
  }
  std::string text;
  if (!py::isinstance<py::str>(value) && !py::isinstance<py::bytes>(value) &&
      py::isinstance<py::sequence>(value)) {
    for (const py::handle item : value.cast<py::sequence>())
      text += (text.empty() ? "" : ",") + text_of(item);
  } else {
    text = text_of(value);
  }
  flags.argv.push_back(flag + "=" + text);
}

Flags keyword_flags(const py::kwargs& kwargs, const std::string& function,
                    const std::vector<std::string>& reserved) {
  Flags flags;
  for (const auto& item : kwargs) {
    const std::string keyword = py::str(item.first).cast<std::string>();
    if (std::find(reserved.begin(), reserved.end(), keyword) != reserved.end())
      throw py::type_error(function + "() got an unexpected keyword argument '" + keyword + "'");
    add_flag(flags, keyword, item.second);
  }
  return flags;
}

std::string Flags::pythonic(std::string message) const {
  for (const auto& [flag, keyword] : names) {
    // Whole flags only: --photons must not rewrite the start of --photons-per-pass.
    for (size_t at = message.find(flag); at != std::string::npos; at = message.find(flag, at)) {
      const size_t end = at + flag.size();
      if (end < message.size() &&
          (std::isalnum(static_cast<unsigned char>(message[end])) || message[end] == '-')) {
        at = end;
        continue;
      }
      message.replace(at, flag.size(), keyword);
      at += keyword.size();
    }
  }
  return message;
}

}  // namespace femto::python
