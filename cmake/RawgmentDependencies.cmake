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

# The file reader's parsers (src/files.cpp): libyaml for YAML and nlohmann-json for JSON, both iterative,
# so that a deeply nested file is an error, not a stack overflow in OpenCV's recursive readers.
find_package(PkgConfig QUIET)
if(PKG_CONFIG_FOUND)
  pkg_check_modules(yaml QUIET IMPORTED_TARGET yaml-0.1>=0.2.5)
endif()
rawgment_require(yaml_FOUND "libyaml 0.2.5" "libyaml-dev")
find_package(nlohmann_json 3.11 QUIET CONFIG)
rawgment_require(nlohmann_json_FOUND "nlohmann-json 3.11" "nlohmann-json3-dev")

if(RAWGMENT_BUILD_TESTS)
  find_package(GTest QUIET CONFIG)
  rawgment_require(GTest_FOUND "GoogleTest" "libgtest-dev")
endif()

if(RAWGMENT_BUILD_PERF)
  find_package(benchmark QUIET CONFIG)
  rawgment_require(benchmark_FOUND "Google Benchmark" "libbenchmark-dev")
endif()

# The Python module needs Debian's interpreter (its numpy, torch and dask are Debian packages), its
# headers, pybind11, NumPy and Doxygen (its docstrings are the C++ documentation); rawgment.batch runs the
# pipeline layer's jobs (pipeline/), not the apps. A sanitizer build has no Python module: an instrumented extension needs the
# sanitizer runtime preloaded into the interpreter.
set(RAWGMENT_WITH_PYTHON OFF)
if(NOT RAWGMENT_BUILD_PYTHON STREQUAL "OFF" AND NOT RAWGMENT_SANITIZE)
  if(NOT DEFINED Python3_EXECUTABLE AND EXISTS /usr/bin/python3)
    set(Python3_EXECUTABLE /usr/bin/python3)
  endif()
  find_package(Python3 QUIET COMPONENTS Interpreter Development.Module NumPy)
  set(PYBIND11_FINDPYTHON ON)
  find_package(pybind11 2.10 QUIET CONFIG)
  find_package(Doxygen QUIET)
  if(Python3_FOUND AND Python3_NumPy_FOUND AND pybind11_FOUND AND DOXYGEN_FOUND)
    set(RAWGMENT_WITH_PYTHON ON)
  elseif(RAWGMENT_BUILD_PYTHON STREQUAL "ON")
    rawgment_require(FALSE "Python 3 with its headers, NumPy, pybind11 and Doxygen (for the Python module)"
                     "python3-dev python3-numpy pybind11-dev python3-pybind11 doxygen")
  else()
    message(STATUS "Python module not built: Python 3 headers, NumPy, pybind11 or Doxygen missing")
  endif()
endif()
