/// @file   Readers.cc
/// @brief  Points (PointDataGrid attributes) and volumes (dense or active voxels) read back from
///         .vdb files into typed columns; see Readers.h.
/// @details Attributes are read through points::AttributeHandle<T> of the attribute's value type,
///          which decodes any codec of that type (null, truncate, fixed point, unit vector), so
///          every value comes back as the float, vector or integer it stands for. Only this
///          translation unit and PointsFile.cc instantiate the points templates (STACK.md).
#include "ReadersDetail.h"

#include <ghostfx/sph/Exceptions.h>
#include <ghostfx/sph/Parallel.h>

#include <openvdb/io/File.h>
#include <openvdb/openvdb.h>
#include <openvdb/points/AttributeArray.h>
#include <openvdb/points/PointDataGrid.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <limits>
#include <type_traits>
#include <utility>

namespace ghostfx {
namespace vdbio {

namespace {

using openvdb::points::PointDataGrid;
using openvdb::points::PointDataTree;
using detail::makeColumn;
using detail::scalarOf;
using detail::Tag;
using detail::ValueTraits;

/// Calls f(Tag<V>{}) for the attribute value type named `type` (OpenVDB's names); false if none.
template <typename F>
bool withAttributeType(const std::string& type, F&& f)
{
    bool found = false;
    auto test = [&](auto tag) {
        using V = typename decltype(tag)::type;
        if (!found && type == openvdb::typeNameAsString<V>()) {
            found = true;
            f(tag);
        }
    };
    test(Tag<float>{}), test(Tag<double>{}), test(Tag<std::int32_t>{}), test(Tag<std::int64_t>{});
    test(Tag<openvdb::Vec3f>{}), test(Tag<openvdb::Vec3d>{}), test(Tag<openvdb::Vec3i>{});
    test(Tag<bool>{}), test(Tag<std::int8_t>{}), test(Tag<std::int16_t>{});
    test(Tag<std::uint8_t>{}), test(Tag<std::uint16_t>{}), test(Tag<std::uint32_t>{});
    test(Tag<std::uint64_t>{});
    return found;
}

const char* const SUPPORTED_ATTRIBUTE_TYPES =
    "float, double, int8 to int64, uint8 to uint64, bool, vec3s, vec3d or vec3i";

// ------------------------------------------------------------------------------------------
// files
// ------------------------------------------------------------------------------------------

std::string gridList(const openvdb::GridPtrVec& grids)
{
    std::string names;
    for (const auto& g : grids) {
        names += msg(names.empty() ? "" : ", ", "'", g->getName(), "' (", g->valueType(), ")");
    }
    return names.empty() ? std::string("none") : names;
}

/// Open `file`: IoError naming it if it is missing or not a readable .vdb.
void openVdb(openvdb::io::File& vdb, const std::string& file, const std::string& context)
{
    std::error_code ec;
    if (!std::filesystem::exists(file, ec)) {
        throw IoError(msg(context, ": file '", file, "' does not exist"));
    }
    try {
        vdb.open(/*delayLoad=*/false);
    } catch (const openvdb::Exception& e) {
        throw IoError(
            msg(context, ": file '", file, "' is not a readable .vdb file (", e.what(), ")"));
    }
}

} // namespace

openvdb::GridBase::Ptr detail::readGridOf(const std::string& file, const std::string& grid,
                                  const std::string& context, const char* wanted,
                                  bool (*accept)(const openvdb::GridBase&))
{
    openvdb::io::File vdb(file);
    openvdb::GridPtrVecPtr descriptors;
    openvdb::GridBase::Ptr base;
    openVdb(vdb, file, context);
    descriptors = vdb.readAllGridMetadata();
    std::string name = grid;
    for (const auto& d : *descriptors) {
        if (name.empty() && accept(*d)) name = d->getName();
    }
    const bool found = !name.empty() && vdb.hasGrid(name);
    try {
        if (found) base = vdb.readGrid(name);
    } catch (const openvdb::Exception& e) {
        vdb.close();
        throw IoError(
            msg(context, ": grid '", name, "' in '", file, "' cannot be read (", e.what(), ")"));
    }
    vdb.close();
    if (!found && grid.empty()) {
        throw GridError(msg(context, ": file '", file, "' has no ", wanted,
                            " (grids: ", gridList(*descriptors), ")"));
    }
    if (!found) {
        throw GridError(msg(context, ": file '", file, "' has no grid '", grid,
                            "' (grids: ", gridList(*descriptors), ")"));
    }
    return base;
}

Column detail::makeColumn(std::string name, std::string storedType, ScalarType scalar,
                          int components, std::size_t rows)
{
    Column c;
    c.name = std::move(name);
    c.storedType = std::move(storedType);
    c.scalar = scalar;
    c.components = components;
    c.rows = rows;
    c.bytes.resize(rows * std::size_t(components) * scalarTypeSize(scalar));
    return c;
}

namespace {

bool isPointGrid(const openvdb::GridBase& g) { return g.isType<PointDataGrid>(); }

// ------------------------------------------------------------------------------------------
// points
// ------------------------------------------------------------------------------------------

/// A leaf and the row of its first point.
struct LeafRows
{
    const PointDataTree::LeafNodeType* leaf;
    std::size_t first;
};

std::vector<LeafRows> leafRows(const PointDataTree& tree, std::size_t& count)
{
    std::vector<LeafRows> leaves;
    count = 0;
    for (auto leaf = tree.cbeginLeaf(); leaf; ++leaf) {
        leaves.push_back({&*leaf, count});
        count += std::size_t(leaf->pointCount());
    }
    return leaves;
}

/// Attribute `position` of every leaf as a column of its value type V.
template <typename V>
Column attributeColumn(const std::vector<LeafRows>& leaves, std::size_t count, std::size_t position,
                       const std::string& name, const std::string& storedType)
{
    using Traits = ValueTraits<V>;
    using E = typename Traits::Element;
    constexpr int N = Traits::components;
    Column column = makeColumn(name, storedType, scalarOf<E>(), N, count);
    E* out = column.data<E>();
    parallel::forEach(
        0, leaves.size(),
        [&](std::size_t l) {
        const auto& leaf = *leaves[l].leaf;
        const openvdb::points::AttributeHandle<V> handle(leaf.constAttributeArray(position));
        const std::size_t n = std::size_t(leaf.pointCount());
        for (std::size_t i = 0; i < n; ++i) {
            const V v = handle.get(openvdb::Index(i));
            for (int c = 0; c < N; ++c) out[(leaves[l].first + i) * N + c] = Traits::get(v, c);
        }
        },
        1);
    return column;
}

/// "P" in world space (float64): each point's voxel plus its stored offset, through the transform.
template <typename V>
Column worldPositions(const std::vector<LeafRows>& leaves, std::size_t count, std::size_t position,
                      const openvdb::math::Transform& xform, const std::string& storedType)
{
    Column column = makeColumn("P", storedType, ScalarType::Float64, 3, count);
    double* out = column.data<double>();
    parallel::forEach(
        0, leaves.size(),
        [&](std::size_t l) {
        const auto& leaf = *leaves[l].leaf;
        const openvdb::points::AttributeHandle<V> handle(leaf.constAttributeArray(position));
        openvdb::Index start = 0;
        for (openvdb::Index voxel = 0; voxel < PointDataTree::LeafNodeType::SIZE; ++voxel) {
            const openvdb::Index end = leaf.getValue(voxel);
            const openvdb::Vec3d ijk = leaf.offsetToGlobalCoord(voxel).asVec3d();
            for (openvdb::Index i = start; i < end; ++i) {
                const openvdb::Vec3d w = xform.indexToWorld(ijk + openvdb::Vec3d(handle.get(i)));
                for (int c = 0; c < 3; ++c) out[(leaves[l].first + i) * 3 + c] = w[c];
            }
            start = end;
        }
        },
        1);
    return column;
}

/// Every group of the points as a bool column "group:<name>".
void addGroupColumns(PointsData& data, const std::vector<LeafRows>& leaves,
                     const openvdb::points::AttributeSet::Descriptor& descriptor)
{
    for (const auto& [groupName, index] : descriptor.groupMap()) {
        (void)index;
        Column column = makeColumn("group:" + groupName, "group", ScalarType::Bool, 1, data.count);
        bool* out = column.data<bool>();
        parallel::forEach(
            0, leaves.size(),
            [&, name = groupName](std::size_t l) {
            const auto handle = leaves[l].leaf->groupHandle(name);
            const std::size_t n = std::size_t(leaves[l].leaf->pointCount());
            for (std::size_t i = 0; i < n; ++i)
                out[leaves[l].first + i] = handle.get(openvdb::Index(i));
            },
            1);
        data.columns.push_back(std::move(column));
    }
}

/// One attribute (other than a group array) as a column; GridError for an unsupported type.
Column attributeOf(const PointDataGrid& grid, const std::vector<LeafRows>& leaves,
                   std::size_t count, std::size_t position, const std::string& name,
                   const openvdb::NamePair& type, const std::string& context)
{
    const std::string stored = msg(type.first, " (", type.second, ")");
    Column column;
    const bool known = withAttributeType(type.first, [&](auto tag) {
        using V = typename decltype(tag)::type;
        if constexpr (ValueTraits<V>::components == 3 && std::is_floating_point_v<
                                                              typename ValueTraits<V>::Element>) {
            if (name == "P") {
                column = worldPositions<V>(leaves, count, position, grid.transform(), stored);
                return;
            }
        }
        column = attributeColumn<V>(leaves, count, position, name, stored);
    });
    if (!known) {
        throw GridError(msg(context, ": attribute '", name, "' of point grid '", grid.getName(),
                            "' holds ", type.first, " values, expected ",
                            SUPPORTED_ATTRIBUTE_TYPES));
    }
    return column;
}

} // namespace

// ------------------------------------------------------------------------------------------
// columns
// ------------------------------------------------------------------------------------------

const char* scalarTypeName(ScalarType type)
{
    switch (type) {
    case ScalarType::Bool: return "bool";
    case ScalarType::Int8: return "int8";
    case ScalarType::Int16: return "int16";
    case ScalarType::Int32: return "int32";
    case ScalarType::Int64: return "int64";
    case ScalarType::UInt8: return "uint8";
    case ScalarType::UInt16: return "uint16";
    case ScalarType::UInt32: return "uint32";
    case ScalarType::UInt64: return "uint64";
    case ScalarType::Float32: return "float32";
    case ScalarType::Float64: return "float64";
    }
    return "?";
}

std::size_t scalarTypeSize(ScalarType type)
{
    switch (type) {
    case ScalarType::Bool:
    case ScalarType::Int8:
    case ScalarType::UInt8: return 1;
    case ScalarType::Int16:
    case ScalarType::UInt16: return 2;
    case ScalarType::Int32:
    case ScalarType::UInt32:
    case ScalarType::Float32: return 4;
    default: return 8;
    }
}

double Column::value(std::size_t row, int component) const
{
    const std::size_t k = row * std::size_t(components) + std::size_t(component);
    switch (scalar) {
    case ScalarType::Bool: return data<bool>()[k] ? 1.0 : 0.0;
    case ScalarType::Int8: return double(data<std::int8_t>()[k]);
    case ScalarType::Int16: return double(data<std::int16_t>()[k]);
    case ScalarType::Int32: return double(data<std::int32_t>()[k]);
    case ScalarType::Int64: return double(data<std::int64_t>()[k]);
    case ScalarType::UInt8: return double(data<std::uint8_t>()[k]);
    case ScalarType::UInt16: return double(data<std::uint16_t>()[k]);
    case ScalarType::UInt32: return double(data<std::uint32_t>()[k]);
    case ScalarType::UInt64: return double(data<std::uint64_t>()[k]);
    case ScalarType::Float32: return double(data<float>()[k]);
    case ScalarType::Float64: return data<double>()[k];
    }
    return 0.0;
}

ColumnRange columnRange(const Column& column)
{
    const std::size_t n = std::size_t(column.components);
    ColumnRange r;
    r.min.assign(n, std::numeric_limits<double>::quiet_NaN());
    r.max = r.min;
    r.mean = r.min;
    for (std::size_t c = 0; c < n && column.rows > 0; ++c) {
        double lo = column.value(0, int(c)), hi = lo, sum = 0.0;
        for (std::size_t row = 0; row < column.rows; ++row) {
            const double v = column.value(row, int(c));
            lo = std::min(lo, v);
            hi = std::max(hi, v);
            sum += v;
        }
        r.min[c] = lo;
        r.max[c] = hi;
        r.mean[c] = sum / double(column.rows);
    }
    return r;
}

// ------------------------------------------------------------------------------------------
// points
// ------------------------------------------------------------------------------------------

PointsData readPointsGrid(const openvdb::GridBase& base, const std::string& context)
{
    const auto* grid = dynamic_cast<const PointDataGrid*>(&base);
    if (!grid) {
        throw GridError(msg(context, ": grid '", base.getName(), "' holds ", base.valueType(),
                            " values, expected a point grid (PointDataGrid)"));
    }
    PointsData data;
    data.grid = grid->getName();
    data.voxelSize = grid->voxelSize().x();
    const std::vector<LeafRows> leaves = leafRows(grid->tree(), data.count);
    if (leaves.empty()) { // no points: no attribute descriptor, only an empty "P"
        data.columns.push_back(makeColumn("P", "vec3s", ScalarType::Float64, 3, 0));
        return data;
    }
    const auto& descriptor = leaves.front().leaf->attributeSet().descriptor();
    std::vector<std::pair<std::size_t, std::string>> byPosition;
    for (const auto& entry : descriptor.map()) byPosition.emplace_back(entry.second, entry.first);
    std::sort(byPosition.begin(), byPosition.end());
    for (const auto& [position, name] : byPosition) {
        const openvdb::NamePair& type = descriptor.type(position);
        if (type.second == openvdb::points::GroupCodec::name()) continue; // groups: below
        Column column = attributeOf(*grid, leaves, data.count, position, name, type, context);
        if (name == "P") data.columns.insert(data.columns.begin(), std::move(column));
        else data.columns.push_back(std::move(column));
    }
    addGroupColumns(data, leaves, descriptor);
    return data;
}

PointsData readPoints(const std::string& file, const std::string& grid, const std::string& context)
{
    const openvdb::GridBase::Ptr base = detail::readGridOf(file, grid, context, "point grid", isPointGrid);
    if (!isPointGrid(*base)) {
        throw GridError(msg(context, ": grid '", grid, "' in '", file, "' holds ",
                            base->valueType(), " values, expected a point grid (PointDataGrid)"));
    }
    return readPointsGrid(*base, msg(context, ": '", file, "'"));
}

} // namespace vdbio
} // namespace ghostfx
