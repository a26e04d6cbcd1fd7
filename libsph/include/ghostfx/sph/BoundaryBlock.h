/// @file   BoundaryBlock.h
/// @brief  Boundary particles of solids (ghost solids, boundary particles) kept apart from the
///         moving particles: sorted by cell once, searched through their own grid.
/// @details [SB12] Sec. 4.4 samples every solid one kernel radius deep. A tank holds more of
///          these particles than the liquid (129k against 98k in the dam break of
///          bench/RESULTS.md), yet a step needs only the few within a kernel radius of liquid.
///          A block stores them with their own NeighborGrid: the solver's neighbour search
///          queries the block's grid from the liquid particles, so a boundary particle that no
///          liquid particle reaches costs nothing. A block of static solids is sorted once and
///          never re-placed; a block of moving solids is re-placed and re-sorted every step
///          (`rebuild()` after moving it).
///
///          The order is deterministic: `rebuild()` first orders the particles by id and then
///          by cell, so a block restored from a checkpoint in any order gets the same order, and
///          the same sums, as the run that wrote it.
#pragma once

#include "ghostfx/sph/NeighborGrid.h"
#include "ghostfx/sph/ParticleSet.h"

#include <cstdint>
#include <vector>

namespace ghostfx {
namespace sph {

class BoundaryBlock
{
public:
    /// @param cellSize  grid cell side (m): the kernel support radius of the queries
    explicit BoundaryBlock(Real cellSize) : mGrid(cellSize) { mGrid.setParticlesPerCellHint(8); }

    ParticleSet& particles() { return mParticles; }
    const ParticleSet& particles() const { return mParticles; }
    std::size_t size() const { return mParticles.size(); }
    bool empty() const { return mParticles.empty(); }

    /// Order the particles by id, then by cell, and rebuild the grid. Call it after adding,
    /// removing or moving particles, before the next query.
    void rebuild();
    /// Whether particles changed since the last rebuild (set by the owner through touch()).
    bool stale() const { return mStale; }
    void touch() { mStale = true; }

    /// The grid over the block, in the block's particle order (identity indices).
    const NeighborGrid& grid() const { return mGrid; }

    /// Bytes held by the particles and the grid.
    std::size_t memoryBytes() const { return mParticles.memoryBytes() + mGrid.memoryBytes(); }

private:
    ParticleSet mParticles;
    NeighborGrid mGrid;
    bool mStale = false;
};

} // namespace sph
} // namespace ghostfx
