#!/usr/bin/env bash
# The README's second command: installs what is missing, then builds and runs every test twice,
# once in Release and once with AddressSanitizer + UndefinedBehaviorSanitizer.
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
jobs=${RAWGMENT_JOBS:-$(nproc)}
bash "$root/scripts/install-deps.sh"

# Sanitizer findings must stop the run: UBSan halts (the build also sets -fno-sanitize-recover),
# ASan's leak checker is on.
export ASAN_OPTIONS=${ASAN_OPTIONS:-detect_leaks=1:abort_on_error=0:strict_string_checks=1}
export LSAN_OPTIONS=${LSAN_OPTIONS:-suppressions=$root/test/lsan_suppressions.txt}
export UBSAN_OPTIONS=${UBSAN_OPTIONS:-halt_on_error=1:print_stacktrace=1}

for flavour in release asan; do
  echo "=== test.sh: $flavour build"
  bash "$root/scripts/build.sh" "$flavour"
  echo "=== test.sh: $flavour tests"
  ctest --test-dir "$root/build/$flavour" --output-on-failure --parallel "$jobs" --timeout 900
done
echo "=== test.sh: all tests passed (release and sanitizer builds)"
