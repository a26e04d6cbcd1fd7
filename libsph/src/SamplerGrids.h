/// @file   SamplerGrids.h
/// @brief  Search grids and the solid band limit shared by the Poisson-disk sampler's phases
///         (PoissonSampler.cc) and its packing relaxation (SamplePacking.cc). Internal to
///         libsph.
#pragma once

#include "ghostfx/sph/Exceptions.h"
#include "ghostfx/sph/LevelSet.h"
#include "ghostfx/sph/PoissonSampler.h"
#include "ghostfx/sph/Types.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <memory>
#include <vector>

namespace ghostfx {
namespace sph {
namespace detail {

/// The cells of side `cellSize` over a box, numbered along x, then y, then z: the index
/// arithmetic that the sampler's search grids share.
struct CellLattice
{
    /// Largest number of cells a grid may allocate.
    static constexpr std::size_t MAX_CELLS = std::size_t(1) << 28;

    CellLattice(const Aabb& bounds, Real cellSize)
        : origin(bounds.min)
        , invCellSize(Real(1) / cellSize)
    {
        const Vec3 extent = bounds.extent();
        for (int a = 0; a < 3; ++a) {
            dims[a] =
                std::max<std::int64_t>(1, std::int64_t(std::ceil(extent[a] * invCellSize)) + 1);
            count *= std::size_t(dims[a]);
            if (count > MAX_CELLS) {
                throw SamplingError(msg("sampling region of ", extent[0], " x ", extent[1], " x ",
                                        extent[2], " m needs more than ", MAX_CELLS,
                                        " search cells of side ", cellSize,
                                        " m: use a larger spacing or a smaller region"));
            }
        }
    }

    bool contains(const Vec3& x) const
    {
        for (int a = 0; a < 3; ++a) {
            const Real c = (x[a] - origin[a]) * invCellSize;
            if (!(c >= Real(0) && c < Real(dims[a]))) return false;
        }
        return true;
    }

    /// The cell that holds x (clamped to the lattice), by coordinates and by index.
    std::int64_t cellOf(const Vec3& x, std::int64_t c[3]) const
    {
        for (int a = 0; a < 3; ++a) {
            c[a] = std::clamp<std::int64_t>(std::int64_t((x[a] - origin[a]) * invCellSize), 0,
                                            dims[a] - 1);
        }
        return (c[2] * dims[1] + c[1]) * dims[0] + c[0];
    }
    std::int64_t cellOf(const Vec3& x) const
    {
        std::int64_t c[3];
        return cellOf(x, c);
    }

    /// The cells [lo, hi] (per axis) that a ball of `radius` about x touches.
    void range(const Vec3& x, Real radius, std::int64_t lo[3], std::int64_t hi[3]) const
    {
        for (int a = 0; a < 3; ++a) {
            lo[a] = std::max<std::int64_t>(
                0, std::int64_t(std::floor((x[a] - radius - origin[a]) * invCellSize)));
            hi[a] = std::min<std::int64_t>(
                dims[a] - 1, std::int64_t(std::floor((x[a] + radius - origin[a]) * invCellSize)));
        }
    }

    /// Index of the first cell of the x-row (j, k).
    std::int64_t row(std::int64_t j, std::int64_t k) const { return (k * dims[1] + j) * dims[0]; }

    /// fn(index) for the cell at coordinates c and its up to 26 neighbours, in index order.
    template <typename Fn>
    void forNeighbourhood(const std::int64_t c[3], Fn&& fn) const
    {
        for (std::int64_t k = std::max<std::int64_t>(0, c[2] - 1);
             k <= std::min(dims[2] - 1, c[2] + 1); ++k) {
            for (std::int64_t j = std::max<std::int64_t>(0, c[1] - 1);
                 j <= std::min(dims[1] - 1, c[1] + 1); ++j) {
                const std::int64_t first = row(j, k);
                for (std::int64_t i = std::max<std::int64_t>(0, c[0] - 1);
                     i <= std::min(dims[0] - 1, c[0] + 1); ++i) {
                    fn(std::size_t(first + i));
                }
            }
        }
    }

    Vec3 origin;
    Real invCellSize;
    std::int64_t dims[3] = {1, 1, 1};
    std::size_t count = 1; ///< number of cells
};

/// Dense grid of cells of side `cellSize` over a box, each cell the head of a linked list of
/// point entries. Lists stay short (a cell of side r holds at most a few Poisson samples), so
/// queries cost 27 (radius <= cellSize) or 125 (radius <= 2 cellSize) list heads.
class PointGrid
{
public:
    PointGrid(const Aabb& bounds, Real cellSize) : mCells(bounds, cellSize)
    {
        mHead.assign(mCells.count, -1);
    }

    bool contains(const Vec3& x) const { return mCells.contains(x); }

    /// Add a point (which must be inside); returns its entry id, ids count up from 0.
    int add(const Vec3& x)
    {
        const int id = int(mPos.size());
        const std::int64_t c = mCells.cellOf(x);
        mPos.push_back(x);
        mNext.push_back(mHead[c]);
        mCell.push_back(c);
        mHead[c] = id;
        return id;
    }

