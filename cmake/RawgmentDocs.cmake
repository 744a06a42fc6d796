# The API reference of the public headers (target `doc`, HTML in <build>/doc/html/index.html) and the
# test that it builds without a single Doxygen warning.
find_package(Doxygen)
if(NOT DOXYGEN_FOUND)
  message(STATUS "Doxygen not found: no `doc` target (apt-get install doxygen)")
  return()
endif()

set(RAWGMENT_DOC_OUTPUT "${CMAKE_BINARY_DIR}/doc")
set(RAWGMENT_DOC_INPUT "${PROJECT_SOURCE_DIR}/modules/rawgment/include")
set(RAWGMENT_DOC_MAINPAGE "")
set(RAWGMENT_DOC_STRIP "${PROJECT_SOURCE_DIR}/modules/rawgment/include")
set(RAWGMENT_DOC_STRIP_INC "${PROJECT_SOURCE_DIR}/modules/rawgment/include")
set(RAWGMENT_DOC_BIB "${PROJECT_SOURCE_DIR}/modules/rawgment/doc/rawgment.bib")
# Formulas are rendered by MathJax: Debian's copy when it is installed (libjs-mathjax, works offline),
# otherwise MathJax's public CDN when the page is opened.
if(EXISTS "/usr/share/javascript/mathjax/MathJax.js")
  set(RAWGMENT_DOC_MATHJAX "file:///usr/share/javascript/mathjax")
else()
  set(RAWGMENT_DOC_MATHJAX "https://cdn.jsdelivr.net/npm/mathjax@2")
endif()
configure_file("${PROJECT_SOURCE_DIR}/modules/rawgment/doc/Doxyfile.in" "${RAWGMENT_DOC_OUTPUT}/Doxyfile" @ONLY)

# @cite runs bibtex, whose search path (kpathsea) does not include the working directory without
# TeX Live's configuration files: BIBINPUTS and BSTINPUTS put it there.
set(RAWGMENT_DOC_COMMAND ${CMAKE_COMMAND} -E env BIBINPUTS=.: BSTINPUTS=.: ${DOXYGEN_EXECUTABLE}
                         "${RAWGMENT_DOC_OUTPUT}/Doxyfile")
add_custom_target(doc COMMAND ${RAWGMENT_DOC_COMMAND} WORKING_DIRECTORY "${RAWGMENT_DOC_OUTPUT}"
                  COMMENT "API reference: ${RAWGMENT_DOC_OUTPUT}/html/index.html" VERBATIM)

if(RAWGMENT_BUILD_TESTS)
  add_test(NAME doxygen_has_no_warnings
    COMMAND ${CMAKE_COMMAND} -DDOC_DIR=${RAWGMENT_DOC_OUTPUT} -DDOXYGEN=${DOXYGEN_EXECUTABLE}
            -P ${PROJECT_SOURCE_DIR}/cmake/CheckDoxygen.cmake)
endif()
