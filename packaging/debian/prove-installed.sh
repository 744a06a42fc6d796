#!/usr/bin/env bash
# Runs inside the throwaway root of scripts/package-deb.sh, as root: installs the package as a user would,
# uses it from its installed paths only, then purges it. Exits non-zero at the first thing that fails.
#   prove-installed.sh <package.deb> <folder with the downstream project>
set -euo pipefail
deb=$1
downstream=$2
unset PYTHONPATH LD_LIBRARY_PATH CMAKE_PREFIX_PATH PKG_CONFIG_PATH
cd /tmp

echo "--- dpkg -i (checks the Depends against this root's packages)"
dpkg -i "$deb"
dpkg -L rawgment | sort > /tmp/rawgment-files.txt

echo "--- every app on PATH answers --help"
apps=$(grep '^/usr/bin/' /tmp/rawgment-files.txt)
[ -n "$apps" ] || { echo "no app in /usr/bin" >&2; exit 1; }
for app in $apps; do
  name=$(basename "$app")
  [ "$(command -v "$name")" = "$app" ] || { echo "$name is not the one on PATH" >&2; exit 1; }
  "$name" --help > /dev/null
done

echo "--- Python imports the installed packages with no environment"
/usr/bin/python3 - <<'PY'
import numpy as np
import importlib.util
import rawgment
assert rawgment.__file__.startswith("/usr/lib/python3/dist-packages/"), rawgment.__file__
# The studies run from a build tree: the package ships none of them.
assert importlib.util.find_spec("rawgment_ablation") is None
out = rawgment.colorJitter(np.full((8, 8), 100, np.uint16), rawgment.RawFormat(), rawgment.NoiseModel(1, 1, 1),
                           rawgment.ColorJitter.exposureChange(0.5, 1), seed=1)[0]
assert out.shape == (8, 8) and out.dtype == np.uint16
print("python:", rawgment.__file__, rawgment.__version__)
PY

echo "--- a CMake project finds the package with no CMAKE_PREFIX_PATH"
cmake -S "$downstream" -B /tmp/downstream-build -DCMAKE_BUILD_TYPE=Release > /dev/null
cmake --build /tmp/downstream-build > /dev/null
/tmp/downstream-build/downstream

echo "--- pkg-config gives the flags of a build without CMake"
g++ -std=c++17 "$downstream/main.cpp" -o /tmp/downstream-pc $(pkg-config --cflags --libs rawgment)
/tmp/downstream-pc
rm -rf /tmp/downstream-build /tmp/downstream-pc

echo "--- purge leaves none of the package's files"
dpkg --purge rawgment
left=0
while read -r f; do
  if [ -e "$f" ] && [ ! -d "$f" ]; then
    echo "left behind: $f" >&2
    left=1
  fi
done < /tmp/rawgment-files.txt
for d in /usr/lib/python3/dist-packages/rawgment \
         /usr/share/doc/rawgment /usr/include/opencv4/opencv2/rawgment; do
  if [ -e "$d" ]; then
    echo "left behind: $d" >&2
    find "$d" >&2
    left=1
  fi
done
rm -f /tmp/rawgment-files.txt
exit $left
