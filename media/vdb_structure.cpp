#include "media/vdb_structure.h"

#include <array>
#include <cstdint>
#include <fstream>
#include <map>
#include <utility>
#include <vector>

namespace femto {
namespace {

constexpr int64_t kMagic = 0x56444220;  // "VDB " as a little-endian int64
constexpr uint32_t kOldestVersion = 219;  // file format with grid offsets and no grid map
constexpr uint32_t kNewestVersion = 224;  // what the linked OpenVDB 10 writes
constexpr uint32_t kMaxString = 1u << 20;  // names and type names; real ones are short
constexpr uint32_t kZip = 0x1, kActiveMask = 0x2, kBlosc = 0x4;
constexpr uint32_t kKnownCompression = kZip | kActiveMask | kBlosc;

struct Bad {
  std::string what;
};

/// Little-endian reads that never go past `end` (the file size, or a grid's end offset).
class Reader {
 public:
  Reader(std::ifstream& in, uint64_t size) : in_(in), end_(size), size_(size) {}

  uint64_t pos() const { return pos_; }
  uint64_t end() const { return end_; }
  uint64_t size() const { return size_; }
  void set_end(uint64_t end) { end_ = end; }

  template <class T>
  T read(const std::string& what) {
    T v{};
    bytes(reinterpret_cast<char*>(&v), sizeof v, what);
    return v;
  }

  std::string string(const std::string& what) {
    const uint32_t n = read<uint32_t>(what + " length");
    if (n > kMaxString)
      throw Bad{what + " claims " + std::to_string(n) + " bytes, above the 1 MiB limit"};
    std::string s(n, '\0');
    bytes(s.data(), n, what);
    return s;
  }

  void skip(uint64_t n, const std::string& what) {
    need(n, what);
    seek(pos_ + n);
  }

  void seek(uint64_t p) {
    in_.seekg(static_cast<std::streamoff>(p));
    pos_ = p;
  }

 private:
  void need(uint64_t n, const std::string& what) const {
    if (n > end_ - pos_)
      throw Bad{what + " claims " + std::to_string(n) + " bytes at offset " + std::to_string(pos_) +
                " but only " + std::to_string(end_ - pos_) + " remain"};
  }
  void bytes(char* dst, uint64_t n, const std::string& what) {
    need(n, what);
    in_.read(dst, static_cast<std::streamsize>(n));
    if (!in_) throw Bad{"cannot read " + what + " at offset " + std::to_string(pos_)};
    pos_ += n;
  }

