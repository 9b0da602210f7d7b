# The script started by hand, as a user's code would be, joins a run it was not started by:
# MODE run:         `grainlink run` with mbs marked `external: true` (it starts only the soil node)
# MODE coordinator: `grainlink coordinator`, with the soil node (NODE) started beside it too.
# The processes run at once (one execute_process pipeline); the result must equal the run in
# which the C++ node plays mass 1.
include(${HERE}/common.cmake)
if(SKIP)
    return()
endif()

string(CONCAT coupling "  scheme: implicit\n  end_time_s: 1.0\n  macro_step_s: 0.01\n"
                       "  handshake_timeout_s: 20.0\n")
write_two_mass(${OUT}/external.yaml "${coupling}" external)
write_two_mass(${OUT}/cpp.yaml "${coupling}" "${CPP_MBS}")
# An external participant needs a fixed address; a socket file of its own avoids port clashes
# with tests running at the same time.
string(RANDOM LENGTH 12 tag)
set(endpoint ipc:///tmp/grainlink-python-test-${tag}.ipc)

# A pipeline would join each one's standard output to the next one's input, and whichever ends
# first would break the other's last line: the participants write theirs to files instead.
set(python_mbs COMMAND sh -c "exec \"$@\" > ${OUT}/mbs.log" sh
                       ${PYTHON} ${EXAMPLE} --name mbs --endpoint ${endpoint}
                       --python-protocol-dir ${PROTOCOL})
set(options ${OUT}/external.yaml --out ${OUT}/external --endpoint ${endpoint}
            --progress-interval 0)
if(MODE STREQUAL "coordinator")
    set(soil COMMAND sh -c "exec \"$@\" > ${OUT}/soil.log" sh
                     ${NODE} --side soil --name soil --endpoint ${endpoint})
    set(coordinator COMMAND ${GRAINLINK} coordinator ${options})
else()
    set(soil)
    set(coordinator COMMAND ${GRAINLINK} run ${options})
endif()
execute_process(${python_mbs} ${soil} ${coordinator}
                RESULTS_VARIABLE statuses OUTPUT_VARIABLE stdout ERROR_VARIABLE stderr
                TIMEOUT 60)
file(REMOVE /tmp/grainlink-python-test-${tag}.ipc)
file(READ ${OUT}/mbs.log mbs_output)
set(output "${stdout}${stderr}${mbs_output}")
message("${output}")
foreach(status IN LISTS statuses)
    if(NOT status EQUAL 0)
        message(FATAL_ERROR "a process of the run failed (exit statuses: ${statuses})")
    endif()
endforeach()
require_output("the external run" "${output}" "participant 'mbs' joined as multibody"
               "coupling: 100 windows" "mbs: done, x = ")

run_grainlink(cpp ${OUT}/cpp.yaml ${OUT}/cpp)
require_success("the run with the C++ participant" "${cpp_status}" "${cpp_output}")
compare_mass1_x(${OUT}/external/coupling.csv ${OUT}/cpp/coupling.csv 1e-12) # see matches_cpp
