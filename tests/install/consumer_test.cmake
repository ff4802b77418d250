# SPDX-License-Identifier: GPL-3.0-or-later
# The installed package works outside the tree: `cmake --install` of the build into a scratch prefix, then
# examples/consumer configured with only that prefix, built, run; it must print a fix within 30 m of the truth.
#   cmake -DBUILD_DIR=... -DCONSUMER_SOURCE=... -DWORK_DIR=... [-DLAUNCHER=ccache] -P consumer_test.cmake
function(run_step what)
  execute_process(COMMAND ${ARGN} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "${what} failed (${rc}):\n${out}\n${err}")
  endif()
  set(step_output "${out}" PARENT_SCOPE)
endfunction()

file(REMOVE_RECURSE "${WORK_DIR}")
run_step("cmake --install" "${CMAKE_COMMAND}" --install "${BUILD_DIR}" --prefix "${WORK_DIR}/prefix")
set(launcher_arg "")
if(LAUNCHER)
  set(launcher_arg "-DCMAKE_CXX_COMPILER_LAUNCHER=${LAUNCHER}")
endif()
run_step("configuring the consumer" "${CMAKE_COMMAND}" -S "${CONSUMER_SOURCE}" -B "${WORK_DIR}/build"
  -DCMAKE_BUILD_TYPE=Release "-DCMAKE_PREFIX_PATH=${WORK_DIR}/prefix" ${launcher_arg})
run_step("building the consumer" "${CMAKE_COMMAND}" --build "${WORK_DIR}/build")
run_step("running the consumer" "${WORK_DIR}/build/consumer")
message("${step_output}")
if(NOT step_output MATCHES "fix: .* ([0-9.]+) m from the truth")
  message(FATAL_ERROR "the consumer printed no fix")
endif()
if(CMAKE_MATCH_1 GREATER 30)
  message(FATAL_ERROR "the consumer's fix is ${CMAKE_MATCH_1} m from the truth (more than 30 m)")
endif()
