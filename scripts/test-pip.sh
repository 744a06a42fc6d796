#!/usr/bin/env bash
# `pip install .` as a Python user does it, offline, proven (an opt-in stage, like build-in-opencv.sh):
#  1. in a virtual environment over Debian's packages (/usr/bin/python3 -m venv --system-site-packages),
#     `pip install --no-index --no-build-isolation .` builds the library and module with CMake (setup.py)
#     and installs `rawgment` (the library inside it), and no study (studies/ run from a build tree);
#  2. the Python tests (python/tests) run against that package; the only skips
#     allowed are the tests that need the build tree, listed in python/tests/allowed_skips_installed.txt;
#  3. `pip wheel` makes a wheel, which installs and runs in a second virtual environment;
#  4. `pip uninstall` removes every file it installed.
# Nothing is downloaded: pip is told --no-index, and the build uses Debian's setuptools and CMake.
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
bash "$root/scripts/install-deps.sh" --packaging
python=/usr/bin/python3
scratch=$(mktemp -d "${TMPDIR:-/tmp}/rawgment-pip.XXXXXX")
trap 'rm -rf "$scratch"' EXIT
unset PYTHONPATH
export PIP_NO_INDEX=1 PIP_DISABLE_PIP_VERSION_CHECK=1 OMP_NUM_THREADS=1

echo "=== test-pip.sh: pip install . in a virtual environment"
"$python" -m venv --system-site-packages "$scratch/venv"
venv_python="$scratch/venv/bin/python"
# A machine without the build tools gets their names and Debian packages, not a trace from deep in a build.
if (cd "$root" && env PATH="$scratch/no-tools" "$venv_python" -m pip install --no-build-isolation . \
      > "$scratch/no-tools.log" 2>&1); then
  echo "test-pip: pip install succeeded without cmake and a compiler on PATH" >&2
  exit 1
fi
grep -q "rawgment needs to build: cmake, c++, doxygen" "$scratch/no-tools.log" ||
  { cat "$scratch/no-tools.log"; echo "test-pip: no clear error without the build tools" >&2; exit 1; }
(cd "$root" && "$venv_python" -m pip install --no-build-isolation . > "$scratch/install.log" 2>&1) ||
  { tail -50 "$scratch/install.log"; exit 1; }
site=$("$venv_python" -c "import sysconfig; print(sysconfig.get_paths()['purelib'])")
compgen -G "$site/rawgment/libopencv_rawgment.so.*" > /dev/null ||
  { echo "test-pip: the library is not inside the package" >&2; exit 1; }
if [ -e "$site/rawgment_ablation" ] || compgen -G "$scratch/venv/bin/rawgment-*" > /dev/null; then
  echo "test-pip: a study was installed (studies/ run from a build tree)" >&2
  exit 1
fi

echo "=== test-pip.sh: the Python tests against the installed package"
# From a folder outside the source tree, so that nothing there can be imported in the package's place.
mkdir "$scratch/run"
(cd "$scratch/run" && RAWGMENT_TEST_INSTALLED_PACKAGE="$site/rawgment" RAWGMENT_SOURCE_DIR="$root" \
  RAWGMENT_SHARED_DATA_DIR="$root/../shared/data" "$venv_python" -m pytest -q -p no:cacheprovider \
  --junitxml="$scratch/tests.xml" "$root/python/tests")
"$python" - "$scratch/tests.xml" "$root/python/tests/allowed_skips_installed.txt" <<'PY'
import sys
import xml.etree.ElementTree as ET

allowed = {line.strip() for line in open(sys.argv[2], encoding="utf-8") if line.strip() and not line.startswith("#")}
skipped = set()
for case in ET.parse(sys.argv[1]).iter("testcase"):
    if case.find("skipped") is not None:
        skipped.add("%s::%s" % (case.get("classname"), case.get("name")))
# A line is a test's id, or `id[*]` for every case of a parametrised test.
def allowed_to_skip(test):
    return any(test == line or (line.endswith("[*]") and test.startswith(line[:-2])) for line in allowed)
unexpected = sorted(t for t in skipped if not allowed_to_skip(t))
if unexpected:
    sys.exit("test-pip: skipped but not allowed to skip against an installed package:\n  " + "\n  ".join(unexpected))
print("test-pip: %d skips, all of tests that need the build tree" % len(skipped))
PY

echo "=== test-pip.sh: pip wheel, installed in a second virtual environment"
(cd "$root" && "$venv_python" -m pip wheel --no-build-isolation --no-deps -w "$scratch/wheels" . \
  > "$scratch/wheel.log" 2>&1) || { tail -50 "$scratch/wheel.log"; exit 1; }
"$python" -m venv --system-site-packages "$scratch/venv2"
"$scratch/venv2/bin/python" -m pip install "$scratch"/wheels/rawgment-*.whl > /dev/null
(cd "$scratch/run" && "$scratch/venv2/bin/python" - "$scratch/venv2" <<'PY'
import os
import sys

import numpy as np
import rawgment

assert os.path.realpath(rawgment.__file__).startswith(os.path.realpath(sys.argv[1]) + os.sep), rawgment.__file__
out = rawgment.colorJitter(np.full((64, 64), 300, np.uint16), rawgment.RawFormat(), rawgment.NoiseModel(0.5, 2, 1),
                           rawgment.ColorJitter.exposureChange(0.5, 1), seed=7)[0]
assert out.shape == (64, 64) and 145 < out.mean() < 155, out.mean()  # half the light: 150 DN (standard error 0.1 DN)
print("test-pip: the wheel works from", os.path.dirname(rawgment.__file__))
PY
)

echo "=== test-pip.sh: pip uninstall"
"$venv_python" -m pip uninstall -y rawgment > /dev/null
left=$(cd "$scratch/venv" && find . \( -path "*rawgment*" \) ! -path "./lib/python3*/site-packages/__pycache__*" | sort)
if [ -n "$left" ]; then
  echo "test-pip: pip uninstall left:" >&2
  echo "$left" >&2
  exit 1
fi
echo "=== test-pip.sh: installed offline, tested, wheeled and uninstalled"
