// Message text: numbers, JSON paths, values after "got", and "did you mean" suggestions.
#include <algorithm>
#include <cstdio>

#include "core/error.h"
#include "core/scene_json/loader.h"

namespace femto::scene_json {

std::string fmt(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%g", v);
  return buf;
}

std::string fmt(const Vec3& v) {
  return "[" + fmt(v.x) + ", " + fmt(v.y) + ", " + fmt(v.z) + "]";
}

namespace {

// JSON pointer escaping (RFC 6901), so a medium named "a/b" still yields a usable path.
std::string escape_key(const std::string& key) {
  std::string out;
  for (char ch : clip(key, 40)) {  // a path is for messages: keep each step short
    if (ch == '~')
      out += "~0";
    else if (ch == '/')
      out += "~1";
    else
      out += ch;
  }
  return out;
}

std::size_t edit_distance(const std::string& a, const std::string& b) {
  std::vector<std::size_t> row(b.size() + 1);
  for (std::size_t j = 0; j <= b.size(); ++j) row[j] = j;
  for (std::size_t i = 1; i <= a.size(); ++i) {
    std::size_t diag = row[0];
    row[0] = i;
    for (std::size_t j = 1; j <= b.size(); ++j) {
      const std::size_t up = row[j];
      row[j] = std::min({row[j] + 1, row[j - 1] + 1, diag + (a[i - 1] == b[j - 1] ? 0u : 1u)});
      diag = up;
    }
  }
  return row[b.size()];
}

}  // namespace

std::string at(const std::string& path, const std::string& key) {
  return path + "/" + escape_key(key);
}
std::string at(const std::string& path, std::size_t index) {
  return path + "/" + std::to_string(index);
}

// A value as shown after "got": compact, and short so the message stays readable on one line.
// Values are at most kMaxNesting deep (checked while parsing), so dump() cannot recurse far.
std::string show(const Json& v) {
  if (v.is_string()) return clip(Json(clip(v.get<std::string>(), 200)).dump());
  return clip(v.dump());
}

// " (did you mean 'x'?)" for the closest option within edit distance 2, else "".
std::string suggest(const std::string& got, const Keys& options) {
  constexpr std::size_t kMaxLen = 64;  // edit distance is quadratic: long names get no hint
  if (got.size() > kMaxLen) return "";
  std::size_t best = 3;
  std::string pick;
  for (const auto& o : options) {
    if (o.size() > kMaxLen || o.size() + 2 < got.size() || got.size() + 2 < o.size()) continue;
    const std::size_t d = edit_distance(got, o);
    if (d < best) {
      best = d;
      pick = o;
    }
  }
  return pick.empty() ? "" : " (did you mean '" + pick + "'?)";
}

// At most 10 entries, each clipped: the list is user data when it names media.
std::string quoted_list(const Keys& options) {
  std::string s;
  const std::size_t n = std::min<std::size_t>(options.size(), 10);
  for (std::size_t i = 0; i < n; ++i) s += (i ? ", \"" : "\"") + clip(options[i], 40) + "\"";
  if (options.size() > n) s += " and " + std::to_string(options.size() - n) + " more";
  return s;
}

}  // namespace femto::scene_json
