# A mole experiment through the whole diagnosis with real coupled runs (docs/gap.md, "The
# mole"): a null twin of scenarios/gap/mole/design.yaml (the HP3 mole in Simbody hammering two
# strokes into a DEM column, two columns), then `gap diagnose` against the same base with one
# candidate effect whose signature is simulated (the hull's friction). The twin's data hold the
# tip's depth below the surface per stroke; the diagnosis compares all of them and claims
# nothing.
file(REMOVE_RECURSE ${OUT})
execute_process(COMMAND ${GRAINLINK} gap twin --model ${BASE} --design ${DESIGN} --null --seed 3
                        --noise 0.03 --out ${OUT}/twin --sims ${OUT}/sims --jobs 2
                RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
if(NOT rc EQUAL 0)
    message(FATAL_ERROR "twin failed (exit ${rc}):\n${out}\n${err}")
endif()
file(READ ${OUT}/twin/data/mole_mars_1.csv data)
message("${data}")
# Stroke 0 (resting on the grains) and two strokes, each deeper than 20 mm.
string(REGEX MATCHALL "\n[0-2],0\\.[0-9]+" rows "${data}")
list(LENGTH rows n)
if(NOT n EQUAL 3)
    message(FATAL_ERROR "the twin's mole data should hold strokes 0, 1 and 2 with positive depths:\n${data}")
endif()
execute_process(COMMAND ${GRAINLINK} gap diagnose ${OUT}/twin --model ${BASE} --out ${OUT}/diag
                        --sims ${OUT}/sims --jobs 2 --only tool_friction
                RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
message("${out}")
if(NOT rc EQUAL 0)
    message(FATAL_ERROR "diagnose failed (exit ${rc}):\n${err}")
endif()
if(NOT out MATCHES "Result: " OR NOT out MATCHES "mole_mars")
    message(FATAL_ERROR "no verdict on the mole experiment")
endif()
if(out MATCHES "explained by")
    message(FATAL_ERROR "a null twin got a claim")
endif()
if(err MATCHES "\\[gap\\] run [0-9a-f]+ ")
    message(FATAL_ERROR "a run failed:\n${err}")
endif()
# A dry run of the same diagnosis: the design and the split as the diagnosis made them, and
# every run before the gap test found in the cache; it runs nothing and writes no report.
file(GLOB points_before ${OUT}/sims/points/*)
execute_process(COMMAND ${GRAINLINK} gap diagnose ${OUT}/twin --model ${BASE} --out ${OUT}/dry
                        --sims ${OUT}/sims --only tool_friction --dry-run
                RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
message("${out}")
if(NOT rc EQUAL 0)
    message(FATAL_ERROR "diagnose --dry-run failed (exit ${rc}):\n${err}")
endif()
if(NOT out MATCHES "mole_mars +mole +[1-9][0-9]* feature")
    message(FATAL_ERROR "the dry run does not list the mole experiment's features")
endif()
if(NOT out MATCHES "runs before the gap test \\([^)]*\\): ([0-9]+), ([0-9]+) in the cache")
    message(FATAL_ERROR "the dry run does not count the runs before the gap test")
endif()
if(NOT CMAKE_MATCH_1 EQUAL CMAKE_MATCH_2 OR CMAKE_MATCH_1 EQUAL 0)
    message(FATAL_ERROR "the diagnosis ran ${CMAKE_MATCH_1} runs before its gap test; the dry "
                        "run finds ${CMAKE_MATCH_2} of them in the cache")
endif()
file(GLOB points_after ${OUT}/sims/points/*)
if(NOT points_before STREQUAL points_after OR EXISTS ${OUT}/dry/diagnosis.json)
    message(FATAL_ERROR "the dry run ran or wrote something")
endif()
