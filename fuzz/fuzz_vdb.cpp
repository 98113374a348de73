// libFuzzer target: loading a .vdb volume from arbitrary bytes, as `femto info` and `femto
// render` do: the bytes are written to a temporary file, then load_volume runs femto's
// structure check (media/vdb_structure.cpp), OpenVDB's reader and femto's own checks
// (media/volume_checks.cpp); a volume that loads is then built into a GridMedium as the renderer
// does. A file that loads with its density grid is loaded again with the albedo and eta grids
// of the tissue example. Bad input must be an InputError; any other exception, a crash, a hang,
// an allocation above libFuzzer's -malloc_limit_mb or a sanitizer report is a finding.
//
// The dense grids are limited to 64 MiB (as `--max-memory` would), so that the documented
// 16 GiB default cannot exhaust the fuzzing machine.
#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <string>

#include "core/error.h"
#include "core/scene_desc.h"
#include "media/grid_medium.h"
#include "media/volume_data.h"

namespace {

std::string g_path;

[[noreturn]] void finding(const std::string& what) {
  std::fprintf(stderr, "fuzz_vdb: %s\n", what.c_str());
  std::abort();
}

void write_file(const uint8_t* data, size_t size) {
  std::FILE* f = std::fopen(g_path.c_str(), "wb");
  if (!f) finding("cannot write " + g_path);
  if (size && std::fwrite(data, 1, size, f) != size) finding("cannot write " + g_path);
  std::fclose(f);
}

// True when the volume loaded.
bool load(bool all_grids) {
  femto::VdbMediumDesc d;
  d.file = g_path;
  d.max_dense_bytes = 64ull << 20;
  d.max_sparse_bytes = 64ull << 20;
  d.interpolation = femto::VdbMediumDesc::Interpolation::Trilinear;
  if (all_grids) {
    d.albedo_grid = "albedo";
    d.eta_grid = "eta";
    d.eta = 1.37;
  }
  try {
    const femto::VolumeData v = femto::load_volume(d, "fuzz.json", "/media/fuzz");
    const femto::GridMedium medium(v, d);
    (void)medium.max_sigma_t();
    return true;
  } catch (const femto::InputError&) {
    return false;  // expected for bad input
  } catch (const std::exception& e) {
    finding(std::string("bad input escaped as ") + e.what() + ", not InputError");
  }
}

}  // namespace

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  const char* tmp = std::getenv("TMPDIR");
  g_path = std::string(tmp && *tmp ? tmp : "/tmp") + "/femto-fuzz-vdb-" + std::to_string(getpid()) + ".vdb";
  std::atexit([] { std::remove(g_path.c_str()); });
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  write_file(data, size);
  if (load(false)) load(true);
  return 0;
}
