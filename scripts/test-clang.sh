#!/usr/bin/env bash
# Opt-in stage (not part of scripts/test.sh, which keeps within its time budget): builds the project with
# Debian's clang 14 instead of GCC 12 into build/clang and runs its C++ tests there. The tests include the
# hashes of augmented outputs and calibrations, so a pass means the same bits as the GCC build.
#   bash scripts/test-clang.sh          (as root or with sudo: installs clang-14 when it is missing)
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
jobs=${RAWGMENT_JOBS:-$(nproc)}
bash "$root/scripts/install-deps.sh"
if ! command -v clang++-14 >/dev/null 2>&1; then
  sudo_cmd=()
  [ "$(id -u)" -eq 0 ] || sudo_cmd=(sudo)
  echo "test-clang: installing clang-14"
  export DEBIAN_FRONTEND=noninteractive
  "${sudo_cmd[@]}" apt-get update -qq
  "${sudo_cmd[@]}" apt-get install -y -qq --no-install-recommends clang-14
fi
build="$root/build/clang"
if [ ! -f "$build/CMakeCache.txt" ]; then
  # No Python module: it is built and tested with the compiler Debian's Python was built with (GCC).
  CC=clang-14 CXX=clang++-14 cmake -S "$root" -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=Release \
    -DRAWGMENT_BUILD_PYTHON=OFF
fi
cmake --build "$build" --parallel "$jobs"
ctest --test-dir "$build" --output-on-failure --parallel "$jobs" --timeout 900
echo "=== test-clang.sh: all tests passed with clang 14"