    /// Move entry `id` to x (inside).
    void move(int id, const Vec3& x)
    {
        const std::int64_t c = mCells.cellOf(x);
        if (c != mCell[id]) {
            int* link = &mHead[mCell[id]];
            while (*link != id) link = &mNext[*link];
            *link = mNext[id];
            mNext[id] = mHead[c];
            mHead[c] = id;
            mCell[id] = c;
        }
        mPos[id] = x;
    }

    std::size_t size() const { return mPos.size(); }

    /// Whether any entry other than `ignore` lies closer than `radius` (<= 2 cellSize) to x.
    bool anyWithin(const Vec3& x, Real radius, int ignore = -1) const
    {
        const Real r2 = radius * radius;
        bool found = false;
        visit(x, radius, [&](int id) {
            if (id != ignore && (mPos[id] - x).lengthSqr() < r2) found = true;
            return !found;
        });
        return found;
    }

    /// Whether any entry lies closer than `radius` (<= 2 cellSize) to x; if so, its position
    /// is stored in `found`.
    bool findWithin(const Vec3& x, Real radius, Vec3& found) const
    {
        const Real r2 = radius * radius;
        bool hit = false;
        visit(x, radius, [&](int id) {
            if ((mPos[id] - x).lengthSqr() < r2) {
                found = mPos[id];
                hit = true;
            }
            return !hit;
        });
        return hit;
    }

    /// Append the entries other than `ignore` closer than `radius` (<= 2 cellSize) to x.
    void gather(const Vec3& x, Real radius, int ignore, std::vector<Vec3>& out) const
    {
        const Real r2 = radius * radius;
        visit(x, radius, [&](int id) {
            if (id != ignore && (mPos[id] - x).lengthSqr() < r2) out.push_back(mPos[id]);
            return true;
        });
    }

private:
    /// Call fn(id) for entries in the cells a ball of `radius` about x touches, until fn
    /// returns false.
    template <typename Fn>
    void visit(const Vec3& x, Real radius, Fn&& fn) const
    {
        std::int64_t lo[3], hi[3];
        mCells.range(x, radius, lo, hi);
        for (std::int64_t k = lo[2]; k <= hi[2]; ++k) {
            for (std::int64_t j = lo[1]; j <= hi[1]; ++j) {
                const std::int64_t row = mCells.row(j, k);
                for (std::int64_t i = lo[0]; i <= hi[0]; ++i) {
                    for (int id = mHead[row + i]; id >= 0; id = mNext[id]) {
                        if (!fn(id)) return;
                    }
                }
            }
        }
    }

    CellLattice mCells;
    std::vector<int> mHead;
    std::vector<int> mNext;
    std::vector<std::int64_t> mCell;
    std::vector<Vec3> mPos;
};

/// Grid bounds for sampling a level set: its active band, padded by one search cell.
inline Aabb samplingBounds(const LevelSet& shape, Real radius)
{
    return shape.bounds().padded(radius);
}

/// The band limit of solids ([SB12] Sec. 4.5): keep samples within `depth` of the surface.
/// Where the level set's narrow band is deeper than `depth`, phi decides. Otherwise phi is
/// clamped before that depth (OpenVDB's default band is 3 voxels, often thinner than a kernel
/// radius), and the distance to the nearest surface sample decides instead; samples lie about
/// r apart, so the band is then between `depth` and `depth + r/2` thick.
class DepthLimit
{
public:
    DepthLimit(const SampleSet& samples, const LevelSet& shape, Real depth, Real radius)
        : mDepth(depth)
    {
        if (!std::isfinite(depth)) {
            mMode = Mode::None;
        } else if (depth < shape.bandWidth() - shape.voxelSize()) {
            mMode = Mode::Phi;
        } else {
            mMode = Mode::SurfaceSamples;
            mReach = depth + Real(0.5) * radius;
            mSurface = std::make_unique<PointGrid>(samplingBounds(shape, radius), mReach);
            for (std::size_t i = 0; i < samples.size(); ++i) {
                if (samples.onSurface[i] && mSurface->contains(samples.positions[i])) {
                    mSurface->add(samples.positions[i]);
                }
            }
        }
    }

    bool limited() const { return mMode != Mode::None; }

    /// Whether x (with level-set value phi) is within the band.
    bool accepts(const Vec3& x, Real phi) const
    {
        Vec3 hint(std::numeric_limits<Real>::max());
        return accepts(
            x, [phi] { return phi; }, hint);
    }

    /// Whether x is within the band; `phiOf()` gives phi(x) and is called only when the band
    /// is set by phi. `hint` is a surface sample found within reach by an earlier call (or far
    /// away): the surface samples never move, so when x is within reach of it the answer is
    /// known without a search, and a search that finds one stores it there. The answer is
    /// the same with any hint.
    template <typename PhiOf>
    bool accepts(const Vec3& x, PhiOf&& phiOf, Vec3& hint) const
    {
        switch (mMode) {
        case Mode::None:
            return true;
        case Mode::Phi:
            return phiOf() >= -mDepth;
        case Mode::SurfaceSamples:
            if ((hint - x).lengthSqr() < mReach * mReach) return true;
            return mSurface->findWithin(x, mReach, hint);
        }
        return true;
    }

private:
    enum class Mode { None, Phi, SurfaceSamples };
    Mode mMode = Mode::None;
    Real mDepth = 0, mReach = 0;
    std::unique_ptr<PointGrid> mSurface;
};

} // namespace detail
} // namespace sph
} // namespace ghostfx
