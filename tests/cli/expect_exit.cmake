# Runs COMMAND (a ;-list) and checks its exit code equals EXPECT_CODE and, if given, that its
# combined output contains EXPECT_TEXT.
execute_process(COMMAND ${COMMAND} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT rc STREQUAL "${EXPECT_CODE}")
    message(FATAL_ERROR "exit code ${rc}, expected ${EXPECT_CODE}\nstdout: ${out}\nstderr: ${err}")
endif()
if(DEFINED EXPECT_TEXT AND NOT "${out}${err}" MATCHES "${EXPECT_TEXT}")
    message(FATAL_ERROR "output lacks '${EXPECT_TEXT}'\nstdout: ${out}\nstderr: ${err}")
endif()
message(STATUS "ok: exit ${rc}")
