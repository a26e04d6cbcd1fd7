/// @file   Readers.h
/// @brief  Read back what ghostfx writes: every attribute of a points .vdb (PointDataGrid) as
///         columns, a volume grid as a dense array or as its active voxels.
/// @details The readers take any .vdb, not only ghostfx's: point grids with attributes of any
///          registered value type and codec (float, double, int8 to int64, bool, vec3s/d/i...),
///          and volume grids of float, double, int32, int64, bool, vec3s, vec3d or vec3i values.
///          Values are returned in the type they are stored in (a vec3s attribute as float32
///          triples, an int64 as int64), except positions "P", which are returned in world space
///          as float64 (OpenVDB stores them as offsets from their voxel's centre; the world
///          position is computed in double from the voxel and the offset, so it adds no rounding
///          to the stored float offset).
///          Points come in the tree's order (leaf by leaf, each leaf's points in their index
///          order); every column follows that order, so row r of every column is one point.
///          Errors are one line naming the file and the grid: IoError for a file that is missing
///          or not a readable .vdb, GridError for a grid that is not there or of another kind.
#pragma once

#include <openvdb/Grid.h>

#include <array>
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace ghostfx {
namespace vdbio {

/// The element type of a column's values in memory.
enum class ScalarType { Bool, Int8, Int16, Int32, Int64, UInt8, UInt16, UInt32, UInt64, Float32, Float64 };

/// "bool", "int8", ..., "float32", "float64" (NumPy's names).
const char* scalarTypeName(ScalarType type);
/// Bytes of one element.
std::size_t scalarTypeSize(ScalarType type);

/// One named array of `rows` x `components` values of one scalar type, row-major.
struct Column
{
    std::string name;
    std::string storedType;      ///< as OpenVDB stores it: value type and codec, "vec3s (null)"
    ScalarType scalar = ScalarType::Float32;
    int components = 1;          ///< 1 for scalars, 3 for vectors
    std::size_t rows = 0;
    std::vector<unsigned char> bytes; ///< rows * components elements of `scalar`

    /// Element (row, component) converted to double.
    double value(std::size_t row, int component) const;
    template <typename T>
    T* data() { return reinterpret_cast<T*>(bytes.data()); }
    template <typename T>
    const T* data() const { return reinterpret_cast<const T*>(bytes.data()); }
};

/// Per-component minimum, maximum and mean of a column (each `components` long; NaN where the
/// column has no rows).
struct ColumnRange
{
    std::vector<double> min, max, mean;
};
ColumnRange columnRange(const Column& column);

/// Every attribute of one point grid, as columns of equal length.
struct PointsData
{
    std::string grid;            ///< the grid's name
    std::size_t count = 0;       ///< points (rows of every column)
    double voxelSize = 0;        ///< m (x axis of the transform)
    /// "P" first (world space, float64), then the others in storage order, then the groups;
    /// a grid without points has no attribute list: only an empty "P"
    std::vector<Column> columns;
};

/// The point grid `grid` of `file` (empty: the file's first point grid). `context` starts every
/// error message ("read_points", "ghostfx info"...).
PointsData readPoints(const std::string& file, const std::string& grid, const std::string& context);

/// The columns of a point grid already in memory (`grid` must be a PointDataGrid).
PointsData readPointsGrid(const openvdb::GridBase& grid, const std::string& context);

/// What a volume reader returns besides the values.
struct VolumeHeader
{
    std::string grid;
    std::string valueType;  ///< OpenVDB's name: "float", "vec3s", ...
    std::string gridClass;  ///< "level set", "fog volume", "staggered", "unknown"
    std::array<double, 3> voxelSize{};
    std::array<double, 16> indexToWorld{}; ///< row-major 4x4: world = [i j k 1] * M (row vectors)
    Column background;      ///< one row, the grid's type
    /// The grid's own metadata (not OpenVDB's name, class and file_* statistics): name, value
    /// type name ("float", "int64", "string"...) and the value as text.
    struct Meta
    {
        std::string name, type, text;
    };
    std::vector<Meta> metadata;
};

/// The values over the active voxels' index bounding box: values[i][j][k] (x slowest, z
/// fastest; vectors add a last axis of 3) at grid index indexMin + (i, j, k). Voxels inside the
/// box but inactive hold what the grid holds there (the background, or a level set's inside).
struct DenseVolume
{
    VolumeHeader header;
    std::array<int, 3> indexMin{};  ///< grid index of values[0][0][0]
    std::array<int, 3> dims{};      ///< 0 0 0 for a grid without active voxels
    std::array<double, 3> origin{}; ///< world position (m) of values[0][0][0]
    Column values;                  ///< dims product rows
};

/// The active voxels, active tiles expanded to their voxels, in the tree's order.
struct ActiveVoxels
{
    VolumeHeader header;
    std::vector<std::array<int, 3>> ijk;      ///< grid index of each voxel
    std::vector<std::array<double, 3>> world; ///< world position (m) of each voxel's centre
    Column values;                            ///< one row per voxel
};

/// The volume grid `grid` of `file`. GridError for a point grid or an unsupported value type.
DenseVolume readDenseVolume(const std::string& file, const std::string& grid,
                            const std::string& context);
ActiveVoxels readActiveVoxels(const std::string& file, const std::string& grid,
                              const std::string& context);

} // namespace vdbio
} // namespace ghostfx
