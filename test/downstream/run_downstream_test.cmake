# Installs the build tree into a fresh prefix, then configures, builds and runs the downstream project
# against that prefix only.
file(REMOVE_RECURSE "${WORK_DIR}")
set(prefix "${WORK_DIR}/prefix")

function(run step)
  execute_process(COMMAND ${ARGN} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  message(STATUS "${step}:\n${out}${err}")
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "downstream test: ${step} failed (exit ${rc})")
  endif()
endfunction()

run("install" ${CMAKE_COMMAND} --install "${RAWGMENT_BUILD_DIR}" --prefix "${prefix}")
# An installed app starts from the prefix alone (its RPATH finds the installed library).
run("installed app" env -u LD_LIBRARY_PATH "${prefix}/bin/rawgment_simulate" --help)
run("configure" ${CMAKE_COMMAND} -S "${DOWNSTREAM_SOURCE_DIR}" -B "${WORK_DIR}/build"
    -DCMAKE_PREFIX_PATH=${prefix} -DCMAKE_BUILD_TYPE=Release)
run("build" ${CMAKE_COMMAND} --build "${WORK_DIR}/build")
run("run" "${WORK_DIR}/build/downstream")
