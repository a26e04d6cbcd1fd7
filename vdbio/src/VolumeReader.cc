/// @file   VolumeReader.cc
/// @brief  A volume grid of a .vdb read back as a dense array over its active box, or as its
///         active voxels; see Readers.h.
#include "ReadersDetail.h"

#include <ghostfx/sph/Exceptions.h>
#include <ghostfx/sph/Parallel.h>

#include <openvdb/points/PointDataGrid.h>

#include <utility>

namespace ghostfx {
namespace vdbio {

namespace {

using detail::makeColumn;
using detail::scalarOf;
using detail::Tag;
using detail::ValueTraits;

/// Calls f(grid) with `base` cast to its grid type; false for a type not read here.
template <typename F>
bool withGridType(const openvdb::GridBase& base, F&& f)
{
    bool found = false;
    auto test = [&](auto tag) {
        using GridT = typename decltype(tag)::type;
        if (!found && base.isType<GridT>()) {
            found = true;
            f(static_cast<const GridT&>(base));
        }
    };
    test(Tag<openvdb::FloatGrid>{}), test(Tag<openvdb::DoubleGrid>{});
    test(Tag<openvdb::Int32Grid>{}), test(Tag<openvdb::Int64Grid>{});
    test(Tag<openvdb::BoolGrid>{}), test(Tag<openvdb::Vec3SGrid>{});
    test(Tag<openvdb::Vec3DGrid>{}), test(Tag<openvdb::Vec3IGrid>{});
    return found;
}

template <typename V>
Column columnOf(const std::string& name, const std::string& valueType, std::size_t rows)
{
    using Traits = ValueTraits<V>;
    return makeColumn(name, valueType, scalarOf<typename Traits::Element>(), Traits::components,
                      rows);
}

template <typename V>
void store(Column& column, std::size_t row, const V& value)
{
    using Traits = ValueTraits<V>;
    using E = typename Traits::Element;
    for (int c = 0; c < Traits::components; ++c)
        column.data<E>()[row * Traits::components + c] = Traits::get(value, c);
}

bool isVolumeGrid(const openvdb::GridBase& g) { return !g.isType<openvdb::points::PointDataGrid>(); }

/// The grid `grid` of `file`, refused (GridError) if it is a point grid or not linear.
openvdb::GridBase::Ptr volumeGrid(const std::string& file, const std::string& grid,
                                  const std::string& context)
{
    openvdb::GridBase::Ptr base = detail::readGridOf(file, grid, context, "volume grid", isVolumeGrid);
    if (!isVolumeGrid(*base)) {
        throw GridError(msg(context, ": grid '", grid, "' in '", file,
                            "' is a point grid, expected a volume (read its points instead)"));
    }
    if (!base->transform().isLinear()) {
        throw GridError(msg(context, ": grid '", grid, "' in '", file, "' has a ",
                            base->transform().mapType(), " transform, expected a linear one"));
    }
    return base;
}

template <typename GridT>
VolumeHeader headerOf(const GridT& grid)
{
    VolumeHeader h;
    h.grid = grid.getName();
    h.valueType = grid.valueType();
    h.gridClass = openvdb::GridBase::gridClassToString(grid.getGridClass());
    const openvdb::Vec3d voxel = grid.voxelSize();
    h.voxelSize = {voxel.x(), voxel.y(), voxel.z()};
    const openvdb::Mat4d m = grid.transform().baseMap()->getAffineMap()->getMat4();
    for (int r = 0; r < 4; ++r) {
        for (int c = 0; c < 4; ++c) h.indexToWorld[std::size_t(4 * r + c)] = m(r, c);
    }
    h.background = columnOf<typename GridT::ValueType>("background", h.valueType, 1);
    store(h.background, 0, grid.background());
    for (auto it = grid.beginMeta(); it != grid.endMeta(); ++it) {
        const std::string& key = it->first;
        if (key == openvdb::GridBase::META_GRID_NAME || key == openvdb::GridBase::META_GRID_CLASS
            || key.rfind("file_", 0) == 0) {
            continue;
        }
        h.metadata.push_back({key, it->second->typeName(), it->second->str()});
    }
    return h;
}

template <typename GridT>
DenseVolume denseOf(const GridT& grid)
{
    DenseVolume out;
    out.header = headerOf(grid);
    const openvdb::CoordBBox box = grid.evalActiveVoxelBoundingBox();
    const openvdb::Coord dim = box.empty() ? openvdb::Coord(0) : box.dim();
    const openvdb::Coord lo = box.empty() ? openvdb::Coord(0) : box.min();
    out.indexMin = {lo.x(), lo.y(), lo.z()};
    out.dims = {dim.x(), dim.y(), dim.z()};
    const openvdb::Vec3d o = grid.transform().indexToWorld(lo);
    out.origin = {o.x(), o.y(), o.z()};
    const std::size_t ny = std::size_t(dim.y()), nz = std::size_t(dim.z());
    out.values = columnOf<typename GridT::ValueType>("values", out.header.valueType,
                                                     std::size_t(dim.x()) * ny * nz);
    parallel::forEach(
        0, std::size_t(dim.x()),
        [&](std::size_t i) {
        auto acc = grid.getConstAccessor(); // one per slab: accessors are not shared
        for (std::size_t j = 0; j < ny; ++j) {
            for (std::size_t k = 0; k < nz; ++k) {
                const openvdb::Coord ijk = lo + openvdb::Coord(int(i), int(j), int(k));
                store(out.values, (i * ny + j) * nz + k, acc.getValue(ijk));
            }
        }
        },
        1);
    return out;
}

template <typename GridT>
ActiveVoxels activeOf(const GridT& grid)
{
    ActiveVoxels out;
    out.header = headerOf(grid);
    std::vector<typename GridT::ValueType> values;
    for (auto it = grid.cbeginValueOn(); it; ++it) {
        const openvdb::CoordBBox box = it.getBoundingBox(); // one voxel, or a tile's voxels
        for (auto ijk = box.begin(); ijk; ++ijk) {
            out.ijk.push_back({(*ijk).x(), (*ijk).y(), (*ijk).z()});
            const openvdb::Vec3d w = grid.transform().indexToWorld(*ijk);
            out.world.push_back({w.x(), w.y(), w.z()});
            values.push_back(*it);
        }
    }
    out.values = columnOf<typename GridT::ValueType>("values", out.header.valueType, values.size());
    for (std::size_t r = 0; r < values.size(); ++r) store(out.values, r, values[r]);
    return out;
}

[[noreturn]] void unsupported(const openvdb::GridBase& base, const std::string& file,
                              const std::string& context)
{
    throw GridError(msg(context, ": grid '", base.getName(), "' in '", file, "' holds ",
                        base.valueType(),
                        " values, expected float, double, int32, int64, bool, vec3s, vec3d or "
                        "vec3i"));
}

} // namespace

DenseVolume readDenseVolume(const std::string& file, const std::string& grid,
                            const std::string& context)
{
    const openvdb::GridBase::Ptr base = volumeGrid(file, grid, context);
    DenseVolume out;
    if (!withGridType(*base, [&](const auto& g) { out = denseOf(g); })) {
        unsupported(*base, file, context);
    }
    return out;
}

ActiveVoxels readActiveVoxels(const std::string& file, const std::string& grid,
                              const std::string& context)
{
    const openvdb::GridBase::Ptr base = volumeGrid(file, grid, context);
    ActiveVoxels out;
    if (!withGridType(*base, [&](const auto& g) { out = activeOf(g); })) {
        unsupported(*base, file, context);
    }
    return out;
}

} // namespace vdbio
} // namespace ghostfx
