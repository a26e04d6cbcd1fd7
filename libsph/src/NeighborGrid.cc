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

namespace {

/// Throw the error for position x of particle i, which the grid of `cellSize` (m) cannot hold.
[[noreturn]] void throwBadPosition(const Vec3& x, std::size_t i, Real cellSize)
{
    if (!isFinite(x)) {
        throw NumericalError(msg("neighbour grid: particle ", i, " has a non-finite position (",
                                 x[0], ", ", x[1], ", ", x[2], ")"));
    }
    throw ValueError(msg("neighbour grid: particle ", i, " at (", x[0], ", ", x[1], ", ", x[2],
                         ") m is beyond the grid range of +/-",
                         Real(NeighborGrid::MAX_CELL_COORD) * cellSize, " m for cell size ",
                         cellSize, " m"));
}

} // namespace

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

    std::vector<std::uint32_t> bucket(count);
    std::vector<std::uint64_t> key(count);
    keyPositions(positions, count, key, bucket);
    const std::vector<std::uint32_t> bucketStart = scatterByBucket(bucket, tableSize);
    const std::vector<std::uint32_t> bucketCells = sortBuckets(key, bucketStart);
    buildLookup(tabulateCells(key, bucketStart, bucketCells));
    gatherCoordinates(positions);
}

void NeighborGrid::keyPositions(const Vec3* positions, std::size_t count,
                                std::vector<std::uint64_t>& key,
                                std::vector<std::uint32_t>& bucket) const
{
    // The first position the grid cannot represent, by index, so the error does not depend
    // on the thread count.
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
    const std::size_t bad = badIndex.load();
    if (bad < count) throwBadPosition(positions[bad], bad, mCellSize);
}

std::vector<std::uint32_t> NeighborGrid::scatterByBucket(const std::vector<std::uint32_t>& bucket,
                                                         std::size_t tableSize)
{
    // Histogram of bucket sizes.
    const std::size_t count = bucket.size();
    std::unique_ptr<std::atomic<std::uint32_t>[]> counts(new std::atomic<std::uint32_t>[tableSize]);
    parallel::forEach(
        0, tableSize, [&](std::size_t b) { counts[b].store(0, std::memory_order_relaxed); }, 8192);
    parallel::forEach(
        0, count, [&](std::size_t i) { counts[bucket[i]].fetch_add(1, std::memory_order_relaxed); },
        4096);

    // Exclusive scan into bucket starts; the counts become scatter cursors.
    std::vector<std::uint32_t> bucketStart(tableSize + 1);
    std::uint32_t running = 0;
    for (std::size_t b = 0; b < tableSize; ++b) {
        bucketStart[b] = running;
        const std::uint32_t c = counts[b].load(std::memory_order_relaxed);
        counts[b].store(running, std::memory_order_relaxed);
        running += c;
    }
    bucketStart[tableSize] = running;

    // Scatter particle indices to their bucket's slots.
    mIndex.resize(count);
    parallel::forEach(
        0, count,
        [&](std::size_t i) {
        mIndex[counts[bucket[i]].fetch_add(1, std::memory_order_relaxed)] = Index(i);
        },
        4096);
    return bucketStart;
}

std::vector<std::uint32_t> NeighborGrid::sortBuckets(const std::vector<std::uint64_t>& key,
                                                     const std::vector<std::uint32_t>& bucketStart)
{
    // The scatter order inside a bucket depends on thread timing: sorting each bucket by
    // cell, then index, makes the result deterministic and every cell one run of slots.
    const std::size_t tableSize = bucketStart.size() - 1;
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
    return bucketCells;
}

std::vector<std::uint32_t> NeighborGrid::tabulateCells(
    const std::vector<std::uint64_t>& key, const std::vector<std::uint32_t>& bucketStart,
    const std::vector<std::uint32_t>& bucketCells)
{
    // Buckets to cells (exclusive scan), then cells to slots and keys.
    const std::size_t tableSize = bucketStart.size() - 1;
    std::vector<std::uint32_t> bucketFirstCell(tableSize + 1);
    std::uint32_t cellCount = 0;
    for (std::size_t b = 0; b < tableSize; ++b) {
        bucketFirstCell[b] = cellCount;
        cellCount += bucketCells[b];
    }
    bucketFirstCell[tableSize] = cellCount;
    mCellKey.resize(cellCount);
    mCellStart.resize(std::size_t(cellCount) + 1);
    mCellStart[cellCount] = std::uint32_t(mSize);
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
    return bucketFirstCell;
}

void NeighborGrid::buildLookup(const std::vector<std::uint32_t>& bucketFirstCell)
{
    // Cells sit in bucket order, so 2^shift consecutive buckets hold one run of cells. Merge
    // as many as keep two lookup buckets per occupied cell: a liquid with about 20 particles
    // per cell keeps an eighth of the table the sort used.
    const std::size_t tableSize = bucketFirstCell.size() - 1;
    const std::size_t cellCount = mCellKey.size();
    mLookupShift = 0;
    while (mLookupShift < MAX_LOOKUP_SHIFT
           && (tableSize >> (mLookupShift + 1)) >= 2 * std::size_t(cellCount)) {
        ++mLookupShift;
    }
    const std::size_t lookupSize = tableSize >> mLookupShift;
    mBucketCell.resize(lookupSize + 1);
    for (std::size_t b = 0; b <= lookupSize; ++b)
        mBucketCell[b] = bucketFirstCell[b << mLookupShift];
}

void NeighborGrid::gatherCoordinates(const Vec3* positions)
{
    // The coordinate arrays carry PADDING more entries, so vectorised distance loops may read
    // past a range; the inverse map serves forEachNeighbor(i).
    const std::size_t count = mSize;
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
