/// @file   NeighborGrid.h
/// @brief  Hashed uniform grid for fixed-radius neighbour queries, rebuilt by a parallel
///         counting sort, with a compact table of occupied cells.
/// @details Cells are cubes of side `cellSize` (normally the kernel support radius), so the
///          neighbours of a particle lie in the 27 cells around it. Cells are not stored densely:
///          a cell (i, j, k) goes to bucket morton(i, j, k) mod T, where the table size T is a
///          power of two about twice the particle count. Memory is therefore O(N) however far
///          apart the particles are (a lone particle 1 km away costs one bucket, not a dense
///          box), and for any compact region narrower than T^(1/3) cells per axis no two cells
///          share a bucket and the bucket order is the Z-order of the cells, so sorting by bucket
///          keeps nearby cells nearby in memory.
///
///          `build()` sorts particles by bucket (parallel count, exclusive scan, parallel scatter,
///          then a per-bucket sort by cell and index so the order never depends on thread
///          timing). The particles of one cell are then one contiguous run of sorted slots: the
///          grid keeps a table of the occupied cells (first slot and packed cell key), reached
///          from the bucket, so a cell lookup is two array reads and a key compare and the
///          candidates of a query are a few dense slot ranges. Sorted coordinates are stored as
///          three arrays (x, y, z), so the distance filter over a range vectorises. Reorder
///          the particle set itself with `order()` (see `sortParticles`) to make every other
///          channel stream too.
///
///          Neighbour callbacks receive `(j, xij, rij)`: the particle index, x_i - x_j (m) and
///          |x_i - x_j| (m). A particle is its own neighbour (j == i, rij == 0), as SPH sums need.
///          NeighborLists.h builds compact per-particle lists from this grid, once per step.
#pragma once

#include "ghostfx/sph/Types.h"

#include <cstdint>
#include <vector>

namespace ghostfx {
namespace sph {

class ParticleSet;

class NeighborGrid
{
public:
    /// Largest |cell coordinate| a particle may have: 2^20 cells from the origin on each axis
    /// (with 3 cm cells, 31 km). Farther particles are rejected with a ValueError.
    static constexpr std::int32_t MAX_CELL_COORD = (1 << 20) - 1;

    /// Integer coordinates of a cell.
    struct Cell
    {
        std::int32_t i, j, k;
        bool operator==(const Cell& o) const { return i == o.i && j == o.j && k == o.k; }
        bool operator!=(const Cell& o) const { return !(*this == o); }
    };
    /// Sorted slots [begin, end) of the particles of one cell.
    struct SlotRange
    {
        std::uint32_t begin = 0, end = 0;
        bool empty() const { return begin == end; }
    };

    /// @param cellSize  cell side (m), normally the kernel support radius; queries with a
    ///                  radius up to `cellSize` visit 27 cells, larger radii more
    explicit NeighborGrid(Real cellSize);

    Real cellSize() const { return mCellSize; }

    /// Expected particles per occupied cell (default 1): the hash table gets about two buckets
    /// per expected cell. Dense sets (a solid's band: about 20 per cell of one kernel radius)
    /// set it higher, so the table stays small and cache-resident.
    void setParticlesPerCellHint(std::size_t perCell) { mPerCellHint = perCell > 0 ? perCell : 1; }

    /// Sort `count` positions into the grid. Throws NumericalError on a non-finite position and
    /// ValueError on a position beyond MAX_CELL_COORD cells.
    void build(const Vec3* positions, std::size_t count);
    void build(const std::vector<Vec3>& positions) { build(positions.data(), positions.size()); }

    /// Build from the set's positions, reorder the whole set by cell, and rebuild the index
    /// mapping as the identity, so neighbour indices are indices into the reordered set.
    void sortParticles(ParticleSet& particles);

    /// Sorted slot k holds particle `order()[k]`: pass it to ParticleSet::reorder. Empty after
    /// sortParticles(), where slot k holds particle k (identityOrder()): the grid then keeps no
    /// index arrays.
    const std::vector<Index>& order() const { return mIndex; }

    std::size_t size() const { return mSize; }
    /// Buckets in the hash table that sets the sort order (a power of two).
    std::size_t bucketCount() const { return std::size_t(mTableMask) + 1; }
    /// Buckets in the cell-lookup table (a power of two, bucketCount() / 8 to bucketCount()).
    std::size_t lookupBucketCount() const { return bucketCount() >> mLookupShift; }
    /// Occupied cells.
    std::size_t cellCount() const { return mCellKey.size(); }
    /// Bytes held by the grid's arrays.
    std::size_t memoryBytes() const;

