# The Debian package: one binary package `rawgment` with the shared library (SONAME
# libopencv_rawgment.so.MAJOR.MINOR), headers, CMake package, pkg-config file, apps, the Python packages
# `rawgment` in Debian's folder, and the docs. scripts/package-deb.sh configures
# with -DRAWGMENT_DEBIAN_PACKAGE=ON -DCMAKE_INSTALL_PREFIX=/usr, builds, runs cpack and checks the result.
#
# One package rather than a runtime/-dev split: the apps and the Python module are the product and need
# the library at its exact version, and a downstream C++ project needs OpenCV's -dev package anyway. lintian
# names that choice in two warnings (the package name does not follow the SONAME, the development symlink
# is in it), not errors.
if(NOT CMAKE_INSTALL_PREFIX STREQUAL "/usr")
  message(FATAL_ERROR "RAWGMENT_DEBIAN_PACKAGE needs -DCMAKE_INSTALL_PREFIX=/usr (it is ${CMAKE_INSTALL_PREFIX})")
endif()

if(NOT RAWGMENT_WITH_PYTHON OR NOT RAWGMENT_BUILD_APPS)
  message(FATAL_ERROR "RAWGMENT_DEBIAN_PACKAGE packages the apps and the Python module: both must be built")
endif()
math(EXPR next_minor "${Python3_VERSION_MINOR} + 1")

set(debian_dir "${CMAKE_SOURCE_DIR}/packaging/debian")
set(doc_dir "${CMAKE_INSTALL_DATAROOTDIR}/doc/rawgment")

# Debian wants changelogs compressed with gzip -9n (no name or time stamp: the same bytes every build).
find_program(GZIP_PROGRAM gzip REQUIRED)
set(staged "${CMAKE_BINARY_DIR}/debian-docs")
file(MAKE_DIRECTORY "${staged}")
foreach(pair "changelog=${debian_dir}/changelog" "CHANGELOG.md=${CMAKE_SOURCE_DIR}/CHANGELOG.md")
  string(REPLACE "=" ";" pair "${pair}")
  list(GET pair 0 name)
  list(GET pair 1 source)
  add_custom_command(OUTPUT "${staged}/${name}.gz"
    COMMAND ${GZIP_PROGRAM} -9n -c "${source}" > "${staged}/${name}.gz"
    DEPENDS "${source}"
    VERBATIM)
  list(APPEND compressed_docs "${staged}/${name}.gz")
endforeach()
add_custom_target(rawgment_debian_docs ALL DEPENDS ${compressed_docs})
install(FILES ${compressed_docs} "${debian_dir}/copyright" "${CMAKE_SOURCE_DIR}/README.md" DESTINATION "${doc_dir}")
install(DIRECTORY "${CMAKE_SOURCE_DIR}/docs/" DESTINATION "${doc_dir}/docs" FILES_MATCHING PATTERN "*.md")

# A manual page per app, made from its --help by help2man; the NAME line is the help's first line after
# "app: ".
find_program(HELP2MAN_PROGRAM help2man REQUIRED)
set(man_dir "${CMAKE_BINARY_DIR}/debian-man")
file(MAKE_DIRECTORY "${man_dir}")
foreach(app IN LISTS RAWGMENT_APPS)
  add_custom_command(OUTPUT "${man_dir}/${app}.1.gz"
    COMMAND sh -c "name=$(\"$1\" --help 2>&1 | head -n 1 | sed 's/^[^:]*: *//; s/[.]$//') && \
                   ${HELP2MAN_PROGRAM} --no-info --no-discard-stderr --version-string=${PROJECT_VERSION} \
                   --name=\"$name\" \"$1\" | ${GZIP_PROGRAM} -9n > \"$2\"" _ "$<TARGET_FILE:${app}>"
            "${man_dir}/${app}.1.gz"
    DEPENDS ${app}
    VERBATIM)
  list(APPEND man_pages "${man_dir}/${app}.1.gz")
endforeach()
add_custom_target(rawgment_man_pages ALL DEPENDS ${man_pages})
install(FILES ${man_pages} DESTINATION "${CMAKE_INSTALL_MANDIR}/man1")

set(CPACK_GENERATOR DEB)
set(CPACK_PACKAGE_NAME rawgment)
set(CPACK_PACKAGE_VERSION "${PROJECT_VERSION}")
set(CPACK_PACKAGING_INSTALL_PREFIX "${CMAKE_INSTALL_PREFIX}")
# A distributor sets their own; the default is the project's placeholder (packaging/debian/changelog and
# copyright name the same).
set(RAWGMENT_DEBIAN_MAINTAINER "The cv-rawgment developers <rawgment@example.org>" CACHE STRING
    "The Maintainer field of the Debian package")
set(CPACK_PACKAGE_CONTACT "${RAWGMENT_DEBIAN_MAINTAINER}")
set(CPACK_DEBIAN_FILE_NAME DEB-DEFAULT)
set(CPACK_DEBIAN_PACKAGE_SECTION science)
set(CPACK_DEBIAN_PACKAGE_PRIORITY optional)
set(CPACK_PACKAGE_DESCRIPTION_SUMMARY "${PROJECT_DESCRIPTION}")
# The summary is the synopsis; CPack puts it first, indents each line of this and writes the empty one as " .".
set(CPACK_DEBIAN_PACKAGE_DESCRIPTION "cv::rawgment makes RAW images of hard scenes (dark, noisy, high dynamic range,
shaken) out of RAW images of easy ones, with the noise a real sensor would
have produced: it calibrates a sensor's noise model from bursts, colour
charts, dark frames or EMVA 1288 data, and augments with the noise already
in the input accounted for.

This package holds the shared library, its headers, CMake package and
pkg-config file, the command-line apps and the Python package rawgment.")
# Depends: what dpkg-shlibdeps finds the binaries need, plus what it cannot see: the Python module is built
# for this Python and imports NumPy. torch and dask are for rawgment.torch and rawgment.batch only.
set(CPACK_DEBIAN_PACKAGE_SHLIBDEPS ON)
set(CPACK_DEBIAN_PACKAGE_DEPENDS
    "python3 (>= ${Python3_VERSION_MAJOR}.${Python3_VERSION_MINOR}), python3 (<< ${Python3_VERSION_MAJOR}.${next_minor}), python3-numpy")
# The apps draw their plots with gnuplot when it is there (a note says so when it is not): recommended, so
# apt installs it by default, and an installed user gets the plots as the README shows them.
set(CPACK_DEBIAN_PACKAGE_RECOMMENDS "gnuplot-nox")
set(CPACK_DEBIAN_PACKAGE_SUGGESTS "python3-torch, python3-dask, python3-distributed")
set(CPACK_DEBIAN_PACKAGE_GENERATE_SHLIBS ON)
set(CPACK_DEBIAN_PACKAGE_GENERATE_SHLIBS_POLICY ">=")
# postinst/prerm byte-compile and clean the Python packages as dh_python3's do; the library's loader cache
# follows through a trigger (CPack's own postinst/postrm would call ldconfig).
set(CPACK_DEBIAN_PACKAGE_CONTROL_EXTRA "${debian_dir}/postinst" "${debian_dir}/prerm" "${debian_dir}/postrm"
    "${debian_dir}/triggers")
set(CPACK_DEBIAN_PACKAGE_CONTROL_STRICT_PERMISSION ON)
set(CPACK_STRIP_FILES ON)
include(CPack)
