#!/usr/bin/env bash
# Configures and builds one flavour of the project.
#   scripts/build.sh release   -> build/release (Release, tests, benchmarks, apps, samples, Python module)
#   scripts/build.sh asan      -> build/asan    (RelWithDebInfo + AddressSanitizer + UBSan, no benchmarks,
#                                                no Python module: an instrumented extension needs the
#                                                sanitizer runtime preloaded into the interpreter)
#   scripts/build.sh portable  -> build/portable (Release on the portable path: no vector extensions, no
#                                                multi-versioned kernels; see scripts/test-portable.sh)
#   scripts/build.sh release rawgment_demo   -> only the named targets (and what they need) of that flavour
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
flavour=${1:-release}
shift $(( $# > 0 ? 1 : 0 ))
targets=()
for target in "$@"; do targets+=(--target "$target"); done
jobs=${RAWGMENT_JOBS:-$(nproc)}

generator=()
command -v ninja >/dev/null 2>&1 && generator=(-G Ninja)

case "$flavour" in
  release) args=(-DCMAKE_BUILD_TYPE=Release -DRAWGMENT_BUILD_PYTHON=ON) ;;
  asan) args=(-DCMAKE_BUILD_TYPE=RelWithDebInfo -DRAWGMENT_SANITIZE=ON -DRAWGMENT_BUILD_PERF=OFF) ;;
  portable) args=(-DCMAKE_BUILD_TYPE=Release -DRAWGMENT_PORTABLE=ON -DRAWGMENT_BUILD_PYTHON=ON) ;;
  *) echo "build.sh: unknown flavour '$flavour' (expected release, asan or portable)" >&2; exit 2 ;;
esac

build="$root/build/$flavour"
# A configure that failed (a package missing) leaves a cache but no build files: configure again then.
if [ ! -f "$build/CMakeCache.txt" ] || { [ ! -f "$build/build.ninja" ] && [ ! -f "$build/Makefile" ]; }; then
  rm -rf "$build"
  cmake -S "$root" -B "$build" "${generator[@]}" "${args[@]}"
fi
cmake --build "$build" --parallel "$jobs" "${targets[@]}"
