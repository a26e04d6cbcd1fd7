/// @file   NeighborGrid.cc
/// @brief  Parallel counting sort and cell table behind NeighborGrid::build.
#include "ghostfx/sph/NeighborGrid.h"

#include "ghostfx/sph/Exceptions.h"
#include "ghostfx/sph/Parallel.h"
#include "ghostfx/sph/ParticleSet.h"

#include <algorithm>
#include <atomic>
#include <memory>
#include <numeric>

namespace ghostfx {
namespace sph {

NeighborGrid::NeighborGrid(Real cellSize) : mCellSize(cellSize), mInvCellSize(Real(1) / cellSize)
{
    if (!(cellSize > Real(0)) || !std::isfinite(cellSize)) {
        throw ValueError(msg("neighbour grid cell size = ", cellSize,
                             " m: expected a finite "
                             "value > 0 (normally the kernel support radius)"));
    }
}

std::size_t NeighborGrid::memoryBytes() const
{
    return mBucketCell.capacity() * sizeof(std::uint32_t)
           + mCellKey.capacity() * sizeof(std::uint64_t)
           + mCellStart.capacity() * sizeof(std::uint32_t)
           + (mX.capacity() + mY.capacity() + mZ.capacity()) * sizeof(Real)
           + mIndex.capacity() * sizeof(Index) + mSlotOf.capacity() * sizeof(std::uint32_t);
}

void NeighborGrid::build(const Vec3* positions, std::size_t count)
{
    if (count >= std::size_t(INVALID_INDEX)) {
        throw ValueError(
            msg("neighbour grid: ", count, " particles exceed the 32-bit index range"));
    }
    mIdentity = false;
    mSize = count;
    // Table size: the smallest power of two >= 2 N (at least 64), so buckets average <= 0.5
    // particle-cells and a compact block of cells never wraps onto itself.
    std::size_t tableSize = 64;
    while (tableSize < 2 * count / mPerCellHint) tableSize *= 2;
    mTableMask = tableSize - 1;

    // 1. Cell key and bucket of every particle; reject what the grid cannot represent.
    std::vector<std::uint32_t> bucket(count);
    std::vector<std::uint64_t> key(count);
    std::atomic<std::size_t> badIndex{count};
    parallel::forEach(
        0, count,
        [&](std::size_t i) {
        const Vec3& x = positions[i];
        const Real limit = Real(MAX_CELL_COORD) * mCellSize;
        if (!isFinite(x) || std::abs(x[0]) >= limit || std::abs(x[1]) >= limit
            || std::abs(x[2]) >= limit) {
            std::size_t expected = badIndex.load();
            while (i < expected && !badIndex.compare_exchange_weak(expected, i)) {}
            return;
        }
        const Cell c = cellOf(x);
        key[i] = packKey(c);
        bucket[i] = bucketOf(c);
        },
        2048);
    if (badIndex.load() < count) {
        const std::size_t i = badIndex.load();
        const Vec3& x = positions[i];
        if (!isFinite(x)) {
            throw NumericalError(msg("neighbour grid: particle ", i, " has a non-finite position (",
                                     x[0], ", ", x[1], ", ", x[2], ")"));
        }
        throw ValueError(msg("neighbour grid: particle ", i, " at (", x[0], ", ", x[1], ", ", x[2],
                             ") m is beyond the grid range of +/-",
                             Real(MAX_CELL_COORD) * mCellSize, " m for cell size ", mCellSize,
                             " m"));
    }

    // 2. Histogram of bucket sizes.
    std::unique_ptr<std::atomic<std::uint32_t>[]> counts(new std::atomic<std::uint32_t>[tableSize]);
    parallel::forEach(
        0, tableSize, [&](std::size_t b) { counts[b].store(0, std::memory_order_relaxed); }, 8192);
    parallel::forEach(
        0, count, [&](std::size_t i) { counts[bucket[i]].fetch_add(1, std::memory_order_relaxed); },
        4096);

    // 3. Exclusive scan into bucket starts; the counts become scatter cursors.
    std::vector<std::uint32_t> bucketStart(tableSize + 1);
    std::uint32_t running = 0;
    for (std::size_t b = 0; b < tableSize; ++b) {
        bucketStart[b] = running;
        const std::uint32_t c = counts[b].load(std::memory_order_relaxed);
        counts[b].store(running, std::memory_order_relaxed);
        running += c;
    }
    bucketStart[tableSize] = running;

    // 4. Scatter particle indices to their bucket's slots.
    mIndex.resize(count);
    parallel::forEach(
        0, count,
        [&](std::size_t i) {
        mIndex[counts[bucket[i]].fetch_add(1, std::memory_order_relaxed)] = Index(i);
        },
        4096);

    // 5. The scatter order inside a bucket depends on thread timing: sort each bucket by cell,
    //    then index, so the result is deterministic and every cell is one run of slots. Count
    //    the cells of each bucket on the way.
    std::vector<std::uint32_t> bucketCells(tableSize + 1, 0);
    parallel::forEach(
        0, tableSize,
        [&](std::size_t b) {
        const std::uint32_t lo = bucketStart[b], hi = bucketStart[b + 1];
        if (hi - lo > 1) {
            std::sort(mIndex.begin() + lo, mIndex.begin() + hi, [&key](Index a, Index c) {
                return key[a] != key[c] ? key[a] < key[c] : a < c;
            });
        }
        std::uint32_t cells = 0;
        for (std::uint32_t s = lo; s < hi; ++s)
            cells += s == lo || key[mIndex[s]] != key[mIndex[s - 1]];
        bucketCells[b] = cells;
        },
        4096);

    // 6. Cell table: buckets to cells (exclusive scan), cells to slots and keys.
    std::vector<std::uint32_t> bucketFirstCell(tableSize + 1);
    std::uint32_t cellCount = 0;
    for (std::size_t b = 0; b < tableSize; ++b) {
        bucketFirstCell[b] = cellCount;
        cellCount += bucketCells[b];
    }
    bucketFirstCell[tableSize] = cellCount;
    mCellKey.resize(cellCount);
    mCellStart.resize(std::size_t(cellCount) + 1);
    mCellStart[cellCount] = std::uint32_t(count);
    parallel::forEach(
        0, tableSize,
        [&](std::size_t b) {
        std::uint32_t cell = bucketFirstCell[b];
        for (std::uint32_t s = bucketStart[b], hi = bucketStart[b + 1]; s < hi; ++s) {
            const std::uint64_t k = key[mIndex[s]];
            if (s == bucketStart[b] || k != key[mIndex[s - 1]]) {
                mCellKey[cell] = k;
                mCellStart[cell] = s;
                ++cell;
            }
        }
        },
        4096);

    // 7. Lookup table: cells sit in bucket order, so 2^shift consecutive buckets hold one run
    //    of cells. Merge as many as keep two lookup buckets per occupied cell: a liquid with
    //    about 20 particles per cell keeps an eighth of the table the sort used.
    mLookupShift = 0;
    while (mLookupShift < MAX_LOOKUP_SHIFT
           && (tableSize >> (mLookupShift + 1)) >= 2 * std::size_t(cellCount)) {
        ++mLookupShift;
    }
    const std::size_t lookupSize = tableSize >> mLookupShift;
    mBucketCell.resize(lookupSize + 1);
    for (std::size_t b = 0; b <= lookupSize; ++b)
        mBucketCell[b] = bucketFirstCell[b << mLookupShift];

    // 8. Gather coordinates in sorted order; inverse map for forEachNeighbor(i). The coordinate
    //    arrays carry PADDING more entries, so vectorised distance loops may read past a range.
    mX.assign(count + PADDING, Real(0));
    mY.assign(count + PADDING, Real(0));
    mZ.assign(count + PADDING, Real(0));
    mSlotOf.resize(count);
    parallel::forEach(
        0, count,
        [&](std::size_t s) {
        const Index i = mIndex[s];
        mX[s] = positions[i][0];
        mY[s] = positions[i][1];
        mZ[s] = positions[i][2];
        mSlotOf[i] = std::uint32_t(s);
        },
        4096);
}

void NeighborGrid::sortParticles(ParticleSet& particles)
{
    build(particles.positions());
    particles.reorder(mIndex);
    // The set now is in slot order: particle k sits in slot k, and the index arrays would
    // only say so (8 bytes per particle, given back).
    std::vector<Index>().swap(mIndex);
    std::vector<std::uint32_t>().swap(mSlotOf);
    mIdentity = true;
}

} // namespace sph
} // namespace ghostfx