  std::ifstream& in_;
  uint64_t end_, size_;
  uint64_t pos_ = 0;
};

// The value size of OpenVDB's fixed-size metadata types (Types.h, typeNameAsString), or 0.
// OpenVDB reads these with their own size whatever size the file states, so a wrong stated size
// would make it read the rest of the file out of step (e.g. a string length taken from a float).
uint32_t fixed_metadata_size(const std::string& type) {
  static const std::pair<const char*, uint32_t> kSizes[] = {
      {"bool", 1},    {"half", 2},     {"float", 4},   {"double", 8},   {"int8", 1},
      {"uint8", 1},   {"int16", 2},    {"uint16", 2},  {"int32", 4},    {"uint32", 4},
      {"int64", 8},   {"vec2i", 8},    {"vec2s", 8},   {"vec2d", 16},   {"vec3u8", 3},
      {"vec3u16", 6}, {"vec3i", 12},   {"vec3s", 12},  {"vec3d", 24},   {"vec4i", 16},
      {"vec4s", 16},  {"vec4d", 32},   {"mat3s", 36},  {"mat3d", 72},   {"mat4s", 64},
      {"mat4d", 128}, {"quats", 16},   {"quatd", 32},  {"ptidx32", 4},  {"ptidx64", 8},
      {"ptdataidx32", 4}, {"ptdataidx64", 8}};
  for (const auto& [name, size] : kSizes)
    if (type == name) return size;
  return 0;
}

// A blosc chunk of `bytes` bytes that must hold `expect` bytes: its header's sizes (blosc trusts
// the compressed size in its header, not the buffer it is given).
void check_blosc(Reader& r, uint64_t bytes, uint64_t expect, const std::string& what) {
  if (bytes < 16) throw Bad{what + " is shorter than a blosc header"};
  r.skip(4, what);
  const uint32_t full = r.read<uint32_t>(what);
  r.skip(4, what);
  const uint32_t packed = r.read<uint32_t>(what);
  if (full < expect || packed > bytes)
    throw Bad{what + " has a blosc header for " + std::to_string(full) + " bytes in " +
              std::to_string(packed) + " where " + std::to_string(expect) + " bytes in " +
              std::to_string(bytes) + " belong"};
  r.skip(bytes - 16, what);
}

// The value of OpenVDB's "__delayedload" metadata (io/DelayedLoadMetadata.cc, readValue): a
// count, then a mask of `count` bytes and `count` compressed sizes of 8 bytes, each raw or as a
// blosc chunk of a stated size. OpenVDB reads these by their own sizes, not the stated one, and
// allocates `count` entries.
void check_delayed_load(Reader& r, uint32_t size, const std::string& entry) {
  if (size == 0) return;
  const uint64_t start = r.pos();
  const uint32_t count = r.read<uint32_t>(entry + " count");
  if (count > r.size() / 64)  // one entry per leaf node, and a leaf takes 64 bytes or more
    throw Bad{entry + " claims " + std::to_string(count) + " leaf nodes, more than the file holds"};
  for (const uint64_t item : {uint64_t(1), uint64_t(8)}) {
    const uint32_t bytes = r.read<uint32_t>(entry + " chunk size");
    if (item == 8 && bytes == UINT32_MAX) break;  // no compressed sizes
    if (bytes > 0)
      check_blosc(r, bytes, count * item, entry + " chunk");
    else
      r.skip(count * item, entry + " values");
  }
  const uint64_t used = r.pos() - start;
  if (used > size)
    throw Bad{entry + " holds " + std::to_string(used) + " bytes but claims " + std::to_string(size)};
  r.skip(size - used, entry + " value");
}

// A metadata map: count, then (name, type name, size, value) per entry.
void check_metadata(Reader& r, const std::string& where) {
  const int32_t count = r.read<int32_t>(where + " metadata count");
  if (count < 0) throw Bad{where + " metadata count is negative"};
  for (int32_t i = 0; i < count; ++i) {
    const std::string entry = where + " metadata entry " + std::to_string(i + 1);
    r.string(entry + " name");
    const std::string type = r.string(entry + " type");
    const uint32_t size = r.read<uint32_t>(entry + " size");
    const uint32_t fixed = fixed_metadata_size(type);
    if (fixed != 0 && size != fixed)
      throw Bad{entry + " of type " + type.substr(0, 16) + " claims " + std::to_string(size) +
                " bytes; the type has " + std::to_string(fixed)};
    if (type == "bool") {  // read into a C++ bool: any byte but 0 or 1 is undefined behaviour
      if (static_cast<unsigned char>(r.read<char>(entry + " value")) > 1)
        throw Bad{entry + " is a bool but is neither 0 nor 1"};
    } else if (type == "__delayedload") {
      check_delayed_load(r, size, entry);
    } else {
      r.skip(size, entry + " value");
    }
  }
}

struct Header {
  uint32_t version = 0;      ///< 0 for a file without grid offsets (written as a stream)
  uint32_t compression = 0;  ///< the file's compression before version 222 (per grid after)
};

Header check_header(Reader& r) {
  if (r.read<int64_t>("the magic number") != kMagic) throw Bad{"not an OpenVDB file (bad magic number)"};
  const uint32_t version = r.read<uint32_t>("the file version");
  if (version < kOldestVersion || version > kNewestVersion)
    throw Bad{"file format version " + std::to_string(version) + " is not supported (" +
              std::to_string(kOldestVersion) + " to " + std::to_string(kNewestVersion) + ")"};
  r.skip(8, "the library version");
  const bool offsets = r.read<char>("the grid-offsets flag") != 0;
  Header h;
  if (version < 222)  // per grid from version 222 on
    h.compression = r.read<char>("the compression flag") != 0 ? kZip : 0;
  r.skip(36, "the file UUID");
  check_metadata(r, "file");
  h.version = offsets ? version : 0;
  return h;
}

// Bytes after the type name of OpenVDB's linear maps (math/Maps.h, read()), or 0 if unknown.
uint64_t linear_map_bytes(const std::string& type) {
  if (type == "AffineMap" || type == "UnitaryMap") return 128;  // a 4x4 double matrix
  if (type == "ScaleMap" || type == "UniformScaleMap") return 120;  // five double vectors
  if (type == "ScaleTranslateMap" || type == "UniformScaleTranslateMap") return 144;  // six
  if (type == "TranslationMap") return 24;
  return 0;
}

// A transform: its map's type name (which OpenVDB reads into a string of the stated length
// before looking the name up), then the map. A frustum holds a box, taper and depth, and a
// second, linear map.
void check_transform(Reader& r, uint32_t version, const std::string& where) {
  const std::string type = r.string(where + " transform type");
  if (type == "NonlinearFrustumMap") {
    r.skip(version >= 221 ? 48 + 16 : 24 + 16, where + " frustum");  // box as doubles from 221
    const std::string second = r.string(where + " frustum map type");
    const uint64_t n = linear_map_bytes(second);
    if (n == 0) throw Bad{where + " frustum has an unknown map type '" + second.substr(0, 40) + "'"};
    r.skip(n, where + " frustum map");
    return;
  }
  const uint64_t n = linear_map_bytes(type);
  if (n == 0) throw Bad{where + " has an unknown transform type '" + type.substr(0, 40) + "'"};
  r.skip(n, where + " transform");
}

// A float tree's node masks and value arrays (tree/InternalNode.h, tree/LeafNode.h,
// io/Compression.h). OpenVDB 10 reads an uncompressed chunk of the stated size into a buffer
// sized for the node and checks the size afterwards (a heap overflow), allocates compressed
// chunks of the stated size, and indexes the active values by the node's value mask. So every
// chunk is checked here against the size its node gives it, with the topology (in front of the
// grid's data offset) and the buffers (after it) walked side by side.
class FloatTreeCheck {
 public:
  FloatTreeCheck(Reader& topology, Reader& buffers, uint32_t version, uint32_t compression,
                 bool half_values, std::string where)
      : topo_(topology),
        buf_(buffers),
        version_(version),
        compression_(compression),
        value_bytes_(half_values ? 2 : 4),
        where_(std::move(where)) {}

