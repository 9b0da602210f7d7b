# Runs each file of CONFIGS (a ;-list) through `grainlink run` into WORK/<file stem>, then the
# check script CHECK with its arguments ARGS (a ;-list in which @WORK@ stands for WORK). The
# checks and their tolerances are written in each check script.
cmake_minimum_required(VERSION 3.16) # new-style quoting: "@WORK@" is not a variable
file(MAKE_DIRECTORY ${WORK})
foreach(config ${CONFIGS})
    get_filename_component(stem ${config} NAME_WE)
    execute_process(COMMAND ${GRAINLINK} run ${config} --out ${WORK}/${stem}
                            --progress-interval 0
                    WORKING_DIRECTORY ${WORK} RESULT_VARIABLE status)
    if(NOT status EQUAL 0)
        message(FATAL_ERROR "the coupled run ${config} failed")
    endif()
endforeach()
string(REPLACE "@WORK@" "${WORK}" arguments "${ARGS}")
execute_process(COMMAND python3 ${CHECK} ${arguments} RESULT_VARIABLE off)
if(NOT off EQUAL 0)
    message(FATAL_ERROR "the check ${CHECK} failed")
endif()
