// Regression tests for hostile .vdb files (docs/RELIABILITY.md): far-apart voxels, corrupt bytes
// and truncation are InputErrors naming the file; none may crash or allocate the box.
#include <catch2/catch.hpp>

#include <climits>
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "core/error.h"
#include "media/vdb_structure.h"
#include "media/volume_data.h"
#include "run_femto.h"
#include "temp_dir.h"

#ifndef FEMTO_SOURCE_DIR
#error "FEMTO_SOURCE_DIR must be defined by the build"
#endif

using namespace femto;
using Catch::Matchers::Contains;
namespace fs = std::filesystem;

namespace {

// A density grid of single voxels at the given VDB index x coordinates.
std::string sparse_volume(const fs::path& dir, const std::vector<int>& xs, double voxel_mm = 1) {
  VdbGridSpec s;
  s.name = "density";
  s.voxel_mm = Vec3(voxel_mm);
  for (int x : xs) s.voxels.push_back({{x, 0, 0}, 1.0f});
  const std::string path = (dir / "sparse.vdb").string();
  write_vdb(path, {s});
  return path;
}

// The InputError message of loading `file`, or "" when it loads.
std::string bad_volume_error(const std::string& file, uint64_t max_bytes = 16ull << 30) {
  VdbMediumDesc d;
  d.file = file;
  d.max_dense_bytes = max_bytes;
  d.storage = VdbMediumDesc::Storage::Dense;  // the dense limits (auto would keep these sparse)
  try {
    load_volume(d, "scene.json", "/media/m");
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

std::string example_volume() { return std::string(FEMTO_SOURCE_DIR) + "/data/volumes/cloud.vdb"; }

// cloud.vdb with bit `mask` of byte `at` flipped (or cut to `at` bytes when mask is 0).
std::string damaged(const fs::path& dir, size_t at, unsigned mask) {
  std::string bytes = test::read_file(example_volume());
  if (mask == 0)
    bytes.resize(at);
  else
    bytes[at] = static_cast<char>(bytes[at] ^ static_cast<char>(mask));
  const std::string path = (dir / "damaged.vdb").string();
  test::write_file(path, bytes);
  return path;
}

// cloud.vdb with `bytes` written over it at `at`.
std::string patched(const fs::path& dir, size_t at, const std::string& bytes) {
  std::string data = test::read_file(example_volume());
  data.replace(at, bytes.size(), bytes);
  const std::string path = (dir / "patched.vdb").string();
  test::write_file(path, data);
  return path;
}

}  // namespace

// Was (found by fuzz/fuzz_vdb.cpp): a metadata type name changed from "vec3i" to "int32" kept
// its stated size of 12 bytes; OpenVDB reads 4 and takes the next string's length from the
// values left over, allocating and filling 1.7 GB twice for a 10 KB file. The same through the
// "__delayedload" metadata, which OpenVDB reads by its inner sizes (1.6 GB twice).
// fuzz/regressions/vdb/metadata-type-size.vdb and delayed-load-size.vdb are the fuzzer's inputs.
TEST_CASE("a metadata value whose stated size differs from its type's is refused", "[robust]") {
  test::TempDir tmp("femto_bad_vdb");
  // cloud.vdb: grid metadata 'file_bbox_max' of type vec3i at 0xba, 'file_mem_bytes' (int64) at 0x42b.
  CHECK_THAT(vdb_structure_problem(patched(tmp.dir, 0xba, "int32")),
             Contains("of type int32 claims 12 bytes; the type has 4"));
  CHECK_THAT(vdb_structure_problem(patched(tmp.dir, 0x42b, "int32")),
             Contains("of type int32 claims 8 bytes; the type has 4"));
  CHECK_THAT(bad_volume_error(patched(tmp.dir, 0xba, "int32")),
             Contains("patched.vdb: corrupt or unsupported OpenVDB file: grid 1 metadata entry 2"));
  // OpenVDB reads its "__delayedload" metadata (0x149: size 699, leaf count 180 at 0x15a, then a
  // 35-byte blosc chunk) by the sizes inside it, not by the stated size.
  CHECK_THAT(vdb_structure_problem(patched(tmp.dir, 0x15a, std::string("\xff\xff\xff\x7f", 4))),
             Contains("claims 2147483647 leaf nodes, more than the file holds"));
  CHECK_THAT(vdb_structure_problem(patched(tmp.dir, 0x156, std::string("\x10\x00\x00\x00", 4))),
             Contains("holds") && Contains("bytes but claims 16"));
  CHECK_THAT(vdb_structure_problem(patched(tmp.dir, 0x15e, std::string("\xff\x00\x00\x00", 4))),
             Contains("blosc header for 180 bytes in 35 where 180 bytes in 255 belong") ||
                 Contains("remain"));
  // The transform's map type name (length at 0x482, "UniformScaleTranslateMap") is read into a
  // string of the stated length: bounded like every other string, and inside the grid.
  CHECK_THAT(vdb_structure_problem(patched(tmp.dir, 0x482, std::string("\xff\xff\xff\x7f", 4))),
             Contains("grid 1 transform type claims 2147483647 bytes, above the 1 MiB limit"));
  CHECK_THAT(vdb_structure_problem(patched(tmp.dir, 0x482, std::string("\x00\x00\x0f\x00", 4))),
             Contains("grid 1 transform type claims 983040 bytes") && Contains("remain"));
}

// Was (found by fuzz/fuzz_vdb.cpp): a root tile's active flag of 2 read into a C++ bool inside
// OpenVDB's RootNode::readTopology (undefined behaviour, reported by UBSan); and a stated child
// count of 2^32 - 1 made OpenVDB allocate a 270 KB node per child, reading past the end of the
// file. fuzz/regressions/vdb/root-tile-flag.vdb is the fuzzer's input.
TEST_CASE("the root node's tiles and children must fit the grid's topology", "[robust]") {
  test::TempDir tmp("femto_bad_vdb");
  // cloud.vdb: the density tree starts at 0x52e (buffer count 1, background 0, 0 tiles at
  // 0x536, 1 child at 0x53a, then the child's origin and masks).
  CHECK_THAT(vdb_structure_problem(patched(tmp.dir, 0x53a, std::string("\xff\xff\xff\xff", 4))),
             Contains("grid 1 root claims 0 tiles and 4294967295 children, more than the"));
  CHECK_THAT(vdb_structure_problem(patched(tmp.dir, 0x536, std::string("\xff\xff\xff\x0f", 4))),
             Contains("grid 1 root claims 268435455 tiles and 1 children"));
  // One tile (origin, value, flag at 0x54e) in front of the child.
  std::string tile_flag_2(0x54f - 0x536, '\0');
  tile_flag_2[0] = '\x01';
  tile_flag_2.back() = '\x02';
  CHECK_THAT(vdb_structure_problem(patched(tmp.dir, 0x536, tile_flag_2)),
             Contains("grid 1 root tile 1 has an active flag that is neither 0 nor 1"));
  // Transform types are known ones with their own sizes.
  CHECK_THAT(vdb_structure_problem(patched(tmp.dir, 0x486, "UniformScaleTranslateMaq")),
             Contains("grid 1 has an unknown transform type 'UniformScaleTranslateMaq'"));
}

// Was (found by fuzz/fuzz_vdb.cpp, reported by ASan): a heap buffer overflow inside OpenVDB 10,
// which reads a chunk stored uncompressed (a negative size) into the node's buffer before
// comparing its size with the buffer's. The structure check now walks every node of a float
// tree and checks each chunk against the size its node gives it.
// fuzz/regressions/vdb/chunk-overflow.vdb is the fuzzer's input.
TEST_CASE("value chunks must have the size of their node", "[robust]") {
  test::TempDir tmp("femto_bad_vdb");
  // cloud.vdb (active-mask and blosc compression): the first leaf's buffers start at 0x567c
  // (value mask with 45 voxels on, flags 0), its chunk at 0x56bd: 196 bytes of blosc holding 180.
  const auto int64 = [](int64_t v) { return std::string(reinterpret_cast<const char*>(&v), 8); };
  const auto int32 = [](uint32_t v) { return std::string(reinterpret_cast<const char*>(&v), 4); };
  CHECK_THAT(vdb_structure_problem(patched(tmp.dir, 0x56bd, int64(-4096))),
             Contains("holds 4096 uncompressed bytes where the node has 180"));
  CHECK_THAT(
      bad_volume_error(patched(tmp.dir, 0x56bd, int64(-4096))),
      Contains(
          "patched.vdb: corrupt or unsupported OpenVDB file: grid 1 value chunk at offset 22205"));
  CHECK_THAT(vdb_structure_problem(patched(tmp.dir, 0x56bd, int64(INT64_MIN))),
             Contains("holds 9223372036854775808 uncompressed bytes"));
  CHECK_THAT(vdb_structure_problem(patched(tmp.dir, 0x56bd, int64(int64_t(1) << 40))), Contains("remain"));
  CHECK_THAT(vdb_structure_problem(patched(tmp.dir, 0x56bd + 12, int32(100))),
             Contains("blosc header for 100 bytes in 196 where 180 bytes in 196 belong"));
  // A leaf's value mask in the buffers must repeat the one in the tree.
  CHECK_THAT(vdb_structure_problem(damaged(tmp.dir, 0x567c, 0x01)), Contains("differs from the tree's"));
}

// Was (found by fuzz/fuzz_vdb.cpp): with the grid-offsets flag cleared, OpenVDB reads the file
// as a stream, grid after grid, and the structure check (which locates grids by their offsets)
// did not look past the header: a corrupt metadata size then asked for 2.7 GB.
// fuzz/regressions/vdb/no-grid-offsets.vdb is the fuzzer's input.
TEST_CASE("files without grid offsets are refused", "[robust]") {
  test::TempDir tmp("femto_bad_vdb");
  CHECK_THAT(vdb_structure_problem(damaged(tmp.dir, 0x14, 0x01)),
             Contains("no grid offsets (it was written as an OpenVDB stream)"));
}

// Was: SIGSEGV: the box size x_max - x_min + 1 overflowed int to 0 cells, densify wrote via null.
TEST_CASE("voxels at INT_MIN and INT_MAX are refused by 64-bit box arithmetic", "[robust]") {
  test::TempDir tmp("femto_bad_vdb");
  const std::string msg = bad_volume_error(sparse_volume(tmp.dir, {INT_MIN, INT_MAX}));
  CHECK_THAT(msg, Contains("sparse.vdb") && Contains("4294967296 x 1 x 1") && Contains("2^30 cells"));
  // A single voxel at INT_MAX is a 1-cell box: it loads (the fill loop must not overflow) when
  // its world position is inside the bounds, and is refused cleanly when not.
  CHECK(bad_volume_error(sparse_volume(tmp.dir, {INT_MAX}, 1e-3)) == "");
  CHECK_THAT(bad_volume_error(sparse_volume(tmp.dir, {INT_MAX})), Contains("beyond +-1e9 mm"));
}

// Was: an 8 GB allocation for a 19 KB file (a box just under the old 2^31-cell limit).
TEST_CASE("far-apart voxels are refused before the dense box is allocated", "[robust]") {
  test::TempDir tmp("femto_bad_vdb");
  const std::string file = sparse_volume(tmp.dir, {-1000000000, 1000000000});
  CHECK(fs::file_size(file) < 100000);
  CHECK_THAT(bad_volume_error(file), Contains("2000000001 x 1 x 1") && Contains("2^30 cells"));
  // A box within the cell limit but above the memory --max-memory leaves for volumes.
  const std::string mid = sparse_volume(tmp.dir, {0, 99999999});
  CHECK_THAT(bad_volume_error(mid, 64ull << 20), Contains("left by --max-memory"));
}

// Was: std::bad_alloc from OpenVDB's reader, exit 1 without naming the file. Since the
// structure check walks the tree's chunks, the bad size is found before OpenVDB reads it.
TEST_CASE("a corrupt size inside the grid data is bad input naming the file", "[robust]") {
  test::TempDir tmp("femto_bad_vdb");
  CHECK_THAT(bad_volume_error(damaged(tmp.dir, 3530, 0x04)),
             Contains("/media/m/file: ") && Contains("damaged.vdb") && Contains("corrupt or unsupported OpenVDB file"));
}

// Was: OpenVDB trusting lengths in the header and metadata (gigabyte allocations, reads past
// the end). Our own bounded check names the problem first.
TEST_CASE("corrupt headers, metadata sizes and truncation are caught by the structure check", "[robust]") {
  test::TempDir tmp("femto_bad_vdb");
  CHECK(vdb_structure_problem(example_volume()).empty());
  CHECK_THAT(vdb_structure_problem(damaged(tmp.dir, 1, 0x01)), Contains("magic"));
  CHECK_THAT(vdb_structure_problem(damaged(tmp.dir, 0x9a, 0x40)), Contains("metadata entry"));
  CHECK_THAT(vdb_structure_problem(damaged(tmp.dir, 0x6f, 0x10)), Contains("offsets"));
  CHECK_THAT(vdb_structure_problem(damaged(tmp.dir, 100, 0)), Contains("remain"));
  CHECK_THAT(bad_volume_error(damaged(tmp.dir, 0x9a, 0x40)), Contains("damaged.vdb: corrupt or unsupported"));
}

// Every single-bit flip in the header, descriptors and metadata either loads or is an
// InputError: none may crash the process or escape as another exception.
TEST_CASE("bit flips across the structure of an example volume never crash", "[robust]") {
  test::TempDir tmp("femto_bad_vdb");
  int refused = 0;
  for (size_t at = 0; at < 0x160; ++at) {
    INFO("byte " << at);
    const std::string msg = bad_volume_error(damaged(tmp.dir, at, 0x08));
    if (!msg.empty()) {
      CHECK_THAT(msg, Contains("damaged.vdb"));
      ++refused;
    }
  }
  CHECK(refused > 50);
}

// The same through the command: exit 2 and one line, never a signal.
TEST_CASE("femto info on a corrupt volume exits 2 naming the file", "[robust]") {
  test::TempDir tmp("femto_bad_vdb");
  damaged(tmp.dir, 3530, 0x04);
  test::write_file(tmp.dir / "scene.json", R"({
    "camera": {"position": [0, 0, 400], "look_at": [0, 0, 0], "resolution": [8, 8]},
    "time": {"bin_width": 10, "bins": 10},
    "media": {"cloud": {"type": "vdb", "file": "damaged.vdb", "sigma_t_scale": 0.08}},
    "medium": "cloud",
    "lights": [{"type": "point", "position": [0, 0, 300], "intensity": 10}]})");
  const test::Run r = test::run_femto({"info", "scene.json"}, tmp.dir);
  CHECK(r.code == 2);
  CHECK_THAT(r.err, Contains("damaged.vdb") && Contains("/media/cloud/file"));
}
