#!/usr/bin/env bash
# femto quick start: installs what is missing (Debian 12), builds, then renders or tests.
#   scripts/quickstart.sh demo      # Release build + render the default scene into ./femto-out
#   scripts/quickstart.sh test      # Release build + run all tests (ctest)
#   scripts/quickstart.sh sanitize  # clang build with ASan and UBSan (build-asan) + all tests;
#                                   # the same build holds the fuzz targets (scripts/fuzz.sh)
#   scripts/quickstart.sh deps      # only install what is missing (also clang for the two above)
set -euo pipefail

mode="${1:-demo}"
case "$mode" in
  demo|test|sanitize|deps) ;;
  *) echo "usage: $0 [demo|test|sanitize|deps]" >&2; exit 2 ;;
esac

root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
jobs="${FEMTO_JOBS:-$(nproc 2>/dev/null || echo 2)}"

packages=(cmake g++ ninja-build libopenvdb-dev libembree-dev libtbb-dev libopenexr-dev catch2
          libboost-iostreams-dev nlohmann-json3-dev libpng-dev python3-numpy libpugixml-dev
          libopenmpi-dev openmpi-bin pybind11-dev python3-dev python3-pytest python3-matplotlib
          pkg-config libavcodec-dev libavformat-dev libswscale-dev libavutil-dev ffmpeg)
# The sanitizer build and the fuzz targets (scripts/fuzz.sh): clang, its sanitizer and libFuzzer
# runtimes, and llvm-symbolizer for readable reports.
if [ "$mode" = sanitize ] || [ "$mode" = deps ]; then
  packages+=(clang libclang-rt-14-dev llvm-14)
fi

missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ "${#missing[@]}" -gt 0 ]; then
  echo "femto: installing missing packages: ${missing[*]}"
  sudo_cmd=()
  [ "$(id -u)" -ne 0 ] && sudo_cmd=(sudo)
  "${sudo_cmd[@]}" apt-get update -qq
  DEBIAN_FRONTEND=noninteractive "${sudo_cmd[@]}" apt-get install -y -qq --no-install-recommends "${missing[@]}"
fi
[ "$mode" = deps ] && exit 0

if [ "$mode" = sanitize ]; then
  # -O1: the instrumented suite runs a few times slower than Release; -O1 compiles faster than
  # -O2 and keeps reports readable (with line tables only, set by CMakeLists.txt: a report's
  # frames keep their file:line). Assertions stay on (no NDEBUG). FEMTO_FUZZ: the fuzz targets
  # are libFuzzer programs of this same build, so scripts/fuzz.sh compiles nothing more.
  build="${FEMTO_BUILD_DIR:-$root/build-asan}"
  cmake -S "$root" -B "$build" -G Ninja -DCMAKE_CXX_COMPILER=clang++ -DCMAKE_BUILD_TYPE=RelWithDebInfo \
        -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O1" -DFEMTO_SANITIZE=ON -DFEMTO_FUZZ=ON -DFEMTO_UNITY=ON \
        -DFEMTO_BUILD_BENCH=OFF
  cmake --build "$build" -j "$jobs"
  cd "$build"
  ctest --output-on-failure -j "$jobs"  # ASAN_OPTIONS and UBSAN_OPTIONS: set per test by CMake
  exit 0
fi

build="${FEMTO_BUILD_DIR:-$root/build}"
cmake -S "$root" -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=Release -DFEMTO_UNITY=ON
cmake --build "$build" -j "$jobs"

if [ "$mode" = demo ]; then
  out="${FEMTO_OUT:-$PWD/femto-out}"
  "$build/femto" render --out "$out"
  echo
  echo "Done. Open $out/steady.png (time-integrated image) and $out/frames.png (frames over time);"
  echo "data: $out/transient.npy (H, W, T, 3 float32), $out/frames/*.exr, $out/render.json."
else
  cd "$build"
  ctest --output-on-failure -j "$jobs"
fi
