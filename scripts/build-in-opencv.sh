#!/usr/bin/env bash
# Opt-in stage, not part of scripts/test.sh: from a fresh clone it took 11 minutes on host H3 (2 cores),
# which with the README's 14-minute test command would pass that command's 20-minute budget.
# Builds OpenCV 4.6 from Debian's source with rawgment as an extra module (core, imgproc, imgcodecs,
# videoio, highgui, ts, python3 and rawgment) into build/opencv/prefix, then
#   0. builds OpenCV's API reference and checks that it has the module's group;
#   1. runs opencv_test_rawgment, the module's unit tests on OpenCV's test framework;
#   2. runs opencv_perf_rawgment once per case (OpenCV's sanity mode: it runs, it is not a measurement);
#   3. imports that prefix's cv2 and checks that cv2.rawgment gives the C++ library's bits
#      (python/tests_opencv/test_cv2_rawgment.py against python/tests/cxx_reference.cpp).
#   bash scripts/build-in-opencv.sh      (as root or with sudo: adds a deb-src entry and packages)
# Environment: RAWGMENT_JOBS (default: all cores), RAWGMENT_CACHE_DIR (where the source is kept,
# default ~/.cache/rawgment).
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
jobs=${RAWGMENT_JOBS:-$(nproc)}
cache=${RAWGMENT_CACHE_DIR:-${XDG_CACHE_HOME:-$HOME/.cache}/rawgment}
build="$root/build/opencv"
prefix="$build/prefix"
bash "$root/scripts/install-deps.sh"

sudo_cmd=()
[ "$(id -u)" -eq 0 ] || sudo_cmd=(sudo)
export DEBIAN_FRONTEND=noninteractive

# What OpenCV's own build needs beyond the project's packages: the image libraries' headers (Debian's
# source has no bundled copies), xz for the tarballs.
packages=(zlib1g-dev libjpeg-dev libpng-dev libtiff-dev xz-utils)
missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ "${#missing[@]}" -gt 0 ]; then
  echo "build-in-opencv: installing ${missing[*]}"
  "${sudo_cmd[@]}" apt-get update -qq
  "${sudo_cmd[@]}" apt-get install -y -qq --no-install-recommends "${missing[@]}"
fi

