#!/usr/bin/env bash
# Fails when a tracked source or text file holds a control character other than tab, newline and
# carriage return: the trace of a backslash lost in a formula (\f became a form feed, \a a bell).
# Tabs are refused in C++, CMake and Python sources too (the code is indented with spaces).
# Fails too on a copy of Eq. 5 outside its home (see below).
#   scripts/check-sources.sh            every tracked file
#   scripts/check-sources.sh FILE...    these files only, every check on each (the script's own test)
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
explicit=("$@")
cd "$root"
if [ "${#explicit[@]}" -gt 0 ]; then
  files=("${explicit[@]}")
elif git rev-parse --is-inside-work-tree >/dev/null 2>&1; then
  mapfile -t files < <(git ls-files -- '*.cpp' '*.hpp' '*.h' '*.py' '*.md' '*.txt' '*.cmake' '*.in' '*.sh' '*.yml' '*.json')
else
  mapfile -t files < <(find . -path ./build -prune -o -type f \( -name '*.cpp' -o -name '*.hpp' -o -name '*.h' \
    -o -name '*.py' -o -name '*.md' -o -name '*.txt' -o -name '*.cmake' -o -name '*.in' -o -name '*.sh' \) -print)
fi
status=0
for f in "${files[@]}"; do
  [ -f "$f" ] || continue
  if grep -nP '[\x00-\x08\x0b\x0c\x0e-\x1f\x7f]' "$f" >/dev/null; then
    grep -nP '[\x00-\x08\x0b\x0c\x0e-\x1f\x7f]' "$f" | cat -A | sed "s|^|$f:|" | head -5
    status=1
  fi
  case "$f" in
    *.cpp|*.hpp|*.h|*.py|*.cmake|CMakeLists.txt|*/CMakeLists.txt)
      if grep -nP '\t' "$f" >/dev/null; then
        grep -nP '\t' "$f" | cat -A | sed "s|^|$f: tab: |" | head -3
        status=1
      fi ;;
  esac
done

