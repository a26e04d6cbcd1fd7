# The dam-break example as one process and as two (mpirun): frame 3 compared by id
# (compare_points, within the tolerance tests/dist/test_mpi.cc explains); then the two-process
# run resumed from its frame-2 checkpoint, against the uninterrupted one: frames 3 and 4 bit for
# bit. (Frame 4 once differed in some runs: the air resampling read the halo flags through a
# pointer that adding air could leave dangling, so what it read depended on the heap; fixed
# 2026-11-24.) Resumed on another process count, the run goes on from the merged parts.
# Run by ctest (tests/CMakeLists.txt).
include(${CMAKE_CURRENT_LIST_DIR}/run_common.cmake)
set(run ${GHOSTFX} run ${SCENE} --threads 1 -q -D outputs.checkpoint.every=2)
set(two ${MPIEXEC} -np 2 --oversubscribe)
ghostfx_run("one process" ${run} --frames 1-3 --out ${OUT}/one)
ghostfx_run("two processes" ${two} ${run} --frames 1-4 --out ${OUT}/two)
ghostfx_run("two processes, resumed" ${two} ${run} --frames 1-4 --out ${OUT}/resumed
            --resume ${OUT}/two/checkpoint.0002.ranks.json)

ghostfx_compare("one against two processes"
                "the two-process frame differs from the one-process frame beyond the tolerance"
                ${OUT}/one/liquid_points.0003.vdb ${OUT}/two/liquid_points.0003.vdb 0.003 0.03)
# The implicit pressure (settings.pressure dfsph) over two processes, against one.
set(dfsph ${run} -D settings.pressure=dfsph --frames 1-3)
ghostfx_run("one process, dfsph" ${dfsph} --out ${OUT}/dfsph_one)
ghostfx_run("two processes, dfsph" ${two} ${dfsph} --out ${OUT}/dfsph_two)
ghostfx_compare("one against two processes, dfsph"
                "the two-process dfsph frame differs from the one-process frame beyond the tolerance"
                ${OUT}/dfsph_one/liquid_points.0003.vdb ${OUT}/dfsph_two/liquid_points.0003.vdb
                0.003 0.03)
# The volumes, built in pieces (one per process) and merged on rank 0: the surface and density
# grids of the same frame hold as many voxels as the one-process run's within 2 % (the
# particles themselves differ by the rms above; measured 0.2 %). tests/dist/test_mpi_frames.cc
# checks that the pieces of one particle set merge to its whole grids exactly.
foreach(grid surface density)
    ghostfx_active_voxels(${OUT}/one/liquid.0003.vdb ${grid} n1)
    ghostfx_active_voxels(${OUT}/two/liquid.0003.vdb ${grid} n2)
    math(EXPR spread "(${n1} - ${n2}) * 1000 / ${n1}")
    message("one against two processes, grid ${grid}: ${n1} and ${n2} active voxels")
    if(spread GREATER 20 OR spread LESS -20)
        message(FATAL_ERROR "the two-process ${grid} grid has ${n2} active voxels, the "
                            "one-process one ${n1} (more than 2 % apart)")
    endif()
endforeach()
foreach(frame 0003 0004)
    ghostfx_compare("resumed against uninterrupted, two processes, frame ${frame}"
                    "the resumed two-process run differs from the uninterrupted one"
                    ${OUT}/two/liquid_points.${frame}.vdb
                    ${OUT}/resumed/liquid_points.${frame}.vdb 0 0)
endforeach()
foreach(file liquid.0003.vdb preview.0003.exr checkpoint.0002.rank0.h5 checkpoint.0002.rank1.h5)
    if(NOT EXISTS ${OUT}/two/${file})
        message(FATAL_ERROR "the two-process run wrote no ${file}")
    endif()
endforeach()

# On another process count the checkpoint's parts are merged and the domain cut anew: the run
# goes on within the one-against-two tolerance of the uninterrupted run (the air of the new
# slabs differs). The same for a one-process checkpoint resumed on two.
ghostfx_run("two processes' checkpoint on three" ${MPIEXEC} -np 3 --oversubscribe ${run}
            --frames 1-4 --out ${OUT}/three --resume ${OUT}/two/checkpoint.0002.ranks.json)
ghostfx_run("two processes' checkpoint on one" ${run} --frames 1-4 --out ${OUT}/merged
            --resume ${OUT}/two/checkpoint.0002.ranks.json)
ghostfx_run("one process's checkpoint on two" ${two} ${run} --frames 1-4 --out ${OUT}/split
            --resume ${OUT}/one/checkpoint.0002.h5)
foreach(resumed three merged split)
    ghostfx_compare("resumed on another count (${resumed}) against two processes, frame 4"
                    "the run resumed on another process count (${resumed}) is off"
                    ${OUT}/two/liquid_points.0004.vdb
                    ${OUT}/${resumed}/liquid_points.0004.vdb 0.003 0.03)
endforeach()

# `ghostfx info` on the manifest: every process's part and the whole simulation's liquid, which
# is the frame files' (a closed tank: no liquid enters or leaves).
execute_process(COMMAND ${GHOSTFX} info ${OUT}/two/checkpoint.0002.ranks.json
                RESULT_VARIABLE code OUTPUT_VARIABLE info ERROR_VARIABLE err)
message("ghostfx info on the manifest:\n${info}")
string(REGEX MATCH "whole simulation: [^\n]* ([0-9]+) liquid" whole "${info}")
set(infoLiquid ${CMAKE_MATCH_1})
string(REGEX MATCH "liquid_points.0004.vdb: ([0-9]+) particles" frame "${compared}")
set(frameLiquid ${CMAKE_MATCH_1})
if(NOT code EQUAL 0 OR NOT info MATCHES "written by 2 processes" OR NOT whole
   OR NOT infoLiquid EQUAL frameLiquid)
    message(FATAL_ERROR "ghostfx info on the manifest (${code}; liquid ${infoLiquid} against "
                        "the frame file's ${frameLiquid}): ${info}${err}")
endif()
