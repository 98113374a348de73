#!/usr/bin/env bash
# femto quick start: installs what is missing (Debian 12), builds Release, then either renders the
# built-in default scene (`demo`) or runs the whole test suite (`test`).
#   scripts/quickstart.sh demo    # build + render the default scene into ./femto-out
#   scripts/quickstart.sh test    # build + run all tests (ctest)
set -euo pipefail

mode="${1:-demo}"
case "$mode" in
  demo|test) ;;
  *) echo "usage: $0 [demo|test]" >&2; exit 2 ;;
esac

root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build="${FEMTO_BUILD_DIR:-$root/build}"
jobs="${FEMTO_JOBS:-$(nproc 2>/dev/null || echo 2)}"

packages=(cmake g++ ninja-build libopenvdb-dev libembree-dev libtbb-dev libopenexr-dev catch2
          libboost-iostreams-dev nlohmann-json3-dev libpng-dev python3-numpy)

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

cmake -S "$root" -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=Release
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