# Eq. 5 has one home: src/noise_terms.hpp (NoiseModel::lineAtGain() and variance() are built on it).
# A per-ISO table or any other change of the model is then made once; a copy of the formula elsewhere
# would bypass it. Caught shapes: g * g * sigmaD2, sigmaD2 + sigmaR2, g ** 2 * sigma_d2, and alpha with
# a read term in one expression. Tests are exempt: they write the formula again on purpose, as an
# independent truth.
eq5='[A-Za-z_][A-Za-z0-9_.]*\s*\*\s*[A-Za-z_][A-Za-z0-9_.]*\s*\*\s*[A-Za-z_.>-]*sigma_?[dD]2\b'
eq5+='|sigma_?[dD]2\s*\+\s*[A-Za-z_.>-]*sigma_?[rR]2|\*\*\s*2\s*\*\s*[A-Za-z_.>-]*sigma_?[dD]2'
eq5+='|alpha\b[^;#]*\+[^;#]*sigma_?[dDrR]2'
copies=0
for f in "${files[@]}"; do
  [ -f "$f" ] || continue
  case "$f" in
    *.cpp|*.hpp|*.h|*.py|*.md) ;;
    *) continue ;;
  esac
  if [ "${#explicit[@]}" -eq 0 ]; then
    case "$f" in
      modules/rawgment/src/noise_terms.hpp|modules/rawgment/test/*|test/*|python/tests/*) continue ;;
    esac
  fi
  if grep -nP "$eq5" "$f" >/dev/null; then
    grep -nP "$eq5" "$f" | sed "s|^|$f: a copy of Eq. 5 (use NoiseModel::lineAtGain or variance): |" | head -5
    copies=1
  fi
done
[ "$copies" -eq 0 ] || status=1

# The layers (docs/architecture.md): Python is built on the module and the pipeline library, never on the
# apps; the RAW reader sits below the augmentation. And each file one idea: no source over 750 lines
# outside the tests (opencv_contrib's xphoto tops out at 826).
if [ "${#explicit[@]}" -eq 0 ]; then
  for f in "${files[@]}"; do
    [ -f "$f" ] || continue
    case "$f" in
      python/*.cpp|python/*.hpp|python/CMakeLists.txt)
        if grep -nE '#include "[./]*apps/|rawgment_apptools|apps/common' "$f" >/dev/null; then
          grep -nE '#include "[./]*apps/|rawgment_apptools|apps/common' "$f" | sed "s|^|$f: Python leans on the apps: |"
          status=1
        fi ;;
      modules/rawgment/src/raw_io*|modules/rawgment/include/opencv2/rawgment/raw_io.hpp)
        if grep -nE '#include .*augment' "$f" >/dev/null; then
          grep -nE '#include .*augment' "$f" | sed "s|^|$f: the RAW reader includes the augmentation: |"
          status=1
        fi ;;
    esac
    case "$f" in
      modules/rawgment/test/*|test/*|python/tests/*) ;;
      *.cpp|*.hpp|*.h|*.py)
        lines=$(wc -l < "$f")
        if [ "$lines" -gt 750 ]; then
          echo "$f: $lines lines; split it along its seams (at most 750 outside the tests)"
          status=1
        fi ;;
    esac
  done
fi
# A noise step validates its model once and prepares its noise once (src/step_noise.hpp): the rows take
# the prepared terms, never a NoiseModel, and the steps' sources make no call that validates a model
# again (only the public entry points name NoiseModel, to wrap it in a ValidatedNoiseModel).
if [ "${#explicit[@]}" -eq 0 ]; then
  steps=(modules/rawgment/src/color_jitter.cpp modules/rawgment/src/color_jitter_poisson.cpp
    modules/rawgment/src/color_jitter_rows.hpp modules/rawgment/src/resample.cpp
    modules/rawgment/src/scale_mosaic.cpp modules/rawgment/src/shift_mosaic.cpp
    modules/rawgment/src/resample_rows.hpp modules/rawgment/src/motion_blur.cpp modules/rawgment/src/scene.cpp
    modules/rawgment/src/augment_steps.cpp modules/rawgment/src/augment_steps.hpp
    modules/rawgment/src/noise_step.cpp modules/rawgment/src/noise_step.hpp modules/rawgment/src/step_noise.cpp)
  again='model\.(validate|lineAtGain|variance|rowVariance|darkShadingAt)\(|checkedNoiseTerms\('
  for f in "${steps[@]}"; do
    if grep -nE "$again" "$f" >/dev/null; then
      grep -nE "$again" "$f" | sed "s|^|$f: validates the model again (use the step's StepNoise): |"
      status=1
    fi
    case "$f" in
      *_rows.hpp|*_poisson.cpp|*/augment_steps.hpp)
        if grep -nE '[^d]NoiseModel&' "$f" >/dev/null; then
          grep -nE '[^d]NoiseModel&' "$f" | sed "s|^|$f: row code takes a NoiseModel (take the StepNoise's terms): |"
          status=1
        fi ;;
    esac
    # The end of a step (its rows' errors, its counts in the report, its time) is the loop's, written once
    # in noise_step.cpp: a step reports to its StepTally.
    case "$f" in
      */noise_step.cpp|*/augment_steps.cpp|*/augment_steps.hpp|*/step_noise.cpp) ;;
      *)
        ends='(recordStep|throwNonFiniteShading)\(|BrighteningPixels \+='
        if grep -nE "$ends" "$f" >/dev/null; then
          grep -nE "$ends" "$f" | sed "s|^|$f: a step ends itself (report to its StepTally; the loop, runNoiseSteps(), ends it): |"
          status=1
        fi ;;
    esac
  done
fi

