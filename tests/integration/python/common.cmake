# Shared by the Python participant tests (cmake -P scripts). Inputs, as -D definitions:
#   GRAINLINK  the grainlink command         PYTHON        the interpreter to run Python with
#   EXAMPLE    examples/python/two_mass_multibody.py
#   PROTOCOL   the folder of the generated grainlink/v1/coupling_pb2.py
#   HERE       this folder                   OUT           this test's scratch folder
#
# Without python3-zmq and python3-protobuf there is nothing to test: the including script
# returns at once when SKIP is set, and ctest reports the test as skipped (SKIP_RETURN_CODE 77
# where CMake can set its exit status, >= 3.29; otherwise the line below matches the test's
# SKIP_REGULAR_EXPRESSION).
execute_process(COMMAND ${PYTHON} -c "import zmq, google.protobuf"
                RESULT_VARIABLE status OUTPUT_QUIET ERROR_QUIET)
set(SKIP FALSE)
if(NOT status EQUAL 0)
    message("python participant test skipped: ${PYTHON} cannot import zmq and google.protobuf "
            "(install python3-zmq and python3-protobuf)")
    if(CMAKE_VERSION VERSION_GREATER_EQUAL 3.29)
        cmake_language(EXIT 77)
    endif()
    set(SKIP TRUE)
    return()
endif()

file(REMOVE_RECURSE ${OUT})
file(MAKE_DIRECTORY ${OUT})

# The Python side, and the C++ node that plays the same side, as command lists.
set(PYTHON_MBS_ARGS --endpoint {endpoint} --name {name} --python-protocol-dir ${PROTOCOL})
set(PYTHON_MBS ${PYTHON} ${EXAMPLE} ${PYTHON_MBS_ARGS})
set(CPP_MBS grainlink-two-mass-node --side multibody --name {name} --endpoint {endpoint})

# Writes a two-mass run to `path`: `coupling` holds the lines under `coupling:`, mass 1 is played
# by the command list `mbs` (or connects by itself when it is "external"), mass 2 by the C++ node.
function(write_two_mass path coupling mbs)
    if(mbs STREQUAL "external")
        set(how "    external: true")
    else()
        list(JOIN mbs "\", \"" args)
        set(how "    command: [\"${args}\"]")
    endif()
    file(WRITE ${path}
         "coupling:\n${coupling}"
         "participants:\n"
         "  - name: mbs\n    role: multibody\n${how}\n"
         "  - name: soil\n    role: soil\n"
         "    command: [grainlink-two-mass-node, --side, soil, --name, \"{name}\", "
         "--endpoint, \"{endpoint}\"]\n")
endfunction()

# Runs `grainlink run config --out out [args...]`; sets <prefix>_status and <prefix>_output
# (stdout and stderr together, which hold the participants' lines too).
function(run_grainlink prefix config out)
    execute_process(COMMAND ${GRAINLINK} run ${config} --out ${out} --progress-interval 0 ${ARGN}
                    RESULT_VARIABLE status OUTPUT_VARIABLE stdout ERROR_VARIABLE stderr
                    TIMEOUT 60)
    set(${prefix}_status "${status}" PARENT_SCOPE)
    set(${prefix}_output "${stdout}${stderr}" PARENT_SCOPE)
endfunction()

# Fails the test unless every regular expression after `text` matches it.
function(require_output what text)
    foreach(pattern IN LISTS ARGN)
        if(NOT text MATCHES "${pattern}")
            message(FATAL_ERROR "${what}: output lacks '${pattern}':\n${text}")
        endif()
    endforeach()
endfunction()

function(require_success what status output)
    if(NOT status EQUAL 0)
        message(FATAL_ERROR "${what} failed (${status}):\n${output}")
    endif()
endfunction()

# Compares mass1.x_m of two coupling.csv files window by window (compare_columns.py).
function(compare_mass1_x tested reference tolerance)
    execute_process(COMMAND ${PYTHON} ${HERE}/compare_columns.py ${tested} ${reference}
                            mass1.x_m ${tolerance} ${ARGN}
                    RESULT_VARIABLE status OUTPUT_VARIABLE report ERROR_VARIABLE report)
    message("${report}")
    if(NOT status EQUAL 0)
        message(FATAL_ERROR "${tested} does not match ${reference}")
    endif()
endfunction()
