#!/usr/bin/env bash
# Fails when a tracked source or text file holds a control character other than tab, newline and
# carriage return: the trace of a backslash lost in a formula (\f became a form feed, \a a bell).
# Tabs are refused in C++, CMake and Python sources too (the code is indented with spaces).
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
cd "$root"
if git rev-parse --is-inside-work-tree >/dev/null 2>&1; then
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
if [ "$status" -eq 0 ]; then
  echo "check-sources: ${#files[@]} files, no control characters"
fi
exit "$status"
