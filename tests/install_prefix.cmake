# Installs this build into PREFIX, emptied first (a file no longer installed must not linger there): the fixture
# tethash_install of the tests that build consumers against the installed package (tests/CMakeLists.txt).
# Arguments: BUILD_DIR (this build), PREFIX.
foreach(var BUILD_DIR PREFIX)
  if(NOT DEFINED ${var} OR "${${var}}" STREQUAL "")
    message(FATAL_ERROR "install_prefix.cmake: ${var} is not set")
  endif()
endforeach()
file(REMOVE_RECURSE ${PREFIX})
execute_process(COMMAND ${CMAKE_COMMAND} --install ${BUILD_DIR} --prefix ${PREFIX}
  RESULT_VARIABLE status OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT status EQUAL 0)
  message(FATAL_ERROR "install into ${PREFIX} failed (${status}):\n${out}\n${err}")
endif()
message(STATUS "installed into ${PREFIX}")
