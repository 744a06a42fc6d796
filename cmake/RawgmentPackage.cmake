# Installs the headers, the library and a CMake package so that a downstream project can do
#   find_package(Rawgment REQUIRED)
#   target_link_libraries(app PRIVATE Rawgment::rawgment)
# and a pkg-config file (`pkg-config --cflags --libs rawgment`) for builds without CMake.
include(CMakePackageConfigHelpers)

set(RAWGMENT_CMAKE_DIR "${CMAKE_INSTALL_LIBDIR}/cmake/Rawgment")

install(TARGETS rawgment EXPORT RawgmentTargets
  LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR}
  ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR}
  RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR}
  INCLUDES DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}/opencv4)
install(DIRECTORY "${CMAKE_SOURCE_DIR}/modules/rawgment/include/"
  DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}/opencv4)
install(EXPORT RawgmentTargets NAMESPACE Rawgment:: DESTINATION ${RAWGMENT_CMAKE_DIR})

configure_package_config_file("${CMAKE_CURRENT_LIST_DIR}/RawgmentConfig.cmake.in"
  "${CMAKE_BINARY_DIR}/RawgmentConfig.cmake" INSTALL_DESTINATION ${RAWGMENT_CMAKE_DIR})
write_basic_package_version_file("${CMAKE_BINARY_DIR}/RawgmentConfigVersion.cmake"
  VERSION ${PROJECT_VERSION} COMPATIBILITY SameMinorVersion)
install(FILES "${CMAKE_BINARY_DIR}/RawgmentConfig.cmake" "${CMAKE_BINARY_DIR}/RawgmentConfigVersion.cmake"
  DESTINATION ${RAWGMENT_CMAKE_DIR})

# The prefix is found from the file's own place, so that `cmake --install --prefix` anywhere gives a
# true file.
file(RELATIVE_PATH RAWGMENT_PC_TO_PREFIX "/prefix/${CMAKE_INSTALL_LIBDIR}/pkgconfig" "/prefix")
configure_file("${CMAKE_CURRENT_LIST_DIR}/rawgment.pc.in" "${CMAKE_BINARY_DIR}/rawgment.pc" @ONLY)
install(FILES "${CMAKE_BINARY_DIR}/rawgment.pc" DESTINATION ${CMAKE_INSTALL_LIBDIR}/pkgconfig)