    // Cell-level access (NeighborLists, boundary activity) ------------------------------------

    /// Cell of a finite point. Coordinates are clamped just beyond the representable range,
    /// so a query point far outside cannot overflow; no particle lives out there anyway.
    Cell cellOf(const Vec3& x) const
    {
        auto axis = [this](Real v) {
            const Real limit = Real(MAX_CELL_COORD + 2);
            return std::int32_t(clamp(std::floor(v * mInvCellSize), -limit, limit));
        };
        return {axis(x[0]), axis(x[1]), axis(x[2])};
    }
    /// The sorted slots of cell c (empty if no particle lies in it).
    SlotRange cellSlots(const Cell& c) const
    {
        const std::uint32_t b = bucketOf(c) >> mLookupShift;
        const std::uint64_t key = packKey(c);
        for (std::uint32_t k = mBucketCell[b], end = mBucketCell[b + 1]; k < end; ++k) {
            if (mCellKey[k] == key) return {mCellStart[k], mCellStart[k + 1]};
        }
        return {};
    }
    /// Whether any particle lies in cell c.
    bool occupied(const Cell& c) const { return !cellSlots(c).empty(); }
    /// Occupied cell k (in sorted order): its coordinates and slots.
    Cell cellAt(std::size_t k) const { return unpackKey(mCellKey[k]); }
    SlotRange cellSlotsAt(std::size_t k) const { return {mCellStart[k], mCellStart[k + 1]}; }
    /// Entries past the last slot in each sorted coordinate array (zeros), so a vectorised
    /// distance loop may read a few slots past the end.
    static constexpr std::size_t PADDING = 8;
    /// Sorted coordinates (m), one array per axis, indexed by slot.
    const Real* sortedX() const { return mX.data(); }
    const Real* sortedY() const { return mY.data(); }
    const Real* sortedZ() const { return mZ.data(); }
    /// Position (m) of sorted slot s.
    Vec3 sortedPosition(std::uint32_t s) const { return Vec3(mX[s], mY[s], mZ[s]); }
    /// The particle index held by sorted slot s.
    Index particleAt(std::uint32_t s) const { return mIdentity ? Index(s) : mIndex[s]; }
    /// The sorted slot of particle i.
    std::uint32_t slotOf(Index i) const { return mIdentity ? std::uint32_t(i) : mSlotOf[i]; }
    /// Whether slot s holds particle s for every s (after sortParticles).
    bool identityOrder() const { return mIdentity; }

    // Queries ----------------------------------------------------------------------------------

    /// Call fn(j, xij, rij) for every particle j with |x_i - x_j| < cellSize, including i.
    template <typename Fn>
    void forEachNeighbor(Index i, Fn&& fn) const
    {
        forEachInRadius(sortedPosition(slotOf(i)), mCellSize, fn);
    }

    /// Call fn(j, x - x_j, r) for every particle j with |x - x_j| < radius (m).
    template <typename Fn>
    void forEachInRadius(const Vec3& x, Real radius, Fn&& fn) const;

    /// Call fn(j, x_j) for every particle j inside the box (bounds included), in slot order
    /// within each cell: visits the cells the box overlaps, or sweeps every particle when that
    /// is cheaper.
    template <typename Fn>
    void forEachInBox(const Aabb& box, Fn&& fn) const
    {
        forEachInBox(
            box, [](const Cell&) { return true; }, fn);
    }

    /// The same, over the cells c with cellWanted(c) true only: a filter on whole cells (the
    /// particles of the other cells are never read), in the same order.
    template <typename CellPred, typename Fn>
    void forEachInBox(const Aabb& box, CellPred&& cellWanted, Fn&& fn) const;

    /// Index of the particle closest to x among those with pred(j) true and distance below
    /// maxRadius (m), or INVALID_INDEX. Searches rings of cells outward and stops as soon as no
    /// closer particle can exist. `distance` (optional) receives the distance (m).
    template <typename Pred>
    Index nearest(const Vec3& x, Real maxRadius, Pred&& pred, Real* distance = nullptr) const;

