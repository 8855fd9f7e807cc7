# Installs this build of tethash into WORK_DIR/prefix and builds examples/fem_contact against it (as a code that
# embeds tethash would): the fixture of the fem_contact.* tests (tests/CMakeLists.txt).
# Arguments: BUILD_DIR (this build), SOURCE_DIR (examples/fem_contact), WORK_DIR, CXX, LAUNCHER (may be empty).
foreach(var BUILD_DIR SOURCE_DIR WORK_DIR CXX)
  if(NOT DEFINED ${var} OR "${${var}}" STREQUAL "")
    message(FATAL_ERROR "fem_contact_build.cmake: ${var} is not set")
  endif()
endforeach()
function(run what)
  execute_process(COMMAND ${ARGN} RESULT_VARIABLE status OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT status EQUAL 0)
    message(FATAL_ERROR "fem_contact: ${what} failed (${status}):\n${out}\n${err}")
  endif()
endfunction()
run("install" ${CMAKE_COMMAND} --install ${BUILD_DIR} --prefix ${WORK_DIR}/prefix)
set(launcher "")
if(LAUNCHER)
  set(launcher -DCMAKE_CXX_COMPILER_LAUNCHER=${LAUNCHER})
endif()
run("configure" ${CMAKE_COMMAND} -S ${SOURCE_DIR} -B ${WORK_DIR}/build -DCMAKE_BUILD_TYPE=Release
  -DCMAKE_CXX_COMPILER=${CXX} -DCMAKE_PREFIX_PATH=${WORK_DIR}/prefix ${launcher})
run("build" ${CMAKE_COMMAND} --build ${WORK_DIR}/build -j2)
message(STATUS "fem_contact built in ${WORK_DIR}/build")