  /// The root's tiles and children; then each child's branch in the order OpenVDB reads their
  /// buffers: by origin, the last of children with the same origin.
  void root() {
    topo_.skip(4 + 4, where_ + " buffer count and background");
    const uint32_t tiles = topo_.read<uint32_t>(where_ + " root tile count");
    const uint32_t children = topo_.read<uint32_t>(where_ + " root child count");
    const uint64_t tile_bytes = 12 + 4 + 1;
    const uint64_t child_bytes = 12 + 2 * 4096;  // origin, child mask and value mask at least
    const uint64_t left = topo_.end() - topo_.pos();
    if (uint64_t(tiles) * tile_bytes + uint64_t(children) * child_bytes > left)
      throw Bad{where_ + " root claims " + std::to_string(tiles) + " tiles and " +
                std::to_string(children) + " children, more than the " + std::to_string(left) +
                " bytes of its topology can hold"};
    for (uint32_t i = 0; i < tiles; ++i) {  // the active flag is read into a C++ bool
      topo_.skip(12 + 4, where_ + " root tile");
      if (static_cast<unsigned char>(topo_.read<char>(where_ + " root tile flag")) > 1)
        throw Bad{where_ + " root tile " + std::to_string(i + 1) +
                  " has an active flag that is neither 0 nor 1"};
    }
    std::map<std::array<int32_t, 3>, uint64_t> branches;  // origin -> start of its topology
    for (uint32_t i = 0; i < children; ++i) {
      std::array<int32_t, 3> origin;
      for (int32_t& c : origin) c = topo_.read<int32_t>(where_ + " root child origin");
      branches[origin] = topo_.pos();
      node(2, false);
    }
    const uint64_t end = topo_.pos();
    for (const auto& branch : branches) {
      topo_.seek(branch.second);
      node(2, true);
    }
    topo_.seek(end);
  }

