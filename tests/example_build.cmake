# Builds an example (a CMake project of its own, examples/NAME) against this build installed in PREFIX (the fixture
# tethash_install), as a code that embeds tethash would: the fixture of each example's tests (tests/CMakeLists.txt).
# Arguments: PREFIX, SOURCE_DIR (examples/NAME), WORK_DIR (the example's build goes to WORK_DIR/build), CXX,
# LAUNCHER (may be empty).
foreach(var PREFIX SOURCE_DIR WORK_DIR CXX)
  if(NOT DEFINED ${var} OR "${${var}}" STREQUAL "")
    message(FATAL_ERROR "example_build.cmake: ${var} is not set")
  endif()
endforeach()
get_filename_component(name ${SOURCE_DIR} NAME)
function(run what)
  execute_process(COMMAND ${ARGN} RESULT_VARIABLE status OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT status EQUAL 0)
    message(FATAL_ERROR "${name}: ${what} failed (${status}):\n${out}\n${err}")
  endif()
endfunction()
set(launcher "")
if(LAUNCHER)
  set(launcher -DCMAKE_CXX_COMPILER_LAUNCHER=${LAUNCHER})
endif()
# A cache left by an earlier layout of the tests keeps the package it found (tethash_DIR): configure afresh.
file(REMOVE ${WORK_DIR}/build/CMakeCache.txt)
run("configure" ${CMAKE_COMMAND} -S ${SOURCE_DIR} -B ${WORK_DIR}/build -DCMAKE_BUILD_TYPE=Release
  -DCMAKE_CXX_COMPILER=${CXX} -DCMAKE_PREFIX_PATH=${PREFIX} ${launcher})
run("build" ${CMAKE_COMMAND} --build ${WORK_DIR}/build -j2)
message(STATUS "${name} built in ${WORK_DIR}/build")
