/// @file   DistributedFrames.h
/// @brief  A frame's points and volumes over several processes: each process builds the part
///         of every grid in its own region, rank 0 merges the parts (built with GHOSTFX_MPI).
/// @details No process gathers the whole liquid; each works from its own particles and a few
///          of the others':
///          - points: OpenVDB points-grid leaves are 8 voxels wide, and a leaf belongs to the
///            process whose region holds the centre of the leaf's first voxel, so no leaf
///            is split between processes; every particle goes to the process owning its leaf
///            (dist::MpiExchange::redistribute: only those within a leaf of a cut move), each
///            process makes its leaves and rank 0 moves every piece's leaves into one grid
///            (vdbio::mergePointsGrids). The voxel size is agreed first: the scene's, or the
///            smallest of the processes' automatic sizes.
///          - volumes: each process builds the grids from its own particles and copies of the
///            others' within (dist::MpiExchange::surroundings)
///            vdbio::volumeReach() of its region, so every voxel centre in the region gets the
///            value the whole liquid gives it, keeps those voxels (vdbio::keepVoxelsIn), and
///            rank 0 merges the pieces (vdbio::mergeVolumeGrids, the level set's signs filled
///            anew).
///          The pieces travel as OpenVDB streams, one process's at a time. Rank 0 holds the
///          merged grids (what the files hold), never the particles of every process.
#pragma once

#include "FrameWriter.h"

#include <ghostfx/dist/MpiExchange.h>
#include <ghostfx/vdbio/FrameFiles.h>

#include <cstdint>
#include <vector>

namespace ghostfx {
namespace cmd {

/// How much a frame's pieces copied (summed over the processes on rank 0).
struct FramePieceCounts
{
    std::uint64_t own = 0;     ///< particles of the kinds written (when volumes are asked)
    std::uint64_t copies = 0;  ///< copies sent to other processes for their volume pieces
    std::uint64_t largest = 0; ///< the most particles one process's volume piece was built from
    std::uint64_t moved = 0;   ///< particles sent to the process owning their points leaf
};

/// The grids of `set`'s particles of `kinds` for one frame: the points grid when `points` is
/// given, the volume grids when `volumes` is; on rank 0 merged from every process's piece,
/// elsewhere empty. Collective.
BuiltGrids buildFrameGrids(dist::MpiExchange& exchange, const sph::ParticleSet& set,
                           const std::vector<sph::ParticleKind>& kinds,
                           const vdbio::PointsOptions* points, const vdbio::VolumeOptions* volumes,
                           FramePieceCounts* counts = nullptr);

} // namespace cmd
} // namespace ghostfx
