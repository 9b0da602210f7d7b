# Runs `grainlink run CONFIG` and requires it to fail with every regular expression in EXPECT
# (a ;-list) found in its output. ctest's TIMEOUT bounds how long the whole stop may take.
execute_process(COMMAND ${GRAINLINK} run ${CONFIG} --out ${OUT} --progress-interval 0
                RESULT_VARIABLE status OUTPUT_VARIABLE out ERROR_VARIABLE err)
set(all "${out}${err}")
message("${all}")
if(status EQUAL 0)
    message(FATAL_ERROR "expected the run to fail, it succeeded")
endif()
foreach(pattern IN LISTS EXPECT)
    if(NOT all MATCHES "${pattern}")
        message(FATAL_ERROR "output lacks: ${pattern}")
    endif()
endforeach()