    /// Whether some particle j with pred(j) true lies closer than maxRadius (m) to x: the same
    /// answer as nearest(x, maxRadius, pred) != INVALID_INDEX, without looking further once
    /// one is found.
    template <typename Pred>
    bool anyInRadius(const Vec3& x, Real maxRadius, Pred&& pred) const;

    /// Nearest particle of one kind (e.g. the closest liquid particle to a ghost, [SB12] Sec. 4).
    template <typename KindT>
    Index nearestOfKind(const Vec3& x, const std::vector<KindT>& kinds, KindT kind, Real maxRadius,
                        Real* distance = nullptr) const
    {
        return nearest(
            x, maxRadius, [&](Index j) { return kinds[j] == kind; }, distance);
    }

private:
    /// Whether a search `reach` cells wide would visit more cells than there are particles:
    /// then a plain sweep over the particles is cheaper.
    bool sweepIsCheaper(Real reach) const { return cube(Real(2) * reach + Real(1)) > Real(size()); }
    static constexpr std::int64_t KEY_OFFSET = std::int64_t(1) << 20;
    static std::uint64_t packKey(const Cell& c)
    {
        return (std::uint64_t(c.i + KEY_OFFSET) << 42) | (std::uint64_t(c.j + KEY_OFFSET) << 21)
               | std::uint64_t(c.k + KEY_OFFSET);
    }
    static Cell unpackKey(std::uint64_t key)
    {
        constexpr std::uint64_t MASK = (std::uint64_t(1) << 21) - 1;
        return {std::int32_t(std::int64_t(key >> 42 & MASK) - KEY_OFFSET),
                std::int32_t(std::int64_t(key >> 21 & MASK) - KEY_OFFSET),
                std::int32_t(std::int64_t(key & MASK) - KEY_OFFSET)};
    }
    static std::uint64_t spreadBits(std::uint64_t v)
    {
        v &= 0x1fffff;
        v = (v | v << 32) & 0x1f00000000ffffULL;
        v = (v | v << 16) & 0x1f0000ff0000ffULL;
        v = (v | v << 8) & 0x100f00f00f00f00fULL;
        v = (v | v << 4) & 0x10c30c30c30c30c3ULL;
        v = (v | v << 2) & 0x1249249249249249ULL;
        return v;
    }
    std::uint32_t bucketOf(const Cell& c) const
    {
        const std::uint64_t m = spreadBits(std::uint64_t(c.i)) << 2
                                | spreadBits(std::uint64_t(c.j)) << 1
                                | spreadBits(std::uint64_t(c.k));
        return std::uint32_t(m & mTableMask);
    }

    template <typename Fn>
    void visitCell(const Cell& c, const Vec3& x, Real radius2, Fn& fn) const;

    // The passes of build(), in order (NeighborGrid.cc).
    /// Cell key and bucket of each position; throws on one the grid cannot represent.
    void keyPositions(const Vec3* positions, std::size_t count, std::vector<std::uint64_t>& key,
                      std::vector<std::uint32_t>& bucket) const;
    /// Particle indices into mIndex by bucket (count, scan, scatter); returns where each of
    /// the `tableSize` buckets starts, and the slot count after them.
    std::vector<std::uint32_t> scatterByBucket(const std::vector<std::uint32_t>& bucket,
                                               std::size_t tableSize);
    /// Sort each bucket's slots by cell, then index; returns the cells in each bucket.
    std::vector<std::uint32_t> sortBuckets(const std::vector<std::uint64_t>& key,
                                           const std::vector<std::uint32_t>& bucketStart);
    /// The table of occupied cells (mCellKey, mCellStart); returns each bucket's first cell.
    std::vector<std::uint32_t> tabulateCells(const std::vector<std::uint64_t>& key,
                                             const std::vector<std::uint32_t>& bucketStart,
                                             const std::vector<std::uint32_t>& bucketCells);
    /// The cell-lookup table (mBucketCell, mLookupShift) over the cells of the sort buckets.
    void buildLookup(const std::vector<std::uint32_t>& bucketFirstCell);
    /// The coordinates in slot order and the slot of each particle.
    void gatherCoordinates(const Vec3* positions);

