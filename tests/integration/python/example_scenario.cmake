# examples/python/two_mass_python.yaml as its README runs it: from the repository root (SOURCE),
# the generated classes found through PYTHONPATH. It must end where the same file with the C++
# node as mass 1 ends.
include(${HERE}/common.cmake)
if(SKIP)
    return()
endif()

set(scenario ${SOURCE}/examples/python/two_mass_python.yaml)
file(READ ${scenario} text)
set(cpp_mbs "grainlink-two-mass-node, --side, multibody, --name, \"{name}\", --endpoint, \"{endpoint}\"")
string(REGEX REPLACE "command: \\[/usr/bin/python3[^]]*\\]" "command: [${cpp_mbs}]"
       cpp_text "${text}")
if(cpp_text STREQUAL text)
    message(FATAL_ERROR "${scenario}: found no Python command to replace with the C++ node")
endif()
file(WRITE ${OUT}/cpp.yaml "${cpp_text}")

execute_process(COMMAND ${CMAKE_COMMAND} -E env PYTHONPATH=${PROTOCOL}
                        ${GRAINLINK} run ${scenario} --out ${OUT}/python --progress-interval 0
                WORKING_DIRECTORY ${SOURCE}
                RESULT_VARIABLE status OUTPUT_VARIABLE stdout ERROR_VARIABLE stderr TIMEOUT 60)
require_success("${scenario}" "${status}" "${stdout}${stderr}")
require_output("${scenario}" "${stdout}${stderr}" "mbs: done, x = ")
run_grainlink(cpp ${OUT}/cpp.yaml ${OUT}/cpp)
require_success("the same run with the C++ participant" "${cpp_status}" "${cpp_output}")
compare_mass1_x(${OUT}/python/coupling.csv ${OUT}/cpp/coupling.csv 1e-12) # see matches_cpp
