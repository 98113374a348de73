// Generic value readers: keys, numbers in range, integers, strings, choices, vectors, colours.
#include <algorithm>
#include <climits>
#include <cmath>
#include <filesystem>

#include "core/error.h"
#include "core/scene_json/loader.h"

namespace femto::scene_json {

namespace fs = std::filesystem;

const Json* Loader::find(const Json& o, const std::string& key) {
  const auto it = o.find(key);
  return it == o.end() ? nullptr : &*it;
}

const Json& Loader::require(const Json& o, const std::string& path, const std::string& key) const {
  const Json* v = find(o, key);
  if (!v) fail(at(path, key), "missing required key '" + key + "'");
  return *v;
}

const Json& Loader::object(const Json& v, const std::string& path) const {
  if (!v.is_object()) fail(path, "expected an object", v);
  return v;
}

/// Rejects keys outside `allowed`; keys listed in `elsewhere` are valid for another type, so
/// the message says they do not apply to `what` instead of calling them unknown.
void Loader::check_keys(const Json& o, const std::string& path, const Keys& allowed,
                        const std::string& what, const Keys& elsewhere) const {
  for (const auto& item : o.items()) {
    const std::string& k = item.key();
    if (std::find(allowed.begin(), allowed.end(), k) != allowed.end()) continue;
    if (std::find(elsewhere.begin(), elsewhere.end(), k) != elsewhere.end())
      fail(at(path, k), "key '" + clip(k) + "' does not apply to " + what);
    fail(at(path, k), "unknown key '" + clip(k) + "'" + suggest(k, allowed));
  }
}

double Loader::number(const Json& v, const std::string& path, const Range& r) const {
  if (!v.is_number()) fail(path, "expected a number", v);
  const double x = v.get<double>();
  if (!std::isfinite(x)) fail(path, "must be finite", v);
  if (!r.contains(x)) fail(path, r.text(), v);
  if (std::abs(x) > kMaxMagnitude)
    fail(path, "must be within +-1e9, the bound for every number (docs/scene-format.md, Bounds)",
         v);
  return x;
}

/// Rejects a positive value below `lo` (lengths and rates that get inverted).
double Loader::not_tiny(double x, double lo, const std::string& path, const Json& v) const {
  if (x < lo) fail(path, "must be >= " + fmt(lo) + " (docs/scene-format.md, Bounds)", v);
  return x;
}

long long Loader::integer(const Json& v, const std::string& path, long long lo,
                          long long hi) const {
  long long x = 0;
  if (v.is_number_unsigned() && v.get<std::uint64_t>() > static_cast<std::uint64_t>(LLONG_MAX))
    x = LLONG_MAX;
  else if (v.is_number_integer())
    x = v.get<long long>();
  else if (v.is_number_float() && std::floor(v.get<double>()) == v.get<double>() &&
           std::abs(v.get<double>()) < 9e18)  // accept 1e6 and 16.0
    x = static_cast<long long>(v.get<double>());
  else
    fail(path, "expected an integer", v);
  if (x < lo || x > hi)
    fail(path,
         hi == LLONG_MAX ? "must be >= " + std::to_string(lo)
                         : "must be in [" + std::to_string(lo) + ", " + std::to_string(hi) + "]",
         v);
  return x;
}

int Loader::int_in(const Json& v, const std::string& path, int lo, int hi) const {
  return static_cast<int>(integer(v, path, lo, hi));
}

std::string Loader::string(const Json& v, const std::string& path) const {
  if (!v.is_string()) fail(path, "expected a string", v);
  return v.get<std::string>();
}

std::string Loader::choice(const Json& v, const std::string& path, const Keys& options) const {
  const std::string s = string(v, path);
  if (std::find(options.begin(), options.end(), s) == options.end())
    fail(path, "must be one of " + quoted_list(options) + suggest(s, options), v);
  return s;
}

Vec3 Loader::vec3(const Json& v, const std::string& path) const {
  if (!v.is_array() || v.size() != 3 ||
      !std::all_of(v.begin(), v.end(), [](const Json& c) { return c.is_number(); }))
    fail(path, "expected an array of 3 numbers", v);
  Vec3 out;
  for (int i = 0; i < 3; ++i) out[i] = number(v[static_cast<std::size_t>(i)], at(path, i));
  return out;
}

Vec3 Loader::nonzero_vec3(const Json& v, const std::string& path) const {
  const Vec3 d = vec3(v, path);
  if (!(length(d) > 0)) fail(path, "must be a non-zero vector", v);
  return d;
}

/// A colour: one number (grey) or [r, g, b], each in [0, hi].
RGB Loader::rgb(const Json& v, const std::string& path, double hi) const {
  const Range r = hi == kInf ? at_least(0) : within(0, hi);
  if (v.is_number()) return RGB(number(v, path, r));
  if (!v.is_array() || v.size() != 3 ||
      !std::all_of(v.begin(), v.end(), [](const Json& c) { return c.is_number(); }))
    fail(path, "expected a number or an array of 3 numbers", v);
  return {number(v[0], at(path, 0), r), number(v[1], at(path, 1), r), number(v[2], at(path, 2), r)};
}

/// An emitted quantity: like rgb(), but all-zero is rejected since such an emitter would only
/// dilute light sampling.
RGB Loader::bright_rgb(const Json& v, const std::string& path) const {
  const RGB c = rgb(v, path);
  if (c.is_black()) fail(path, "must be > 0 in some channel", v);
  return c;
}

/// Reads "type" from a typed object; a missing type is reported after checking the keys
/// against every type, so a misspelt "tpye" gets its own, clearer message.
std::string Loader::type_of(const Json& o, const std::string& path, const Keys& types,
                            const Keys& all_keys) const {
  const Json* t = find(o, "type");
  if (!t) {
    check_keys(o, path, all_keys);
    fail(at(path, "type"), "missing required key 'type' (one of " + quoted_list(types) + ")");
  }
  return choice(*t, at(path, "type"), types);
}

Keys Loader::join(Keys a, const Keys& b) {
  a.insert(a.end(), b.begin(), b.end());
  return a;
}

std::string Loader::resolve(const std::string& file) const {
  fs::path f(file);
  if (f.is_relative() && !base_dir_.empty()) f = fs::path(base_dir_) / f;
  return f.lexically_normal().string();
}

}  // namespace femto::scene_json