    Real mCellSize, mInvCellSize;
    /// Buckets of the sort table (minus one). Sorted order is by bucket, then key.
    std::uint64_t mTableMask = 63;
    /// The lookup table merges 2^shift consecutive sort buckets (at most a 2 x 2 x 2 block of
    /// cells, whose keys share a cache line), so a set with many particles per cell keeps a
    /// small table without changing its sort order.
    static constexpr unsigned MAX_LOOKUP_SHIFT = 3;
    unsigned mLookupShift = 0;
    std::vector<std::uint32_t> mBucketCell; ///< lookup bucket b holds cells [cell[b], cell[b+1])
    std::vector<std::uint64_t> mCellKey;    ///< packed key of each occupied cell, sorted order
    std::vector<std::uint32_t> mCellStart;  ///< cell k holds slots [start[k], start[k+1])
    std::vector<Real> mX, mY, mZ;           ///< positions in sorted order (m)
    std::vector<Index> mIndex;          ///< particle index of each sorted slot (empty if identity)
    std::vector<std::uint32_t> mSlotOf; ///< sorted slot of each particle index (empty if identity)
    std::size_t mSize = 0;              ///< particles in the grid
    bool mIdentity = false;             ///< slot s holds particle s for every slot
    std::size_t mPerCellHint = 1;       ///< see setParticlesPerCellHint
};

// ---------------------------------------------------------------------------------------------

template <typename Fn>
inline void NeighborGrid::visitCell(const Cell& c, const Vec3& x, Real radius2, Fn& fn) const
{
    const SlotRange range = cellSlots(c);
    // Two passes per batch of slots: a branch-free filter that appends every slot within the
    // radius to `hit`, then the callbacks, in slot order with the same xij and rij as a plain
    // loop. Inside a cell the particle order is arbitrary in a running simulation, so a branch
    // on `r2 < radius2` is mispredicted very often (bench/history/diary-2026-11.md, "Neighbour
    // search").
    constexpr std::uint32_t BATCH = 64;
    std::uint32_t hit[BATCH];
    Real hitR2[BATCH];
    for (std::uint32_t k = range.begin; k < range.end;) {
        const std::uint32_t stop = range.end - k > BATCH ? k + BATCH : range.end;
        std::uint32_t n = 0;
        for (std::uint32_t s = k; s < stop; ++s) {
            const Real dx = x[0] - mX[s], dy = x[1] - mY[s], dz = x[2] - mZ[s];
            const Real r2 = dx * dx + dy * dy + dz * dz;
            hit[n] = s;
            hitR2[n] = r2;
            n += std::uint32_t(r2 < radius2);
        }
        for (std::uint32_t h = 0; h < n; ++h) {
            const std::uint32_t s = hit[h];
            fn(particleAt(s), x - sortedPosition(s), std::sqrt(hitR2[h]));
        }
        k = stop;
    }
}

template <typename Fn>
inline void NeighborGrid::forEachInRadius(const Vec3& x, Real radius, Fn&& fn) const
{
    if (mSize == 0 || !isFinite(x) || !(radius > Real(0))) return;
    const Real radius2 = radius * radius;
    const Real reachCells = std::ceil(radius * mInvCellSize);
    if (sweepIsCheaper(reachCells)) {
        for (std::uint32_t s = 0; s < mSize; ++s) {
            const Vec3 xij = x - sortedPosition(s);
            const Real r2 = xij.lengthSqr();
            if (r2 < radius2) fn(particleAt(s), xij, std::sqrt(r2));
        }
        return;
    }
    const Cell c = cellOf(x);
    const int reach = radius <= mCellSize ? 1 : int(reachCells);
    for (int di = -reach; di <= reach; ++di) {
        for (int dj = -reach; dj <= reach; ++dj) {
            for (int dk = -reach; dk <= reach; ++dk) {
                visitCell(Cell{c.i + di, c.j + dj, c.k + dk}, x, radius2, fn);
            }
        }
    }
}

template <typename CellPred, typename Fn>
inline void NeighborGrid::forEachInBox(const Aabb& box, CellPred&& cellWanted, Fn&& fn) const
{
    if (mSize == 0 || box.empty() || !isFinite(box.min) || !isFinite(box.max)) return;
    const Cell lo = cellOf(box.min), hi = cellOf(box.max);
    const double cells =
        double(hi.i - lo.i + 1) * double(hi.j - lo.j + 1) * double(hi.k - lo.k + 1);
    if (cells > double(cellCount())) {
        for (std::uint32_t s = 0; s < mSize; ++s) {
            const Vec3 x = sortedPosition(s);
            if (box.contains(x) && cellWanted(cellOf(x))) fn(particleAt(s), x);
        }
        return;
    }
    for (std::int32_t i = lo.i; i <= hi.i; ++i) {
        for (std::int32_t j = lo.j; j <= hi.j; ++j) {
            for (std::int32_t k = lo.k; k <= hi.k; ++k) {
                if (!cellWanted(Cell{i, j, k})) continue;
                const SlotRange r = cellSlots(Cell{i, j, k});
                for (std::uint32_t s = r.begin; s < r.end; ++s) {
                    const Vec3 x = sortedPosition(s);
                    if (box.contains(x)) fn(particleAt(s), x);
                }
            }
        }
    }
}

template <typename Pred>
inline Index NeighborGrid::nearest(const Vec3& x, Real maxRadius, Pred&& pred, Real* distance) const
{
    Index best = INVALID_INDEX;
    Real best2 = maxRadius * maxRadius;
    // Equal distances go to the lower index, so the answer does not depend on visiting order.
    auto consider = [&](Index j, const Vec3& xij, Real) {
        const Real r2 = xij.lengthSqr();
        const bool closer = r2 < best2 || (r2 == best2 && best != INVALID_INDEX && j < best);
        if (closer && pred(j)) {
            best2 = r2;
            best = j;
        }
    };
    if (mSize != 0 && isFinite(x) && maxRadius > Real(0)) {
        const Real maxRingCells = std::ceil(maxRadius * mInvCellSize);
        if (sweepIsCheaper(maxRingCells)) {
            // A search this wide would visit more cells than there are particles.
            for (std::uint32_t s = 0; s < mSize; ++s) {
                consider(particleAt(s), x - sortedPosition(s), Real(0));
            }
        } else {
            const Cell c = cellOf(x);
            const int maxRing = int(maxRingCells);
            for (int ring = 0; ring <= maxRing; ++ring) {
                // Cells at Chebyshev distance `ring` from c: the shell of the (2 ring + 1)^3
                // block.
                for (int di = -ring; di <= ring; ++di) {
                    for (int dj = -ring; dj <= ring; ++dj) {
                        const bool faceIJ =
                            (di == -ring || di == ring || dj == -ring || dj == ring);
                        const int stepK = faceIJ || ring == 0 ? 1 : 2 * ring;
                        for (int dk = -ring; dk <= ring; dk += stepK) {
                            visitCell(Cell{c.i + di, c.j + dj, c.k + dk}, x, best2, consider);
                        }
                    }
                }
                // Every particle in ring + 1 or beyond is at least ring * cellSize away.
                if (best != INVALID_INDEX && best2 <= sqr(Real(ring) * mCellSize)) break;
            }
        }
    }
    if (distance) *distance = best == INVALID_INDEX ? Real(-1) : std::sqrt(best2);
    return best;
}

template <typename Pred>
inline bool NeighborGrid::anyInRadius(const Vec3& x, Real maxRadius, Pred&& pred) const
{
    if (mSize == 0 || !isFinite(x) || !(maxRadius > Real(0))) return false;
    const Real radius2 = maxRadius * maxRadius;
    // The distance as nearest() computes it, so both agree on particles at the limit.
    auto hit = [&](std::uint32_t s) {
        return (x - sortedPosition(s)).lengthSqr() < radius2 && pred(particleAt(s));
    };
    const Real maxRingCells = std::ceil(maxRadius * mInvCellSize);
    if (sweepIsCheaper(maxRingCells)) {
        for (std::uint32_t s = 0; s < mSize; ++s) {
            if (hit(s)) return true;
        }
        return false;
    }
    const Cell c = cellOf(x);
    const int reach = int(maxRingCells);
    // The own cell first (the likeliest hit), then the rest of the block.
    auto inCell = [&](const Cell& cell) {
        const SlotRange range = cellSlots(cell);
        for (std::uint32_t s = range.begin; s < range.end; ++s) {
            if (hit(s)) return true;
        }
        return false;
    };
    if (inCell(c)) return true;
    for (int di = -reach; di <= reach; ++di) {
        for (int dj = -reach; dj <= reach; ++dj) {
            for (int dk = -reach; dk <= reach; ++dk) {
                if ((di | dj | dk) != 0 && inCell(Cell{c.i + di, c.j + dj, c.k + dk})) return true;
            }
        }
    }
    return false;
}

} // namespace sph
} // namespace ghostfx
