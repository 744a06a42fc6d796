# Every dependency is a Debian 12 package; a missing one stops configuration and names the package.
# scripts/install-deps.sh installs them all.

macro(rawgment_require found what package)
  if(NOT ${found})
    message(FATAL_ERROR "${what} was not found. On Debian 12 install it with: apt-get install ${package} "
                        "(or run scripts/install-deps.sh).")
  endif()
endmacro()

find_package(OpenCV 4.6 QUIET COMPONENTS core imgproc imgcodecs mcc)
rawgment_require(OpenCV_FOUND "OpenCV 4.6 with the contrib module mcc" "libopencv-dev libopencv-contrib-dev")

find_package(Ceres 2.1 QUIET CONFIG)
rawgment_require(Ceres_FOUND "Ceres Solver 2.1" "libceres-dev")

find_package(LibRaw 0.20 QUIET)
rawgment_require(LibRaw_FOUND "LibRaw 0.20" "libraw-dev")

if(RAWGMENT_BUILD_TESTS)
  find_package(GTest QUIET CONFIG)
  rawgment_require(GTest_FOUND "GoogleTest" "libgtest-dev")
endif()

if(RAWGMENT_BUILD_PERF)
  find_package(benchmark QUIET CONFIG)
  rawgment_require(benchmark_FOUND "Google Benchmark" "libbenchmark-dev")
endif()
