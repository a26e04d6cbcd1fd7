# What the MPI run scripts share (run_dam_break.cmake, run_tomato.cmake): a fresh output
# folder and a command that must succeed.
file(REMOVE_RECURSE ${OUT})
function(ghostfx_run name)
    execute_process(COMMAND ${ARGN} RESULT_VARIABLE code ERROR_VARIABLE err OUTPUT_VARIABLE out)
    if(NOT code EQUAL 0)
        message(FATAL_ERROR "${name} failed (${code}): ${err}")
    endif()
endfunction()
# compare_points with ARGN; prints `label: what it measured`, stops with `failure` when the
# comparison fails. What it printed is left in `compared`.
function(ghostfx_compare label failure)
    execute_process(COMMAND ${COMPARE} ${ARGN} RESULT_VARIABLE code OUTPUT_VARIABLE out)
    message("${label}: ${out}")
    if(NOT code EQUAL 0)
        message(FATAL_ERROR "${failure}")
    endif()
    set(compared "${out}" PARENT_SCOPE)
endfunction()
