# `grainlink lab` end to end (tests/lab/CMakeLists.txt): the run writes its results and its plot,
# and without matplotlib it says so in one line, keeps the results and still exits 0.
function(run_lab out env)
    file(REMOVE_RECURSE ${out})
    execute_process(COMMAND ${CMAKE_COMMAND} -E env OMP_WAIT_POLICY=PASSIVE ${env}
                            ${GRAINLINK} lab repose ${SCENARIO} --out ${out} --progress-interval 100
                    RESULT_VARIABLE rc OUTPUT_VARIABLE stdout ERROR_VARIABLE stderr)
    if(NOT rc EQUAL 0)
        message(FATAL_ERROR "grainlink lab failed (${rc}): ${stderr}")
    endif()
    foreach(file heap_profile.csv report.txt summary.json)
        if(NOT EXISTS ${out}/${file})
            message(FATAL_ERROR "missing output ${out}/${file}")
        endif()
    endforeach()
    set(stdout "${stdout}" PARENT_SCOPE)
endfunction()

function(expect what)
    string(FIND "${stdout}" "${what}" at)
    if(at EQUAL -1)
        message(FATAL_ERROR "the output lacks '${what}':\n${stdout}")
    endif()
endfunction()

run_lab(${OUT}/plotted "")
expect("written: ${OUT}/plotted/{heap_profile.csv,report.txt,summary.json}\n")
expect("plot: ${OUT}/plotted/repose.png\n")
if(NOT EXISTS ${OUT}/plotted/repose.png)
    message(FATAL_ERROR "no ${OUT}/plotted/repose.png")
endif()

# A matplotlib that fails to import, first on Python's module path.
file(WRITE ${OUT}/fake/matplotlib/__init__.py "raise ImportError('no matplotlib here')\n")
run_lab(${OUT}/unplotted PYTHONPATH=${OUT}/fake)
expect("no plot: plot_lab.py: python3-matplotlib is not installed")
if(EXISTS ${OUT}/unplotted/repose.png)
    message(FATAL_ERROR "a plot without matplotlib")
endif()
