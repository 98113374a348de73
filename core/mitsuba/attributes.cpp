// Attributes: allowed names, no stray text, $variable substitution, and the numbers they hold.
#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>

#include "core/error.h"
#include "core/mitsuba/importer.h"

namespace femto::mitsuba {

void Importer::check_attributes(Node n, std::initializer_list<const char*> allowed) const {
  for (pugi::xml_attribute a : n.attributes()) {
    const std::string name = a.name();
    if (std::none_of(allowed.begin(), allowed.end(), [&](const char* x) { return name == x; }))
      fail(n, "unknown attribute '" + clip(name) + "'");
  }
}

// Mitsuba's structure is attributes only: text between tags is a mistake.
void Importer::check_text(Node n) const {
  for (Node c : n.children())
    if (c.type() == pugi::node_pcdata || c.type() == pugi::node_cdata)
      fail(n, "unexpected text '" + clip(c.value(), 40) + "' inside the element");
}

// Plugins take the attributes type, id and name only.
std::string Importer::plugin_type(Node n) const {
  check_attributes(n, {"type", "id", "name"});
  return attr(n, "type");
}

std::string Importer::raw_attr(Node n, const char* name) const {
  const pugi::xml_attribute a = n.attribute(name);
  if (!a) fail(n, std::string("missing attribute '") + name + "'");
  return a.value();
}

std::string Importer::required_attr(Node n, const char* name) const {
  return attr(n, name);
}

/// An attribute's value with every $name replaced by its <default>.
std::string Importer::attr(Node n, const char* name) const {
  const std::string raw = raw_attr(n, name);
  std::string out;
  for (std::size_t i = 0; i < raw.size(); ++i) {
    if (raw[i] != '$') {
      out += raw[i];
      continue;
    }
    std::size_t j = i + 1;
    while (j < raw.size() && (std::isalnum(static_cast<unsigned char>(raw[j])) || raw[j] == '_'))
      ++j;
    const std::string var = raw.substr(i + 1, j - i - 1);
    if (var.empty())
      fail(n, std::string("attribute '") + name + "': '$' must start a variable name (got \"" +
                  clip(raw) + "\")");
    const auto it = defaults_.find(var);
    if (it == defaults_.end())
      fail(n, std::string("attribute '") + name + "': undefined variable $" + clip(var) +
                  " (no <default name=\"" + clip(var) + "\" .../>, nor -D " + clip(var) + "=...)");
    out += it->second;
    i = j - 1;
  }
  return out;
}

bool Importer::parse_number(const std::string& s, double& v) {
  std::string t = s;
  t.erase(0, t.find_first_not_of(" \t\r\n"));
  t.erase(t.find_last_not_of(" \t\r\n") + 1);
  if (!t.empty() && t[0] == '+') t.erase(0, 1);
  const auto r = std::from_chars(t.data(), t.data() + t.size(), v);
  return !t.empty() && r.ec == std::errc() && r.ptr == t.data() + t.size() && std::isfinite(v);
}

double Importer::number(Node n, const char* what, const std::string& s) const {
  double v = 0;
  if (!parse_number(s, v))
    fail(n, std::string("attribute '") + what + "': expected a finite number (got \"" + clip(s) +
                "\")");
  return v;
}

std::vector<double> Importer::numbers(Node n, const char* what, const std::string& s) const {
  std::vector<double> out;
  std::string tok;
  for (std::size_t i = 0; i <= s.size(); ++i) {
    const char c = i < s.size() ? s[i] : ' ';
    if (c == ',' || std::isspace(static_cast<unsigned char>(c))) {
      if (!tok.empty()) out.push_back(number(n, what, tok));
      tok.clear();
    } else {
      tok += c;
    }
  }
  return out;
}

Vec3 Importer::xyz(Node n, double fallback) const {
  if (n.attribute("value")) {
    if (n.attribute("x") || n.attribute("y") || n.attribute("z"))
      fail(n, "give either 'value' or 'x', 'y', 'z', not both");
    const std::vector<double> v = numbers(n, "value", attr(n, "value"));
    if (v.size() == 1) return Vec3(v[0]);
    if (v.size() != 3)
      fail(n, "attribute 'value': expected 3 numbers (got \"" + clip(attr(n, "value")) + "\")");
    return {v[0], v[1], v[2]};
  }
  Vec3 out(fallback);
  const char* names[3] = {"x", "y", "z"};
  for (int i = 0; i < 3; ++i)
    if (n.attribute(names[i])) out[i] = number(n, names[i], attr(n, names[i]));
  return out;
}

Vec3 Importer::triple(Node n, const char* name) const {
  const std::string s = attr(n, name);
  const std::vector<double> v = numbers(n, name, s);
  if (v.size() != 3)
    fail(n, std::string("attribute '") + name + "': expected 3 numbers (got \"" + clip(s) + "\")");
  return {v[0], v[1], v[2]};
}

}  // namespace femto::mitsuba