# Files have one home, the files topic (files.cpp, file_system.cpp, text_checks.cpp; src/file_access.hpp): no
# other source of the library stats, opens, reads by descriptor, lists, removes or renames a file, streams one
# or reads or writes an image by its path. A rule about files (a FIFO never opened, a name resolved one way)
# is then made once.
if [ "${#explicit[@]}" -eq 0 ]; then
  fileCalls='(^|[^A-Za-z0-9_>])::(stat|lstat|fstat|open|pread|read|write|close|unlink|rename)\(|std::(remove|rename)\(|std::filesystem|std::(i|o|)fstream|fopen\(|[^a-z_]im(read|write)\(|(open|read)dir\('
  for f in "${files[@]}"; do
    case "$f" in
      modules/rawgment/src/files.cpp|modules/rawgment/src/file_system.cpp|modules/rawgment/src/text_checks.cpp) ;;
      modules/rawgment/src/*.cpp|modules/rawgment/src/*.hpp)
        if grep -nE "$fileCalls" "$f" >/dev/null; then
          grep -nE "$fileCalls" "$f" | sed "s|^|$f: reaches a file outside the files topic (use src/file_access.hpp): |"
          status=1
        fi ;;
    esac
  done
fi

# Functions along their seams: none in the library over 120 lines. A body opens with a brace alone on its line
# after a signature (clang-format puts a function's brace there and no other) and closes at that indentation.
if [ "${#explicit[@]}" -eq 0 ]; then
  library=()
  for f in "${files[@]}"; do
    case "$f" in modules/rawgment/src/*.cpp|modules/rawgment/src/*.hpp) [ -f "$f" ] && library+=("$f") ;; esac
  done
  long=$(awk -v limit=120 '
    FNR == 1 { open = 0; prev = "" }
    {
      if (!open && $0 ~ /^ *\{$/ && prev ~ /\)/ && prev !~ /^ *(class|struct|enum|namespace|union)[ ]/) {
        open = 1; start = FNR; indent = substr($0, 1, index($0, "{") - 1); sig = prev
      } else if (open && $0 == indent "}") {
        if (FNR - start + 2 > limit) {
          gsub(/^ +/, "", sig)
          printf "%s:%d: a function of %d lines (at most %d; split it along its steps): %s\n", FILENAME, start - 1, FNR - start + 2, limit, substr(sig, 1, 80)
        }
        open = 0
      }
      if ($0 ~ /[^ ]/) prev = $0
    }' "${library[@]}")
  if [ -n "$long" ]; then
    echo "$long"
    status=1
  fi
fi

# Tests are organised like the code: no test file over 800 lines (a topic's tests split along its seams).
# Private functions are never exported: tests reach them by linking rawgment_internal, so no header of src/
# carries an export macro. precomp.hpp holds includes only: a declaration belongs to its topic's header.
if [ "${#explicit[@]}" -eq 0 ]; then
  for f in "${files[@]}"; do
    [ -f "$f" ] || continue
    case "$f" in
      modules/rawgment/test/*.cpp|modules/rawgment/test/*.hpp|test/*.cpp|test/*.hpp|test/fuzz/*.cpp|python/tests/*.py|python/tests_opencv/*.py)
        lines=$(wc -l < "$f")
        if [ "$lines" -gt 800 ]; then
          echo "$f: $lines lines; split the tests along the seams of what they test (at most 800)"
          status=1
        fi ;;
      modules/rawgment/src/*.hpp)
        if grep -nE 'CV_RAWGMENT_EXPORTS|CV_EXPORTS' "$f" >/dev/null; then
          grep -nE 'CV_RAWGMENT_EXPORTS|CV_EXPORTS' "$f" | sed "s|^|$f: a private function exported (tests link rawgment_internal): |"
          status=1
        fi ;;
    esac
  done
  precomp=modules/rawgment/src/precomp.hpp
  if grep -nvE '^(#include |#ifndef |#define |#endif|//|$)' "$precomp" >/dev/null; then
    grep -nvE '^(#include |#ifndef |#define |#endif|//|$)' "$precomp" | sed "s|^|$precomp: declares something (put it in its topic's header): |" | head -5
    status=1
  fi
fi

if [ "$status" -eq 0 ]; then
  echo "check-sources: ${#files[@]} files, no control characters, no copy of Eq. 5, layers kept, no file over 750 lines (tests 800), no library function over 120 lines, file access only in the files topic, noise steps prepared once, no exported private function, precomp.hpp only includes"
fi
exit "$status"
