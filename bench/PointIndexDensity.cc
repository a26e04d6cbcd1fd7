/// @file   PointIndexDensity.cc
/// @brief  The only translation unit that instantiates tools::PointIndexGrid (build and
///         PointIndexIterator queries) for bench_neighbors.
#include "PointIndexDensity.h"

#include "ghostfx/sph/EnumNames.h"
#include "ghostfx/sph/Parallel.h"

#include <openvdb/tools/PointIndexGrid.h>

#include <atomic>

namespace ghostfx {
namespace bench {

namespace {

using sph::Real;
using sph::Vec3;

/// PointArray interface of tools::createPointIndexGrid over a plain position array.
struct PositionArray
{
    using PosType = Vec3;

    const Vec3* data = nullptr;
    std::size_t count = 0;

    std::size_t size() const { return count; }
    void getPos(std::size_t n, PosType& x) const { x = data[n]; }
};

using Grid = openvdb::tools::PointIndexGrid;
using Tree = Grid::TreeType;
using Iterator = openvdb::tools::PointIndexIterator<Tree>;

/// Particles a task processes with one accessor and one iterator.
constexpr std::size_t GRAIN = parallel::DEFAULT_GRAIN;

} // namespace

const char* queryName(PointIndexQuery query)
{
    static const sph::EnumName<PointIndexQuery> names[] = {
        {PointIndexQuery::BoxThenDistance, "box+distance"},
        {PointIndexQuery::RadialSubvoxel, "radial(subvoxel)"}};
    return sph::nameOf(names, query);
}

struct PointIndexDensity::Impl
{
    PositionArray points;
    Grid::Ptr grid;

    /// Call fn(j, r) for every j with |x_i - x_j| < radius, using `it` and `acc` of the task.
    template <typename Fn>
    void forEachNeighbor(std::size_t i, Real radius, PointIndexQuery query, Iterator& it,
                         Iterator::ConstAccessor& acc, Fn&& fn) const
    {
        const Vec3& x = points.data[i];
        const openvdb::math::Transform& xform = grid->transform();
        if (query == PointIndexQuery::BoxThenDistance) {
            const openvdb::Vec3d lo(x[0] - radius, x[1] - radius, x[2] - radius);
            const openvdb::Vec3d hi(x[0] + radius, x[1] + radius, x[2] + radius);
            it.searchAndUpdate(openvdb::CoordBBox(xform.worldToIndexCellCentered(lo),
                                                  xform.worldToIndexCellCentered(hi)),
                               acc);
        } else {
            it.worldSpaceSearchAndUpdate(openvdb::Vec3d(x), double(radius), acc, points, xform,
                                         /*subvoxelAccuracy=*/true);
        }
        const Real radius2 = radius * radius;
        for (; it; ++it) {
            const std::size_t j = *it;
            const Vec3 xij = x - points.data[j];
            const Real r2 = xij.lengthSqr();
            if (r2 < radius2) fn(j, std::sqrt(r2));
        }
    }
};

PointIndexDensity::PointIndexDensity(double voxelSize)
    : mVoxelSize(voxelSize)
    , mImpl(std::make_unique<Impl>())
{}

PointIndexDensity::~PointIndexDensity() = default;

void PointIndexDensity::build(const Vec3* positions, std::size_t count)
{
    mImpl->points = PositionArray{positions, count};
    mImpl->grid = openvdb::tools::createPointIndexGrid<Grid>(mImpl->points, mVoxelSize);
}

std::size_t PointIndexDensity::memoryBytes() const
{
    return mImpl->grid ? std::size_t(mImpl->grid->memUsage()) : 0;
}

void PointIndexDensity::density(const sph::CubicSplineKernel& kernel, const Real* mass, Real* rho,
                                PointIndexQuery query) const
{
    const Impl& impl = *mImpl;
    const Real radius = kernel.supportRadius();
    parallel::forRange(
        0, impl.points.count,
        [&](std::size_t begin, std::size_t end) {
        Iterator::ConstAccessor acc(impl.grid->constTree());
        Iterator it;
        for (std::size_t i = begin; i < end; ++i) {
            Real sum = 0;
            impl.forEachNeighbor(i, radius, query, it, acc,
                                 [&](std::size_t j, Real r) { sum += mass[j] * kernel.W(r); });
            rho[i] = sum;
        }
        },
        GRAIN);
}

std::uint64_t PointIndexDensity::countPairs(Real radius) const
{
    const Impl& impl = *mImpl;
    std::atomic<std::uint64_t> total{0};
    parallel::forRange(
        0, impl.points.count,
        [&](std::size_t begin, std::size_t end) {
        Iterator::ConstAccessor acc(impl.grid->constTree());
        Iterator it;
        std::uint64_t pairs = 0;
        for (std::size_t i = begin; i < end; ++i) {
            impl.forEachNeighbor(i, radius, PointIndexQuery::BoxThenDistance, it, acc,
                                 [&](std::size_t, Real) { ++pairs; });
        }
        total.fetch_add(pairs, std::memory_order_relaxed);
        },
        GRAIN);
    return total.load();
}

} // namespace bench
} // namespace ghostfx
