# Runs CONFIG through `grainlink run` into WORK/out, then the check script CHECK with its
# arguments ARGS (a ;-list in which @OUT@ stands for the output directory). The checks and
# their tolerances are written in each check script.
file(MAKE_DIRECTORY ${WORK})
execute_process(COMMAND ${GRAINLINK} run ${CONFIG} --out ${WORK}/out --progress-interval 0
                WORKING_DIRECTORY ${WORK} RESULT_VARIABLE status)
if(NOT status EQUAL 0)
    message(FATAL_ERROR "the coupled run failed")
endif()
string(REPLACE "@OUT@" "${WORK}/out" arguments "${ARGS}")
execute_process(COMMAND python3 ${CHECK} ${arguments} RESULT_VARIABLE off)
if(NOT off EQUAL 0)
    message(FATAL_ERROR "the check ${CHECK} failed")
endif()
