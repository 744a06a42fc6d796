#!/usr/bin/env bash
# Installs the Debian 12 packages that cv::rawgment needs to build, test and run its demo; with --packaging
# also what scripts/package-deb.sh needs. Idempotent: packages already present are not reinstalled. Runs as
# root or through sudo.
set -euo pipefail

packages=(
  build-essential   # g++ 12
  cmake             # >= 3.25
  ninja-build       # faster incremental builds than make on 2 cores
  pkg-config        # FindLibRaw.cmake reads libraw.pc
  libopencv-dev     # OpenCV 4.6: core, imgproc, imgcodecs
  libopencv-contrib-dev  # contrib modules: mcc (colour-checker detection)
  libceres-dev      # Ceres 2.1: cross-gain noise fits
  libraw-dev        # LibRaw 0.20: camera RAW input
  libyaml-dev       # libyaml 0.2.5: the file reader's YAML parser (iterative, depth-limited)
  nlohmann-json3-dev  # nlohmann-json 3.11: the file reader's JSON parser (iterative, reads \u escapes)
  libgtest-dev      # GoogleTest
  libbenchmark-dev  # Google Benchmark
  gnuplot-nox       # PNG plots in apps and the demo
  libimage-exiftool-perl  # exiftool: the tests' independent reader of the DNG tags we write
  doxygen           # the API reference (target doc), built without warnings by the tests
  texlive-binaries  # bibtex, which doxygen runs for @cite
  python3-dev       # the Python module (rawgment): headers of Debian's Python 3.11
  pybind11-dev      # its C++ bindings
  python3-pybind11  # pybind11's CMake package as the Python side sees it
  python3-numpy     # arrays in and out
  python3-opencv    # cv2: the Python example of the docs reads a mosaic as cv2 gives it (run by the tests)
  python3-pytest    # the Python tests
  python3-torch     # rawgment.torch: transform and dataset (CPU build)
  python3-dask      # rawgment.batch on a cluster
  python3-distributed  # Dask's scheduler, workers and LocalCluster
)

# scripts/package-deb.sh also writes the apps' manual pages and checks its package with lintian;
# scripts/test-pip.sh builds with pip in a virtual environment (setuptools 66 and wheel as the backend).
if [ "${1:-}" = "--packaging" ]; then
  packages+=(help2man lintian python3-pip python3-venv python3-setuptools python3-wheel)
elif [ $# -gt 0 ]; then
  echo "install-deps: unknown argument '$1' (expected nothing or --packaging)" >&2
  exit 2
fi

missing=()
for p in "${packages[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done

root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
sudo_cmd=()
if [ "$(id -u)" -ne 0 ]; then
  command -v sudo >/dev/null 2>&1 || sudo_cmd=(false)
  [ "${sudo_cmd[*]}" = false ] || sudo_cmd=(sudo)
fi

if [ "${#missing[@]}" -eq 0 ]; then
  echo "install-deps: all ${#packages[@]} Debian packages present"
else
  if [ "${sudo_cmd[*]}" = false ]; then
    echo "install-deps: need root or sudo to install: ${missing[*]}" >&2
    exit 1
  fi
  echo "install-deps: installing ${missing[*]}"
  export DEBIAN_FRONTEND=noninteractive
  "${sudo_cmd[@]}" apt-get update -qq
  "${sudo_cmd[@]}" apt-get install -y -qq --no-install-recommends "${missing[@]}"
fi

# darktable's measured camera noise profiles: one file of the darktable package, not the package.
bash "$root/scripts/fetch-darktable-profiles.sh"
