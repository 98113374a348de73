#include "core/io/ply.h"

#include <cctype>
#include <charconv>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string_view>

#include "core/error.h"

namespace femto {
namespace {

constexpr std::uintmax_t kMaxPlyBytes = 1ull << 30;  // the same bound as OBJ meshes

enum class Scalar { Int8, UInt8, Int16, UInt16, Int32, UInt32, Float32, Float64 };

bool scalar_of(const std::string& name, Scalar& s) {
  static const struct {
    const char* name;
    Scalar type;
  } kTypes[] = {
      {"char", Scalar::Int8},      {"int8", Scalar::Int8},       {"uchar", Scalar::UInt8},
      {"uint8", Scalar::UInt8},    {"short", Scalar::Int16},     {"int16", Scalar::Int16},
      {"ushort", Scalar::UInt16},  {"uint16", Scalar::UInt16},   {"int", Scalar::Int32},
      {"int32", Scalar::Int32},    {"uint", Scalar::UInt32},     {"uint32", Scalar::UInt32},
      {"float", Scalar::Float32},  {"float32", Scalar::Float32}, {"double", Scalar::Float64},
      {"float64", Scalar::Float64}};
  for (const auto& t : kTypes)
    if (name == t.name) {
      s = t.type;
      return true;
    }
  return false;
}

std::size_t size_of(Scalar s) {
  switch (s) {
    case Scalar::Int8:
    case Scalar::UInt8:
      return 1;
    case Scalar::Int16:
    case Scalar::UInt16:
      return 2;
    case Scalar::Int32:
    case Scalar::UInt32:
    case Scalar::Float32:
      return 4;
    case Scalar::Float64:
      return 8;
  }
  return 1;
}

struct Property {
  std::string name;
  bool is_list = false;
  Scalar count_type = Scalar::UInt8;  ///< list length type
  Scalar type = Scalar::Float32;      ///< value (or list item) type
};

struct Element {
  std::string name;
  std::uint64_t count = 0;
  std::vector<Property> properties;
};

/// Reads values in file order from either encoding; `what()` names the place for messages.
class Reader {
 public:
  Reader(const std::string& path, const std::string& data, std::size_t pos, bool ascii)
      : path_(path), data_(data), pos_(pos), ascii_(ascii) {}

  [[noreturn]] void fail(const std::string& problem) const {
    throw InputError(clip(path_, 200) + ": " + problem);
  }

  double value(Scalar t, const char* what) {
    if (ascii_) return ascii_value(t, what);
    const std::size_t n = size_of(t);
    if (data_.size() - pos_ < n) fail(std::string("file ends inside the data (") + what + ")");
    unsigned char b[8] = {};
    std::memcpy(b, data_.data() + pos_, n);
    pos_ += n;
    std::uint64_t u = 0;  // little-endian bytes, independent of the host's order
    for (std::size_t i = 0; i < n; ++i) u |= std::uint64_t(b[i]) << (8 * i);
    switch (t) {
      case Scalar::Int8:
        return static_cast<std::int8_t>(u);
      case Scalar::UInt8:
        return static_cast<double>(u);
      case Scalar::Int16:
        return static_cast<std::int16_t>(u);
      case Scalar::UInt16:
        return static_cast<double>(u);
      case Scalar::Int32:
        return static_cast<std::int32_t>(u);
      case Scalar::UInt32:
        return static_cast<double>(u);
      case Scalar::Float32: {
        float f;
        const std::uint32_t u32 = static_cast<std::uint32_t>(u);
        std::memcpy(&f, &u32, 4);
        return f;
      }
      case Scalar::Float64: {
        double d;
        std::memcpy(&d, &u, 8);
        return d;
      }
    }
    return 0;
  }

  /// Bytes left to read (binary), to bound element counts before allocating.
  std::size_t remaining() const { return data_.size() - pos_; }

