// Error messages "<file>:<line>: <element>: <problem>", warnings, and JSON errors traced to XML.
#include <algorithm>

#include "core/error.h"
#include "core/mitsuba/importer.h"

namespace femto::mitsuba {

std::size_t Importer::line_of(std::ptrdiff_t offset) const {
  if (offset < 0) return 0;
  const auto it =
      std::upper_bound(line_starts_.begin(), line_starts_.end(), static_cast<std::size_t>(offset));
  return static_cast<std::size_t>(it - line_starts_.begin());
}

std::size_t Importer::line_of(Node n) const {
  return line_of(n.offset_debug());
}

std::string Importer::describe(Node n) const {
  std::string s = "<" + clip(n.name(), 40);
  for (const char* a : {"type", "name", "id"})
    if (n.attribute(a)) s += std::string(" ") + a + "=\"" + clip(n.attribute(a).value(), 40) + "\"";
  return s + ">";
}

std::string Importer::where(Node n) const {
  return clip(source_, 200) + ":" + std::to_string(line_of(n)) + ": " + describe(n);
}

void Importer::fail(Node n, const std::string& problem) const {
  throw InputError(where(n) + ": " + problem);
}

void Importer::warn(Node n, const std::string& text) {
  warnings_.push_back(where(n) + ": " + text);
}

// A message of the JSON loader ("<source>: <json path>: <problem>") told at the XML element
// the value came from.
void Importer::rethrow_at_element(const std::string& msg) const {
  const std::string prefix = clip(source_, 200) + ": ";
  if (msg.compare(0, prefix.size(), prefix) != 0) throw InputError(msg);
  const std::string rest = msg.substr(prefix.size());
  const std::size_t colon = rest.find(": ");
  const std::string path = rest.substr(0, colon);
  const std::string problem = colon == std::string::npos ? rest : rest.substr(colon + 2);
  const Node* best = nullptr;
  std::size_t best_len = 0;
  for (const auto& [p, node] : origins_) {
    const bool covers = path == p || (path.size() > p.size() && path.compare(0, p.size(), p) == 0 &&
                                      path[p.size()] == '/');
    if (covers && p.size() >= best_len) {
      best = &node;
      best_len = p.size();
    }
  }
  if (!best) throw InputError(prefix + "in the translated femto scene: " + rest);
  throw InputError(where(*best) + ": " + problem + " (femto scene key " + path + ")");
}

void Importer::origin(const std::string& json_path, Node n) {
  origins_.emplace_back(json_path, n);
}

}  // namespace femto::mitsuba
