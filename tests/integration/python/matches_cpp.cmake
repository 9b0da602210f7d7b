# The two-mass run with the Python script as mass 1 ends where the run with the C++ node does.
# CASE: explicit-serial | explicit-parallel | implicit (IQN-ILS, windows repeated with rollback)
#     | long-windows (two windows that each take the Python side longer than peer_timeout_s, so
#       only its heartbeats keep it in the run).
include(${HERE}/common.cmake)
if(SKIP)
    return()
endif()

# Tolerance on mass1.x_m, relative to its amplitude: 1e-12. The script does the C++ node's RK4
# arithmetic in the same order on IEEE doubles (both without fused multiply-add), and the wire
# carries doubles exactly, so the runs agree to the last bit; the tolerance only leaves room for
# a compiler that contracts a*b+c differently.
set(tolerance 1e-12)
set(extra_checks)
if(CASE STREQUAL "long-windows")
    # 3e6 RK4 sub-steps a window: about 2 s of CPython 3.11 where this was written.
    string(CONCAT coupling "  scheme: explicit-serial\n  end_time_s: 600.0\n"
                          "  macro_step_s: 300.0\n"
                          "  heartbeat_interval_s: 0.1\n  peer_timeout_s: 0.5\n")
    set(extra_checks --min-wall-s 0.6) # longer than peer_timeout_s without a WindowDone
else()
    set(coupling "  scheme: ${CASE}\n  end_time_s: 2.0\n  macro_step_s: 0.01\n")
    if(CASE STREQUAL "implicit")
        string(APPEND coupling "  implicit:\n    relative_tolerance: 1.0e-8\n"
                               "    acceleration: iqn-ils\n")
    endif()
endif()

write_two_mass(${OUT}/python.yaml "${coupling}" "${PYTHON_MBS}")
write_two_mass(${OUT}/cpp.yaml "${coupling}" "${CPP_MBS}")
run_grainlink(python ${OUT}/python.yaml ${OUT}/python)
require_success("the run with the Python participant" "${python_status}" "${python_output}")
require_output("the run with the Python participant" "${python_output}"
               "participant 'mbs' joined as multibody" "mbs: done, x = ")
run_grainlink(cpp ${OUT}/cpp.yaml ${OUT}/cpp)
require_success("the run with the C++ participant" "${cpp_status}" "${cpp_output}")

if(CASE STREQUAL "implicit") # rollback is exercised only if windows were repeated
    if(NOT python_output MATCHES "200 windows \\(([0-9.]+) passes each\\)"
       OR CMAKE_MATCH_1 VERSION_LESS_EQUAL 1.0)
        message(FATAL_ERROR "the implicit run repeated no window:\n${python_output}")
    endif()
endif()
compare_mass1_x(${OUT}/python/coupling.csv ${OUT}/cpp/coupling.csv ${tolerance} ${extra_checks})
