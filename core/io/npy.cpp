#include "core/io/npy.h"

#include <cerrno>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <limits>
#include <memory>

#include "core/error.h"
#include "core/io/atomic_file.h"

#if !defined(__BYTE_ORDER__) || __BYTE_ORDER__ != __ORDER_LITTLE_ENDIAN__
#error "npy.cpp writes host floats as '<f4' and assumes a little-endian host"
#endif

namespace femto {
namespace {

constexpr char kMagic[] = "\x93NUMPY";  // 6 bytes + implicit NUL
constexpr size_t kMagicLen = 6;

struct FileCloser {
  void operator()(std::FILE* f) const { std::fclose(f); }
};
using FilePtr = std::unique_ptr<std::FILE, FileCloser>;

[[noreturn]] void fail(const std::string& path, const std::string& what) {
  throw RuntimeError("NPY '" + path + "': " + what);
}

size_t element_count(const std::vector<size_t>& shape) {
  size_t n = 1;
  for (size_t d : shape) {
    if (d != 0 && n > std::numeric_limits<size_t>::max() / d) return std::numeric_limits<size_t>::max();
    n *= d;
  }
  return n;
}

// The dict text numpy expects; the spec asks for a trailing comma in 1-tuples.
std::string header_dict(const std::vector<size_t>& shape) {
  std::string s = "{'descr': '<f4', 'fortran_order': False, 'shape': (";
  for (size_t i = 0; i < shape.size(); ++i) s += (i ? ", " : "") + std::to_string(shape[i]);
  if (shape.size() == 1) s += ",";
  return s + "), }";
}

// Value text following 'key': in the header dict (up to the next ',' or '}' outside parens).
std::string dict_value(const std::string& path, const std::string& dict, const std::string& key) {
  size_t k = dict.find("'" + key + "'");
  if (k == std::string::npos) k = dict.find("\"" + key + "\"");
  if (k == std::string::npos) fail(path, "header lacks '" + key + "'");
  size_t p = dict.find(':', k + key.size() + 2);
  if (p == std::string::npos) fail(path, "malformed header");
  ++p;
  while (p < dict.size() && dict[p] == ' ') ++p;
  size_t e = p;
  if (p < dict.size() && dict[p] == '(') {
    e = dict.find(')', p);
    if (e == std::string::npos) fail(path, "malformed shape in header");
    return dict.substr(p, e + 1 - p);
  }
  while (e < dict.size() && dict[e] != ',' && dict[e] != '}') ++e;
  while (e > p && dict[e - 1] == ' ') --e;
  return dict.substr(p, e - p);
}

std::vector<size_t> parse_shape(const std::string& path, const std::string& tuple) {
  std::vector<size_t> shape;
  size_t i = 1;  // skip '('
  while (i < tuple.size()) {
    const char c = tuple[i];
    if (c == ' ' || c == ',' || c == ')') { ++i; continue; }
    if (c < '0' || c > '9') fail(path, "bad shape " + tuple);
    size_t v = 0;
    while (i < tuple.size() && tuple[i] >= '0' && tuple[i] <= '9') {
      const size_t digit = static_cast<size_t>(tuple[i++] - '0');
      if (v > (std::numeric_limits<size_t>::max() - digit) / 10) fail(path, "shape overflows");
      v = v * 10 + digit;
    }
    shape.push_back(v);
  }
  return shape;
}

}  // namespace

void write_npy_float32(const std::string& path, const std::vector<size_t>& shape, const float* data) {
  const size_t count = element_count(shape);
  if (count == std::numeric_limits<size_t>::max()) fail(path, "shape overflows");
  if (count > 0 && !data) fail(path, "null data");
  std::string dict = header_dict(shape);
  // Version 1.0 has a 2-byte header length; fall back to 2.0 (4 bytes) for huge headers.
  size_t prefix = kMagicLen + 2 + 2;
  size_t total = (prefix + dict.size() + 1 + 63) / 64 * 64;  // +1 for the '\n'; pad to 64
  const bool v2 = total - prefix > 0xFFFF;
  if (v2) {
    prefix = kMagicLen + 2 + 4;
    total = (prefix + dict.size() + 1 + 63) / 64 * 64;
  }
  const size_t hlen = total - prefix;
  dict.append(hlen - dict.size() - 1, ' ');
  dict.push_back('\n');

  std::string head(kMagic, kMagicLen);
  head.push_back(static_cast<char>(v2 ? 2 : 1));
  head.push_back(0);
  for (size_t b = 0; b < (v2 ? 4u : 2u); ++b) head.push_back(static_cast<char>((hlen >> (8 * b)) & 0xFF));
  head += dict;

  write_atomically(path, [&](const std::string& tmp) {
    FilePtr f(std::fopen(tmp.c_str(), "wb"));
    if (!f) fail(path, std::strerror(errno));
    if (std::fwrite(head.data(), 1, head.size(), f.get()) != head.size() ||
        (count > 0 && std::fwrite(data, sizeof(float), count, f.get()) != count))
      fail(path, std::string("write failed: ") + std::strerror(errno));
    if (std::fclose(f.release()) != 0) fail(path, std::string("close failed: ") + std::strerror(errno));
  });
}

void read_npy_float32(const std::string& path, std::vector<size_t>& shape, std::vector<float>& data) {
  FilePtr f(std::fopen(path.c_str(), "rb"));
  if (!f) fail(path, std::strerror(errno));
  unsigned char pre[kMagicLen + 2];
  if (std::fread(pre, 1, sizeof pre, f.get()) != sizeof pre || std::memcmp(pre, kMagic, kMagicLen) != 0)
    fail(path, "not an NPY file (bad magic)");
  const int major = pre[kMagicLen];
  if (major < 1 || major > 3) fail(path, "unsupported NPY version " + std::to_string(major));
  const size_t len_bytes = major == 1 ? 2 : 4;
  unsigned char lb[4] = {0, 0, 0, 0};
  if (std::fread(lb, 1, len_bytes, f.get()) != len_bytes) fail(path, "truncated header");
  const size_t hlen = lb[0] | (size_t(lb[1]) << 8) | (size_t(lb[2]) << 16) | (size_t(lb[3]) << 24);
  std::string dict(hlen, '\0');
  if (std::fread(&dict[0], 1, hlen, f.get()) != hlen) fail(path, "truncated header");

  const std::string descr = dict_value(path, dict, "descr");
  if (descr != "'<f4'" && descr != "\"<f4\"") fail(path, "dtype " + descr + " is not '<f4'");
  if (dict_value(path, dict, "fortran_order") != "False") fail(path, "Fortran order is not supported");
  const std::string tuple = dict_value(path, dict, "shape");
  if (tuple.empty() || tuple.front() != '(') fail(path, "bad shape " + tuple);
  std::vector<size_t> s = parse_shape(path, tuple);

  const size_t count = element_count(s);
  if (count == std::numeric_limits<size_t>::max()) fail(path, "shape overflows");
  // Check the size before allocating, so a corrupt shape cannot trigger a huge allocation.
  const long pos = std::ftell(f.get());
  if (pos < 0 || std::fseek(f.get(), 0, SEEK_END) != 0) fail(path, "cannot seek");
  const long end = std::ftell(f.get());
  if (end < pos || std::fseek(f.get(), pos, SEEK_SET) != 0) fail(path, "cannot seek");
  const size_t bytes = static_cast<size_t>(end - pos);
  if (count > bytes / sizeof(float) || bytes != count * sizeof(float))
    fail(path, std::to_string(bytes) + " data bytes do not match shape " + tuple);
  std::vector<float> d(count);
  if (count > 0 && std::fread(d.data(), sizeof(float), count, f.get()) != count)
    fail(path, "short read");
  shape = std::move(s);
  data = std::move(d);
}

}  // namespace femto
