# Checkpoints: a run whose Python participant breaks at window 120 keeps the checkpoint of window
# 100 (the Python side's state file among it); `grainlink run --resume` continues from there and
# ends exactly where an unbroken run with the C++ node does, which it can only if the script wrote
# and read back its state.
include(${HERE}/common.cmake)
if(SKIP)
    return()
endif()

string(CONCAT coupling "  scheme: implicit\n  end_time_s: 2.0\n  macro_step_s: 0.01\n"
                       "  implicit:\n    relative_tolerance: 1.0e-8\n    acceleration: iqn-ils\n"
                       "  checkpoint_every_windows: 50\n")
write_two_mass(${OUT}/broken.yaml "${coupling}"
    "${PYTHON};${HERE}/misbehaving_mbs.py;--fault;garbage;--at-window;120;${PYTHON_MBS_ARGS}")
write_two_mass(${OUT}/python.yaml "${coupling}" "${PYTHON_MBS}")
write_two_mass(${OUT}/cpp.yaml "${coupling}" "${CPP_MBS}")

run_grainlink(broken ${OUT}/broken.yaml ${OUT}/python)
require_output("the broken run" "${broken_output}"
               "grainlink: error: participant 'mbs' failed in window 120")
file(READ ${OUT}/python/checkpoints/latest latest)
if(NOT latest STREQUAL "window_000000100\n")
    message(FATAL_ERROR "latest checkpoint is '${latest}', expected window_000000100")
endif()
file(READ ${OUT}/python/checkpoints/window_000000100/mbs/mbs.state state)
if(NOT state MATCHES "^[-+0-9.e]+ [-+0-9.e]+\n$")
    message(FATAL_ERROR "the Python side's checkpoint holds '${state}', expected 'x v'")
endif()

run_grainlink(resumed ${OUT}/python.yaml ${OUT}/python --resume)
require_success("the resumed run" "${resumed_status}" "${resumed_output}")
run_grainlink(cpp ${OUT}/cpp.yaml ${OUT}/cpp)
require_success("the run with the C++ participant" "${cpp_status}" "${cpp_output}")
# Same tolerance as matches_cpp.cmake: the state file's 17 digits round-trip doubles exactly.
compare_mass1_x(${OUT}/python/coupling.csv ${OUT}/cpp/coupling.csv 1e-12)
