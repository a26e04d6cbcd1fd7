# The dam-break example for 3 frames as one process and as two (mpirun), then the two frame-3
# points files compared by id (compare_points). Run by ctest (tests/CMakeLists.txt).
file(REMOVE_RECURSE ${OUT})
foreach(run one two)
    if(run STREQUAL "one")
        set(launch "")
    else()
        set(launch ${MPIEXEC} -np 2 --oversubscribe)
    endif()
    execute_process(COMMAND ${launch} ${GHOSTFX} run ${SCENE} --frames 1-3 --threads 1 -q
                            --out ${OUT}/${run}
                    RESULT_VARIABLE code ERROR_VARIABLE err)
    if(NOT code EQUAL 0)
        message(FATAL_ERROR "ghostfx run (${run}) failed (${code}): ${err}")
    endif()
endforeach()
execute_process(COMMAND ${COMPARE} ${OUT}/one/liquid_points.0003.vdb
                        ${OUT}/two/liquid_points.0003.vdb 0.003 0.03
                RESULT_VARIABLE code OUTPUT_VARIABLE out)
message("${out}")
if(NOT code EQUAL 0)
    message(FATAL_ERROR "the two-process frame differs from the one-process frame beyond the tolerance")
endif()
foreach(file liquid.0003.vdb preview.0003.exr)
    if(NOT EXISTS ${OUT}/two/${file})
        message(FATAL_ERROR "the two-process run wrote no ${file}")
    endif()
endforeach()