# Debian's OpenCV source, kept in the cache.
source_dir="$cache/opencv-src/opencv-4.6.0"
if [ ! -f "$source_dir/CMakeLists.txt" ]; then
  mkdir -p "$cache/opencv-src"
  # apt-get source needs a deb-src entry for bookworm's main: when the first try finds none, one is
  # made from the machine's own deb entry and the download tried again.
  if ! (cd "$cache/opencv-src" && apt-get source --download-only opencv); then
    uri=$(awk '/^URIs:/ {print $2; exit}' /etc/apt/sources.list.d/debian.sources 2>/dev/null || true)
    uri=${uri:-http://deb.debian.org/debian}
    echo "build-in-opencv: adding a deb-src entry for $uri bookworm main"
    printf 'Types: deb-src\nURIs: %s\nSuites: bookworm\nComponents: main\nSigned-By: %s\n' "$uri" \
      /usr/share/keyrings/debian-archive-keyring.gpg |
      "${sudo_cmd[@]}" tee /etc/apt/sources.list.d/rawgment-debian-src.sources >/dev/null
    "${sudo_cmd[@]}" apt-get update -qq
    (cd "$cache/opencv-src" && apt-get source --download-only opencv)
  fi
  tarball=$(ls "$cache"/opencv-src/opencv_4.6.0*.orig.tar.xz 2>/dev/null | grep -v contrib | head -n 1)
  if [ -z "$tarball" ]; then
    echo "build-in-opencv: Debian's source of OpenCV 4.6.0 was not downloaded" >&2
    exit 1
  fi
  rm -rf "$source_dir.partial"
  mkdir -p "$source_dir.partial"
  tar -xf "$tarball" -C "$source_dir.partial" --strip-components=1
  mv "$source_dir.partial" "$source_dir"
fi

# A minimal OpenCV. Debian's source lacks the bundled third-party code, hence the features turned off
# (OpenCL, for one: its install step needs a licence file that the source lacks).
# The module's tests only: OPENCV_BUILD_(PERF_)TEST_MODULES_LIST keeps OpenCV's own tests out.
mkdir -p "$build"
cmake -S "$source_dir" -B "$build/build" -G Ninja -DCMAKE_BUILD_TYPE=Release \
  -DCMAKE_INSTALL_PREFIX="$prefix" \
  -DOPENCV_EXTRA_MODULES_PATH="$root/modules" \
  -DBUILD_LIST=core,imgproc,imgcodecs,videoio,highgui,ts,python3,rawgment \
  -DBUILD_TESTS=ON -DBUILD_PERF_TESTS=ON \
  -DOPENCV_BUILD_TEST_MODULES_LIST=rawgment -DOPENCV_BUILD_PERF_TEST_MODULES_LIST=rawgment \
  -DENABLE_PRECOMPILED_HEADERS=OFF -DBUILD_EXAMPLES=OFF -DBUILD_opencv_apps=OFF -DBUILD_DOCS=ON \
  -DBUILD_JAVA=OFF -DBUILD_opencv_java=OFF -DBUILD_opencv_js=OFF -DBUILD_opencv_gapi=OFF \
  -DWITH_IPP=OFF -DWITH_ITT=OFF -DWITH_PROTOBUF=OFF -DWITH_QUIRC=OFF -DWITH_ADE=OFF -DWITH_OPENCL=OFF \
  -DWITH_OPENEXR=OFF -DWITH_JASPER=OFF -DWITH_WEBP=OFF -DWITH_OPENJPEG=OFF -DWITH_FFMPEG=OFF \
  -DWITH_GSTREAMER=OFF -DWITH_V4L=OFF -DWITH_GTK=OFF -DWITH_QT=OFF -DWITH_VTK=OFF -DWITH_1394=OFF \
  -DPYTHON3_EXECUTABLE=/usr/bin/python3 >"$build/configure.log" ||
  { tail -n 40 "$build/configure.log" >&2; exit 1; }
grep -q "To be built:.*rawgment" "$build/configure.log" || {
  grep -i "rawgment" "$build/configure.log" >&2
  echo "build-in-opencv: OpenCV's configuration does not build rawgment" >&2
  exit 1
}
echo "=== build-in-opencv.sh: building OpenCV with rawgment ($jobs jobs)"
cmake --build "$build/build" --parallel "$jobs"
cmake --install "$build/build" >"$build/install.log"
# OpenCV's API reference, which has a group for each module it builds: rawgment's must be there.
cmake --build "$build/build" --target doxygen >"$build/doxygen.log" 2>&1 ||
  { tail -n 20 "$build/doxygen.log" >&2; exit 1; }
if ! find "$build/build/doc/doxygen/html" -name 'group__rawgment.html' | grep -q .; then
  echo "build-in-opencv: OpenCV's API reference has no rawgment group" >&2
  exit 1
fi

echo "=== build-in-opencv.sh: opencv_test_rawgment"
"$build/build/bin/opencv_test_rawgment"
echo "=== build-in-opencv.sh: opencv_perf_rawgment (sanity mode: each case once)"
"$build/build/bin/opencv_perf_rawgment" --perf_min_samples=1 --perf_force_samples=1 --perf_verify_sanity

echo "=== build-in-opencv.sh: cv2.rawgment against the C++ library"
bash "$root/scripts/build.sh" release rawgment_python_reference
site=$(ls -d "$prefix"/lib/python3*/*-packages 2>/dev/null | head -n 1)
if [ -z "$site" ] || [ ! -d "$site/cv2" ]; then
  echo "build-in-opencv: no cv2 package under $prefix/lib" >&2
  exit 1
fi
PYTHONPATH="$site" RAWGMENT_OPENCV_PREFIX="$prefix" \
  RAWGMENT_PYTHON_REFERENCE="$root/build/release/bin/rawgment_python_reference" \
  RAWGMENT_SHARED_DATA_DIR="$root/../shared/data" \
  /usr/bin/python3 -m pytest -q -p no:cacheprovider "$root/python/tests_opencv"
echo "=== build-in-opencv.sh: OpenCV 4.6 with rawgment built in $prefix, all its tests passed"