 private:
  using Mask = std::vector<uint64_t>;

  static uint64_t count_on(const Mask& m) {
    uint64_t n = 0;
    for (const uint64_t w : m) n += static_cast<uint64_t>(__builtin_popcountll(w));
    return n;
  }

  Mask mask(Reader& r, uint64_t bits, const std::string& what) {
    Mask m(bits / 64);
    for (uint64_t& w : m) w = r.read<uint64_t>(what);
    return m;
  }

  // readData: `bytes` of values, stored raw or as one zip or blosc chunk.
  void data(Reader& r, uint64_t bytes, uint32_t compression) {
    const std::string what = where_ + " value chunk at offset " + std::to_string(r.pos());
    if (!(compression & (kZip | kBlosc))) {
      r.skip(bytes, what);
      return;
    }
    const int64_t n = r.read<int64_t>(what);
    if (n <= 0) {  // stored uncompressed: OpenVDB reads -n bytes into a buffer of `bytes`
      const uint64_t raw = 0 - static_cast<uint64_t>(n);
      if (raw != bytes)
        throw Bad{what + " holds " + std::to_string(raw) + " uncompressed bytes where the node has " +
                  std::to_string(bytes)};
      r.skip(raw, what);
      return;
    }
    if (compression & kBlosc) {
      check_blosc(r, static_cast<uint64_t>(n), bytes, what);
      return;
    }
    r.skip(static_cast<uint64_t>(n), what);  // zlib bounds its output itself
  }

  // readCompressedValues: `count` values of a node with value mask `on`.
  void values(Reader& r, uint64_t count, const Mask& on) {
    int8_t meta = 6;  // NO_MASK_AND_ALL_VALS
    if (version_ >= 222) meta = r.read<int8_t>(where_ + " node value flags");
    if (meta == 2 || meta == 4 || meta == 5) r.skip(meta == 5 ? 8 : 4, where_ + " inactive values");
    if (meta == 3 || meta == 4 || meta == 5) r.skip(on.size() * 8, where_ + " selection mask");
    if ((compression_ & kActiveMask) && meta != 6 && version_ >= 222) count = count_on(on);
    data(r, count * value_bytes_, compression_);
  }

  // A node at `level` (2 and 1: internal nodes of 32^3 and 16^3 children, 0: a leaf), with its
  // buffers when `buffers`.
  void node(int level, bool buffers) {
    if (level == 0) {
      const Mask on = mask(topo_, 512, where_ + " leaf value mask");
      if (!buffers) return;
      if (mask(buf_, 512, where_ + " leaf value mask") != on)
        throw Bad{where_ + " leaf value mask at offset " + std::to_string(buf_.pos() - 64) +
                  " differs from the tree's"};
      int8_t extra = 0;
      if (version_ < 222) {
        buf_.skip(12, where_ + " leaf origin");
        extra = static_cast<int8_t>(buf_.read<int8_t>(where_ + " leaf buffer count") - 1);
      }
      values(buf_, 512, on);
      for (int i = 0; i < extra; ++i) data(buf_, 512 * value_bytes_, compression_ & kZip);
      return;
    }
    const uint64_t bits = level == 2 ? 32768 : 4096;
    const Mask child = mask(topo_, bits, where_ + " node child mask");
    const Mask on = mask(topo_, bits, where_ + " node value mask");
    values(topo_, version_ < 222 ? bits - count_on(child) : bits, on);
    for (size_t w = 0; w < child.size(); ++w)
      for (int b = 0; b < 64; ++b)
        if (child[w] >> b & 1) node(level - 1, buffers);
  }

