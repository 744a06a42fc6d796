#!/usr/bin/env bash
# Opt-in stage (not part of scripts/test.sh, which keeps within its time budget): builds the project on its
# portable path into build/portable (the kernels on arrays of lanes, src/lanes.hpp, as a compiler without
# GCC's vector extensions builds them, and no multi-versioned kernels), runs its C++ tests, and checks that
# the C++ reference program (python/tests/cxx_reference.cpp: simulator, jitter, blur, scale, scene,
# normals, Shapiro-Wilk, bursts, calibration, dark-frame components, DNG) writes the same bytes as the
# release build's.
#   bash scripts/test-portable.sh
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
jobs=${RAWGMENT_JOBS:-$(nproc)}
bash "$root/scripts/install-deps.sh"
bash "$root/scripts/build.sh" portable rawgment_test rawgment_python_reference
bash "$root/scripts/build.sh" release rawgment_python_reference
"$root/build/portable/bin/rawgment_test"
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
mkdir "$work/portable" "$work/release"
"$root/build/portable/bin/rawgment_python_reference" "$work/portable"
"$root/build/release/bin/rawgment_python_reference" "$work/release"
compared=0
for file in "$work"/release/*; do
  name=$(basename "$file")
  if ! cmp -s "$file" "$work/portable/$name"; then
    echo "test-portable: $name differs between the portable and the release build" >&2
    exit 1
  fi
  compared=$((compared + 1))
done
[ "$compared" -ge 18 ] || { echo "test-portable: only $compared reference files" >&2; exit 1; }
echo "=== test-portable.sh: the portable path passed its tests and wrote the release build's bytes ($compared files)"
