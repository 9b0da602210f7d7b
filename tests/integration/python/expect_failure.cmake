# A Python participant that breaks the protocol makes `grainlink run` fail with the coordinator's
# one line naming it, and every other participant is told to stop.
# FAULT: wrong-version (speaks protocol major version 2) | garbage (bytes that are no Envelope in
# place of window 5's WindowDone) | model-error (the model raises in window 5).
# EXPECT: ;-list of regular expressions the output must match.
include(${HERE}/common.cmake)
if(SKIP)
    return()
endif()

write_two_mass(${OUT}/fault.yaml
    "  scheme: explicit-serial\n  end_time_s: 2.0\n  macro_step_s: 0.01\n"
    "${PYTHON};${HERE}/misbehaving_mbs.py;--fault;${FAULT};--at-window;5;${PYTHON_MBS_ARGS}")
run_grainlink(run ${OUT}/fault.yaml ${OUT}/run)
message("${run_output}")
if(run_status EQUAL 0)
    message(FATAL_ERROR "expected the run to fail, it succeeded")
endif()
require_output("the run with a misbehaving participant" "${run_output}" ${EXPECT})
