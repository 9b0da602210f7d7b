# Runs COMMAND (a ;-list) and requires both its exit status and its output: EXIT `success` wants
# status 0, `failure` a non-zero status the command chose (a crash by a signal is no clean
# failure); every regular expression in EXPECT (a ;-list) must match the output. A line alone
# passes nothing: ctest's PASS_REGULAR_EXPRESSION ignores the exit status, so an error printed
# by a command that then exits 0, or a success line printed before a crash, would pass.
execute_process(COMMAND ${COMMAND} RESULT_VARIABLE status OUTPUT_VARIABLE out ERROR_VARIABLE err)
set(all "${out}${err}")
message("${all}")
if(EXIT STREQUAL "success")
    if(NOT status EQUAL 0)
        message(FATAL_ERROR "expected exit status 0, got ${status}")
    endif()
elseif(EXIT STREQUAL "failure")
    if(NOT status MATCHES "^[0-9]+$" OR status EQUAL 0)
        message(FATAL_ERROR "expected a non-zero exit status, got ${status}")
    endif()
else()
    message(FATAL_ERROR "EXIT must be success or failure, not '${EXIT}'")
endif()
foreach(pattern IN LISTS EXPECT)
    if(NOT all MATCHES "${pattern}")
        message(FATAL_ERROR "output lacks: ${pattern}")
    endif()
endforeach()
