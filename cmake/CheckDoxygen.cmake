# Builds the API reference and fails when Doxygen warns (an undocumented public symbol, a broken
# command, a citation without its reference), printing the warnings.
file(REMOVE_RECURSE "${DOC_DIR}/html")
file(REMOVE "${DOC_DIR}/doxygen_warnings.log")
execute_process(COMMAND ${CMAKE_COMMAND} -E env BIBINPUTS=.: BSTINPUTS=.: ${DOXYGEN} "${DOC_DIR}/Doxyfile"
                WORKING_DIRECTORY "${DOC_DIR}" RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "doxygen failed (exit ${rc}):\n${out}${err}")
endif()
file(READ "${DOC_DIR}/doxygen_warnings.log" warnings)
if(NOT warnings STREQUAL "")
  message(FATAL_ERROR "doxygen warnings:\n${warnings}")
endif()
if(NOT EXISTS "${DOC_DIR}/html/index.html")
  message(FATAL_ERROR "doxygen wrote no ${DOC_DIR}/html/index.html")
endif()
message(STATUS "API reference without warnings: ${DOC_DIR}/html/index.html")
