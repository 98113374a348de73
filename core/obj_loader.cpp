#include "core/obj_loader.h"

#include <charconv>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <string_view>

#include "core/error.h"

namespace femto {
namespace {

std::vector<std::string_view> split_ws(std::string_view s) {
  std::vector<std::string_view> out;
  std::size_t i = 0;
  while (i < s.size()) {
    while (i < s.size() && (s[i] == ' ' || s[i] == '\t')) ++i;
    const std::size_t j = i;
    while (i < s.size() && s[i] != ' ' && s[i] != '\t') ++i;
    if (i > j) out.push_back(s.substr(j, i - j));
  }
  return out;
}

// std::from_chars is locale-independent, unlike strtod; it rejects a leading '+', which OBJ allows.
bool parse_double(std::string_view s, double& out) {
  if (!s.empty() && s[0] == '+') s.remove_prefix(1);
  const auto r = std::from_chars(s.data(), s.data() + s.size(), out);
  return r.ec == std::errc() && r.ptr == s.data() + s.size() && std::isfinite(out);
}

bool parse_int(std::string_view s, long long& out) {
  if (!s.empty() && s[0] == '+') s.remove_prefix(1);
  const auto r = std::from_chars(s.data(), s.data() + s.size(), out);
  return r.ec == std::errc() && r.ptr == s.data() + s.size();
}

// Statements that carry no triangle geometry; skipping them loses nothing we could render.
bool ignored_statement(std::string_view k) {
  static const char* const kIgnored[] = {"vt",       "vn",       "vp",         "l",        "p",
                                         "o",        "g",        "s",          "mg",       "usemtl",
                                         "mtllib",   "usemap",   "maplib",     "lod",      "bevel",
                                         "c_interp", "d_interp", "shadow_obj", "trace_obj"};
  for (const char* s : kIgnored)
    if (k == s) return true;
  return false;
}

}  // namespace

void load_obj(const std::string& path, std::vector<Vec3>& vertices,
              std::vector<std::array<uint32_t, 3>>& triangles) {
  constexpr std::uintmax_t kMaxObjBytes = 1ull << 30;  // docs/scene-format.md, Bounds
  std::error_code ec;
  const std::uintmax_t size = std::filesystem::file_size(path, ec);
  if (ec) throw InputError(clip(path, 200) + ": cannot read mesh file (" + ec.message() + ")");
  if (size > kMaxObjBytes) throw InputError(clip(path, 200) + ": mesh file is larger than the 1 GiB limit");
  std::ifstream in(path);
  if (!in) throw InputError(clip(path, 200) + ": cannot open mesh file");
  vertices.clear();
  triangles.clear();

  std::size_t line_no = 0;
  auto fail = [&](const std::string& problem) -> void {
    throw InputError(clip(path, 200) + ":" + std::to_string(line_no) + ": " + problem);
  };
  // Positive indices may point forward, so they are range-checked once the whole file is read.
  long long max_index = 0;
  std::size_t max_index_line = 0;

  std::string line;
  std::vector<uint32_t> poly;
  while (std::getline(in, line)) {
    ++line_no;
    std::string_view sv(line);
    if (const auto hash = sv.find('#'); hash != std::string_view::npos) sv = sv.substr(0, hash);
    if (!sv.empty() && sv.back() == '\r') sv.remove_suffix(1);
    const auto tok = split_ws(sv);
    if (tok.empty()) continue;
    const std::string_view key = tok[0];

    if (key == "v") {
      // x y z, optionally followed by w or by an r g b vertex colour, which are ignored.
      if (tok.size() < 4 || tok.size() > 7)
        fail("a vertex needs 3 coordinates (got " + std::to_string(tok.size() - 1) + " values)");
      Vec3 p;
      for (int a = 0; a < 3; ++a)
        if (!parse_double(tok[static_cast<std::size_t>(a) + 1], p[a]))
          fail("bad number '" + clip(std::string(tok[static_cast<std::size_t>(a) + 1])) + "'");
      if (vertices.size() >= std::numeric_limits<uint32_t>::max()) fail("too many vertices");
      vertices.push_back(p);
    } else if (key == "f") {
      if (tok.size() < 4)
        fail("a face needs at least 3 vertices (got " + std::to_string(tok.size() - 1) + ")");
      poly.clear();
      for (std::size_t c = 1; c < tok.size(); ++c) {
        const std::string_view corner = tok[c];
        // Corner forms v, v/vt, v//vn, v/vt/vn: only v is used, the rest is syntax-checked.
        std::vector<std::string_view> parts;
        std::size_t start = 0;
        for (std::size_t i = 0; i <= corner.size(); ++i)
          if (i == corner.size() || corner[i] == '/') {
            parts.push_back(corner.substr(start, i - start));
            start = i + 1;
          }
        long long idx = 0, unused = 0;
        bool ok = parts.size() <= 3 && parse_int(parts[0], idx) && idx != 0;
        if (ok && parts.size() == 2) ok = parse_int(parts[1], unused);
        if (ok && parts.size() == 3)
          ok = (parts[1].empty() || parse_int(parts[1], unused)) && parse_int(parts[2], unused);
        if (!ok) fail("bad face vertex '" + clip(std::string(corner)) + "'");
        const long long n = static_cast<long long>(vertices.size());
        if (idx < 0) {
          if (-idx > n)
            fail("face index " + std::to_string(idx) + " is out of range (" + std::to_string(n) +
                 " vertices defined so far)");
          idx += n;
        } else {
          if (idx > max_index) {
            max_index = idx;
            max_index_line = line_no;
          }
          idx -= 1;
        }
        if (idx > static_cast<long long>(std::numeric_limits<uint32_t>::max()))
          fail("face index " + clip(std::string(corner)) + " is too large");
        poly.push_back(static_cast<uint32_t>(idx));
      }
      for (std::size_t k = 1; k + 1 < poly.size(); ++k)
        triangles.push_back({poly[0], poly[k], poly[k + 1]});
    } else if (!ignored_statement(key)) {
      fail("unsupported OBJ statement '" + clip(std::string(key)) +
           "' (only polygonal meshes are supported)");
    }
  }
  if (in.bad()) throw InputError(clip(path, 200) + ": read error");
  if (max_index > static_cast<long long>(vertices.size())) {
    line_no = max_index_line;
    fail("face index " + std::to_string(max_index) + " is out of range (the file has " +
         std::to_string(vertices.size()) + " vertices)");
  }
  if (triangles.empty()) throw InputError(clip(path, 200) + ": mesh has no faces");
}

}  // namespace femto
