# FindLibRaw
# ----------
# Finds the thread-safe LibRaw library (libraw_r) through pkg-config.
#
# Defines the imported target LibRaw::LibRaw and the variables LibRaw_FOUND and LibRaw_VERSION.
# The thread-safe flavour is used because raw files are read from parallel workers.

find_package(PkgConfig QUIET)
if(PKG_CONFIG_FOUND)
  pkg_check_modules(PC_LibRaw QUIET libraw_r)
endif()

find_path(LibRaw_INCLUDE_DIR NAMES libraw/libraw.h HINTS ${PC_LibRaw_INCLUDEDIR} ${PC_LibRaw_INCLUDE_DIRS})
find_library(LibRaw_LIBRARY NAMES raw_r HINTS ${PC_LibRaw_LIBDIR} ${PC_LibRaw_LIBRARY_DIRS})
set(LibRaw_VERSION "${PC_LibRaw_VERSION}")

include(FindPackageHandleStandardArgs)
find_package_handle_standard_args(LibRaw
  REQUIRED_VARS LibRaw_LIBRARY LibRaw_INCLUDE_DIR
  VERSION_VAR LibRaw_VERSION)

if(LibRaw_FOUND AND NOT TARGET LibRaw::LibRaw)
  add_library(LibRaw::LibRaw UNKNOWN IMPORTED)
  set_target_properties(LibRaw::LibRaw PROPERTIES
    IMPORTED_LOCATION "${LibRaw_LIBRARY}"
    INTERFACE_INCLUDE_DIRECTORIES "${LibRaw_INCLUDE_DIR}")
  # libraw_r.pc links OpenMP and lcms2 through its own flags; carry the non -l/-L ones over.
  if(PC_LibRaw_LDFLAGS_OTHER)
    set_property(TARGET LibRaw::LibRaw PROPERTY INTERFACE_LINK_OPTIONS ${PC_LibRaw_LDFLAGS_OTHER})
  endif()
endif()
mark_as_advanced(LibRaw_INCLUDE_DIR LibRaw_LIBRARY)