  Reader& topo_;
  Reader& buf_;
  uint32_t version_, compression_;
  uint64_t value_bytes_;
  std::string where_;
};

// One grid descriptor (name, type, parent, three offsets), the grid's own metadata, its
// transform and, for a float grid, its tree.
void check_grid(Reader& r, Reader& data, const Header& h, int index) {
  const uint32_t version = h.version;
  const std::string where = "grid " + std::to_string(index + 1);
  r.string(where + " name");
  const std::string type = r.string(where + " type");
  const bool instance = !r.string(where + " instance parent").empty();  // shares another's tree
  const int64_t grid = r.read<int64_t>(where + " offset");
  const int64_t block = r.read<int64_t>(where + " data offset");
  const int64_t end = r.read<int64_t>(where + " end offset");
  const auto inside = [&](int64_t x) { return x >= 0 && static_cast<uint64_t>(x) <= r.size(); };
  if (!inside(grid) || !inside(block) || !inside(end) || static_cast<uint64_t>(grid) < r.pos() ||
      grid > block || block > end)
    throw Bad{where + " offsets " + std::to_string(grid) + ", " + std::to_string(block) + ", " +
              std::to_string(end) + " are not ordered inside the file of " +
              std::to_string(r.size()) + " bytes"};
  r.seek(static_cast<uint64_t>(grid));
  r.set_end(static_cast<uint64_t>(block));
  uint32_t compression = h.compression;
  if (version >= 222) {
    compression = r.read<uint32_t>(where + " compression flags");
    if (compression & ~kKnownCompression)
      throw Bad{where + " has unknown compression flags " + std::to_string(compression)};
  }
  check_metadata(r, where);
  check_transform(r, version, where);  // after the metadata from file version 216 on
  const bool half_values = type == "Tree_float_5_4_3_HalfFloat";
  if (!instance && (type == "Tree_float_5_4_3" || half_values)) {
    data.seek(static_cast<uint64_t>(block));
    data.set_end(static_cast<uint64_t>(end));
    FloatTreeCheck(r, data, version, compression, half_values, where).root();
  }
  r.set_end(r.size());
  r.seek(static_cast<uint64_t>(end));
}

}  // namespace

std::string vdb_structure_problem(const std::string& path) {
  std::ifstream in(path, std::ios::binary | std::ios::ate);
  if (!in) return "cannot open the file";
  const std::streamoff size = in.tellg();
  if (size < 0) return "cannot read the file size";
  in.seekg(0);
  Reader r(in, static_cast<uint64_t>(size));
  std::ifstream in_data(path, std::ios::binary);  // a second position: a grid's buffers
  if (!in_data) return "cannot open the file";
  Reader data(in_data, static_cast<uint64_t>(size));
  try {
    const Header h = check_header(r);
    // Without grid offsets (a file written by openvdb::io::Stream) OpenVDB reads every grid in
    // turn, and where one ends is only known by reading it: such files are not checked, so not
    // read. openvdb::io::File, which the common tools use, always writes the offsets.
    if (h.version == 0)
      return "the file has no grid offsets (it was written as an OpenVDB stream); femto reads "
             "files written with openvdb::io::File";
    const int32_t grids = r.read<int32_t>("the grid count");
    if (grids < 0 || static_cast<uint64_t>(grids) > r.size() / 36)  // 36: smallest descriptor
      return "the grid count " + std::to_string(grids) + " does not fit the file";
    for (int32_t i = 0; i < grids; ++i) check_grid(r, data, h, i);
  } catch (const Bad& b) {
    return b.what;
  }
  return "";
}

}  // namespace femto