 private:
  double ascii_value(Scalar t, const char* what) {
    while (pos_ < data_.size() && std::isspace(static_cast<unsigned char>(data_[pos_]))) ++pos_;
    std::size_t end = pos_;
    while (end < data_.size() && !std::isspace(static_cast<unsigned char>(data_[end]))) ++end;
    if (end == pos_) fail(std::string("file ends inside the data (") + what + ")");
    std::string_view tok(data_.data() + pos_, end - pos_);
    if (!tok.empty() && tok[0] == '+') tok.remove_prefix(1);
    double v = 0;
    const auto r = std::from_chars(tok.data(), tok.data() + tok.size(), v);
    if (r.ec != std::errc() || r.ptr != tok.data() + tok.size() || !std::isfinite(v))
      fail(std::string("bad number '") + clip(std::string(data_.substr(pos_, end - pos_)), 40) +
           "' (" + what + ")");
    if (t != Scalar::Float32 && t != Scalar::Float64 && std::floor(v) != v)
      fail(std::string("expected an integer, got '") + clip(std::string(tok), 40) + "' (" + what +
           ")");
    pos_ = end;
    return v;
  }

  const std::string& path_;
  const std::string& data_;
  std::size_t pos_;
  bool ascii_;
};

}  // namespace

void load_ply(const std::string& path, std::vector<Vec3>& vertices,
              std::vector<std::array<uint32_t, 3>>& triangles) {
  const std::string name = clip(path, 200);
  std::error_code ec;
  const std::uintmax_t bytes = std::filesystem::file_size(path, ec);
  if (ec) throw InputError(name + ": cannot read PLY file");
  if (bytes > kMaxPlyBytes) throw InputError(name + ": PLY file is larger than the 1 GiB limit");
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(name + ": cannot open PLY file");
  std::string data((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());

  // ---- header: text lines up to "end_header"
  std::size_t pos = 0;
  int line_no = 0;
  auto next_line = [&](std::string& line) {
    if (pos >= data.size()) return false;
    std::size_t end = data.find('\n', pos);
    if (end == std::string::npos) end = data.size();
    line = data.substr(pos, end - pos);
    if (!line.empty() && line.back() == '\r') line.pop_back();
    pos = end + 1;
    ++line_no;
    return true;
  };
  auto bad = [&](const std::string& problem) {
    throw InputError(name + ":" + std::to_string(line_no) + ": " + problem);
  };
  std::string line;
  if (!next_line(line) || line != "ply")
    throw InputError(name + ": not a PLY file (no 'ply' line)");
  bool ascii = false, format_seen = false, ended = false;
  std::vector<Element> elements;
  while (next_line(line)) {
    std::istringstream ss(line);
    std::string key;
    ss >> key;
    if (key.empty() || key == "comment" || key == "obj_info") continue;
    if (key == "end_header") {
      ended = true;
      break;
    }
    if (key == "format") {
      std::string f, version;
      ss >> f >> version;
      if (f == "ascii")
        ascii = true;
      else if (f == "binary_little_endian")
        ascii = false;
      else if (f == "binary_big_endian")
        bad("binary big-endian PLY is not supported; convert it to little-endian or ASCII");
      else
        bad("unknown format '" + clip(f, 40) + "'");
      format_seen = true;
    } else if (key == "element") {
      Element e;
      long long count = -1;
      ss >> e.name >> count;
      if (e.name.empty() || count < 0 || !ss) bad("expected 'element <name> <count>'");
      e.count = static_cast<std::uint64_t>(count);
      elements.push_back(e);
    } else if (key == "property") {
      if (elements.empty()) bad("'property' before any 'element'");
      Property p;
      std::string t;
      ss >> t;
      if (t == "list") {
        std::string ct, it;
        ss >> ct >> it >> p.name;
        p.is_list = true;
        if (!scalar_of(ct, p.count_type) || !scalar_of(it, p.type) || p.name.empty())
          bad("expected 'property list <count type> <item type> <name>'");
        if (p.count_type == Scalar::Float32 || p.count_type == Scalar::Float64)
          bad("a list length must have an integer type");
      } else {
        ss >> p.name;
        if (!scalar_of(t, p.type) || p.name.empty())
          bad("unknown property type '" + clip(t, 40) + "'");
      }
      elements.back().properties.push_back(p);
    } else {
      bad("unknown header line '" + clip(line, 60) + "'");
    }
  }
  if (!ended) throw InputError(name + ": PLY header has no 'end_header' line");
  if (!format_seen) throw InputError(name + ": PLY header has no 'format' line");

  // ---- data
  Reader r(path, data, pos, ascii);
  vertices.clear();
  triangles.clear();
  bool have_faces = false;
  for (const Element& e : elements) {
    const bool is_vertex = e.name == "vertex", is_face = e.name == "face";
    int ix = -1, iy = -1, iz = -1, iidx = -1;
    for (std::size_t k = 0; k < e.properties.size(); ++k) {
      const std::string& n = e.properties[k].name;
      const int ki = static_cast<int>(k);
      if (n == "x") ix = ki;
      if (n == "y") iy = ki;
      if (n == "z") iz = ki;
      if (n == "vertex_indices" || n == "vertex_index") iidx = ki;
    }
    if (is_vertex && (ix < 0 || iy < 0 || iz < 0))
      r.fail("element 'vertex' needs properties x, y and z");
    if (is_face && (iidx < 0 || !e.properties[static_cast<std::size_t>(iidx)].is_list))
      r.fail("element 'face' needs a list property 'vertex_indices'");
    // Each entry takes at least one byte (binary) or two characters (ASCII): bounds the count
    // before anything is allocated for it.
    if (e.count > r.remaining())
      r.fail("element '" + clip(e.name, 40) + "' count " + std::to_string(e.count) +
             " exceeds the file's data");
    if (is_vertex) {
      if (e.count > 0xFFFFFFFFull) r.fail("more than 2^32 - 1 vertices");
      vertices.reserve(static_cast<std::size_t>(e.count));
    }
    for (std::uint64_t i = 0; i < e.count; ++i) {
      Vec3 v;
      std::vector<uint32_t> face;
      for (std::size_t k = 0; k < e.properties.size(); ++k) {
        const Property& p = e.properties[k];
        const int ki = static_cast<int>(k);
        if (!p.is_list) {
          const double x = r.value(p.type, is_vertex ? "vertex" : "element value");
          if (!std::isfinite(x)) r.fail("vertex " + std::to_string(i) + " is not finite");
          if (is_vertex && ki == ix) v.x = x;
          if (is_vertex && ki == iy) v.y = x;
          if (is_vertex && ki == iz) v.z = x;
          continue;
        }
        const double n = r.value(p.count_type, "list length");
        if (n < 0) r.fail("negative list length in element '" + clip(e.name, 40) + "'");
        const auto count = static_cast<std::uint64_t>(n);
        if (count > r.remaining())
          r.fail("list length " + std::to_string(count) + " exceeds the file's data");
        for (std::uint64_t j = 0; j < count; ++j) {
          const double idx = r.value(p.type, "face index");
          if (is_face && ki == iidx) {
            if (idx < 0 || idx >= static_cast<double>(vertices.size()))
              r.fail("face " + std::to_string(i) + ": vertex index " +
                     std::to_string(static_cast<long long>(idx)) + " out of range (" +
                     std::to_string(vertices.size()) + " vertices precede the faces)");
            face.push_back(static_cast<uint32_t>(idx));
          }
        }
      }
      if (is_vertex) vertices.push_back(v);
      if (is_face) {
        if (face.size() < 3)
          r.fail("face " + std::to_string(i) + " has " + std::to_string(face.size()) +
                 " corners; at least 3 needed");
        for (std::size_t j = 1; j + 1 < face.size(); ++j)
          triangles.push_back({face[0], face[j], face[j + 1]});
        have_faces = true;
      }
    }
  }
  if (!have_faces) throw InputError(name + ": PLY file has no faces");
}

}  // namespace femto
