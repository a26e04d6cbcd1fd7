/// @file   Info.cc
/// @brief  describeFile(): .vdb grids and points, and a generic walk of HDF5 files.
#include <ghostfx/vdbio/Info.h>

#include <ghostfx/sph/Exceptions.h>
#include <ghostfx/vdbio/AtomicFile.h>
#include <ghostfx/vdbio/Readers.h>

#include <openvdb/io/File.h>
#include <openvdb/points/PointCount.h>
#include <openvdb/points/PointDataGrid.h>
#include <openvdb/tools/Statistics.h>

#include <H5Cpp.h>

#include <algorithm>
#include <cstdint>
#include <filesystem>
#include <iomanip>
#include <limits>
#include <sstream>
#include <vector>

namespace ghostfx {
namespace vdbio {

namespace fs = std::filesystem;

namespace {

// Attribute arrays longer than this are summarised by their shape, not printed.
constexpr std::size_t MAX_PRINTED_VALUES = 8;
// Longer string attributes (settings as JSON text...) are cut here.
constexpr std::size_t MAX_PRINTED_CHARACTERS = 200;
// String-array attributes (column names...) with at most this many elements are printed.
constexpr std::size_t MAX_PRINTED_STRINGS = 32;
// HDF5 groups deeper than this are not entered (guards against hard-link cycles).
constexpr int MAX_GROUP_DEPTH = 32;
constexpr double BYTES_PER_MB = 1.0e6;

/// File and dataset sizes: bytes, kB or MB, whichever reads best.
std::string sizeText(double bytes)
{
    std::ostringstream os;
    if (bytes < 1e4) os << bytes << " bytes";
    else if (bytes < 1e7) os << std::fixed << std::setprecision(1) << bytes / 1e3 << " kB";
    else os << std::fixed << std::setprecision(1) << bytes / BYTES_PER_MB << " MB";
    return os.str();
}

std::string megabytes(double bytes)
{
    std::ostringstream os;
    os << std::fixed << std::setprecision(bytes < 1e5 ? 4 : 2) << bytes / BYTES_PER_MB << " MB";
    return os.str();
}

// ------------------------------------------------------------------------------------------
// .vdb
// ------------------------------------------------------------------------------------------

bool isStatisticsKey(const std::string& key)
{
    // Written by io::File for every grid; the same facts are printed from the grid itself.
    return key.rfind("file_", 0) == 0;
}

void describeMetadata(std::ostream& os, const openvdb::MetaMap& meta, const std::string& indent,
                      bool skipBuiltIn)
{
    for (auto it = meta.beginMeta(); it != meta.endMeta(); ++it) {
        const std::string& key = it->first;
        if (skipBuiltIn
            && (key == openvdb::GridBase::META_GRID_NAME
                || key == openvdb::GridBase::META_GRID_CLASS || isStatisticsKey(key))) {
            continue;
        }
        os << indent << key << " (" << it->second->typeName() << "): " << it->second->str() << "\n";
    }
}

/// World box of the active voxels' extent (voxel centres +- half a voxel).
void worldBounds(const openvdb::GridBase& grid, const openvdb::CoordBBox& ibox,
                 openvdb::Vec3d& wmin, openvdb::Vec3d& wmax)
{
    const openvdb::Vec3d lo = ibox.min().asVec3d() - openvdb::Vec3d(0.5);
    const openvdb::Vec3d hi = ibox.max().asVec3d() + openvdb::Vec3d(0.5);
    wmin = openvdb::Vec3d(std::numeric_limits<double>::max());
    wmax = -wmin;
    for (int corner = 0; corner < 8; ++corner) {
        const openvdb::Vec3d c((corner & 1) ? hi.x() : lo.x(), (corner & 2) ? hi.y() : lo.y(),
                               (corner & 4) ? hi.z() : lo.z());
        const openvdb::Vec3d w = grid.transform().indexToWorld(c);
        wmin = openvdb::math::minComponent(wmin, w);
        wmax = openvdb::math::maxComponent(wmax, w);
    }
}

/// One component list: "1.5" for a scalar, "[1, 2, 3]" for a vector.
std::string components(const std::vector<double>& v)
{
    if (v.size() == 1) return msg(v[0]);
    std::string out;
    for (double x : v) out += (out.empty() ? "[" : ", ") + msg(x);
    return out + "]";
}

/// Per attribute (as vdbio::readPointsGrid returns it, P in world space): min .. max and the
/// mean of each component.
void describeRanges(std::ostream& os, const openvdb::points::PointDataGrid& grid)
{
    PointsData data;
    try {
        data = readPointsGrid(grid, "ghostfx info");
    } catch (const GridError& e) { // an attribute type the reader does not take
        os << "  attribute ranges: not read (" << e.what() << ")\n";
        return;
    }
    if (data.count == 0) return;
    os << "  attribute ranges (min .. max, mean; P in world space, m):\n";
    for (const Column& column : data.columns) {
        const ColumnRange r = columnRange(column);
        os << "    " << std::left << std::setw(14) << column.name << std::right << " "
           << components(r.min) << " .. " << components(r.max) << ", mean " << components(r.mean)
           << "\n";
    }
}

void describePoints(std::ostream& os, const openvdb::points::PointDataGrid& grid)
{
    const openvdb::Index64 count = openvdb::points::pointCount(grid.tree());
    os << "  points:          " << count << "\n";
    auto leaf = grid.tree().cbeginLeaf();
    if (!leaf) return;
    const openvdb::points::AttributeSet::Descriptor& descriptor = leaf->attributeSet().descriptor();
    // Attributes in their storage order, each with its value type, codec and stored bytes.
    std::vector<std::pair<std::size_t, std::string>> byPosition;
    for (const auto& entry : descriptor.map()) byPosition.emplace_back(entry.second, entry.first);
    std::sort(byPosition.begin(), byPosition.end());
    std::size_t bytesPerPoint = 0;
    os << "  attributes:\n";
    for (const auto& [position, name] : byPosition) {
        const openvdb::NamePair& type = descriptor.type(position);
        const openvdb::points::AttributeArray& array = leaf->constAttributeArray(position);
        const std::size_t bytes =
            std::size_t(array.storageTypeSize()) * std::max<openvdb::Index>(1, array.stride());
        bytesPerPoint += bytes;
        os << "    " << std::left << std::setw(14) << name << std::right << " " << type.first
           << " (codec " << type.second << ", " << bytes << " bytes)\n";
    }
    if (!descriptor.groupMap().empty()) {
        os << "  groups:         ";
        for (const auto& group : descriptor.groupMap()) os << " " << group.first;
        os << "\n";
    }
    os << "  bytes per point: " << bytesPerPoint << " in attributes";
    if (count > 0) {
        std::ostringstream perPoint; // own stream: keeps `os` at its default precision
        perPoint << std::fixed << std::setprecision(1) << double(grid.memUsage()) / double(count);
        os << ", " << perPoint.str() << " in memory with the tree";
    }
    os << "\n";
    describeRanges(os, grid);
}

void describeGrid(std::ostream& os, const openvdb::GridBase& grid)
{
    os << "grid '" << grid.getName() << "'\n";
    os << "  type:            " << grid.valueType() << " (" << grid.type() << ")\n";
    os << "  class:           " << openvdb::GridBase::gridClassToMenuName(grid.getGridClass())
       << "\n";
    const openvdb::Vec3d voxel = grid.voxelSize();
    os << "  voxel size:      ";
    if (grid.hasUniformVoxels()) os << voxel.x() << " m\n";
    else os << voxel << " m (non-uniform)\n";
    os << "  active voxels:   " << grid.activeVoxelCount() << "\n";
    const openvdb::CoordBBox ibox = grid.evalActiveVoxelBoundingBox();
    if (ibox.empty()) {
        os << "  world bounds:    empty\n";
    } else {
        openvdb::Vec3d wmin, wmax;
        worldBounds(grid, ibox, wmin, wmax);
        os << "  world bounds:    " << wmin << " .. " << wmax << " m (index " << ibox.min()
           << " .. " << ibox.max() << ")\n";
    }
    os << "  memory:          " << megabytes(double(grid.memUsage())) << "\n";
    if (const auto floatGrid = dynamic_cast<const openvdb::FloatGrid*>(&grid)) {
        os << "  background:      " << floatGrid->background() << "\n";
        if (grid.activeVoxelCount() > 0) {
            const auto range = openvdb::tools::minMax(floatGrid->tree());
            os << "  active values:   " << range.min() << " .. " << range.max() << "\n";
        }
    }
    if (const auto points = dynamic_cast<const openvdb::points::PointDataGrid*>(&grid)) {
        describePoints(os, *points);
    }
    std::ostringstream meta;
    describeMetadata(meta, grid, "    ", /*skipBuiltIn=*/true);
    if (!meta.str().empty()) os << "  metadata:\n" << meta.str();
}

std::string describeVdb(const std::string& path)
{
    openvdb::io::File file(path);
    openvdb::GridPtrVecPtr grids;
    openvdb::MetaMap::Ptr fileMeta;
    try {
        file.open(/*delayLoad=*/false);
        fileMeta = file.getMetadata();
        grids = file.getGrids();
    } catch (const openvdb::Exception& e) {
        throw IoError(msg("'", path, "': cannot read as a .vdb file (", e.what(), ")"));
    }
    std::ostringstream os;
    os << path << ": OpenVDB file, " << sizeText(double(fs::file_size(path)))
       << " on disk, file format " << file.fileVersion() << ", written by library "
       << file.libraryVersion().first << "." << file.libraryVersion().second << ", "
       << grids->size() << " grid(s)\n";
    file.close();
    if (fileMeta && fileMeta->metaCount() > 0) {
        os << "file metadata:\n";
        describeMetadata(os, *fileMeta, "  ", /*skipBuiltIn=*/false);
    }
    for (const auto& grid : *grids) describeGrid(os, *grid);
    return os.str();
}

// ------------------------------------------------------------------------------------------
// .h5
// ------------------------------------------------------------------------------------------

/// Element type in words: int32, uint8, float64, string, array [3] of float32, compound {...}.
std::string typeName(hid_t type)
{
    const std::size_t size = H5Tget_size(type);
    switch (H5Tget_class(type)) {
    case H5T_INTEGER:
        return msg(H5Tget_sign(type) == H5T_SGN_NONE ? "uint" : "int", 8 * size);
    case H5T_FLOAT:
        return msg("float", 8 * size);
    case H5T_STRING:
        return H5Tis_variable_str(type) > 0 ? std::string("string") : msg("string[", size, "]");
    case H5T_BITFIELD:
        return msg("bitfield", 8 * size);
    case H5T_OPAQUE:
        return msg("opaque[", size, "]");
    case H5T_REFERENCE:
        return "reference";
    case H5T_ENUM:
        return msg("enum (", size, " bytes)");
    case H5T_VLEN: {
        const hid_t base = H5Tget_super(type);
        const std::string name = msg("variable-length of ", typeName(base));
        H5Tclose(base);
        return name;
    }
    case H5T_ARRAY: {
        const int rank = H5Tget_array_ndims(type);
        std::vector<hsize_t> dims(static_cast<std::size_t>(std::max(rank, 0)));
        if (rank > 0) H5Tget_array_dims2(type, dims.data());
        std::string shape;
        for (hsize_t d : dims) shape += (shape.empty() ? "" : " x ") + std::to_string(d);
        const hid_t base = H5Tget_super(type);
        const std::string name = msg("array [", shape, "] of ", typeName(base));
        H5Tclose(base);
        return name;
    }
    case H5T_COMPOUND: {
        std::string members;
        const int n = H5Tget_nmembers(type);
        for (int i = 0; i < n; ++i) {
            char* memberName = H5Tget_member_name(type, unsigned(i));
            const hid_t memberType = H5Tget_member_type(type, unsigned(i));
            members +=
                msg(i ? ", " : "", memberName ? memberName : "?", ": ", typeName(memberType));
            H5Tclose(memberType);
            H5free_memory(memberName);
        }
        return "compound {" + members + "}";
    }
    default:
        return msg("type of ", size, " bytes");
    }
}

std::string shapeOf(const H5::DataSpace& space)
{
    if (space.getSimpleExtentType() == H5S_SCALAR) return "scalar";
    if (space.getSimpleExtentType() == H5S_NULL) return "empty";
    const int rank = space.getSimpleExtentNdims();
    std::vector<hsize_t> dims(static_cast<std::size_t>(rank));
    space.getSimpleExtentDims(dims.data());
    std::string shape;
    for (hsize_t d : dims) shape += (shape.empty() ? "" : " x ") + std::to_string(d);
    return "[" + shape + "]";
}

template <typename T>
std::string joinValues(const std::vector<T>& values)
{
    std::ostringstream os;
    os << std::setprecision(10);
    if (values.size() != 1) os << "[";
    for (std::size_t i = 0; i < values.size(); ++i) os << (i ? ", " : "") << values[i];
    if (values.size() != 1) os << "]";
    return os.str();
}

/// A string attribute value in quotes, without padding zeros, cut if very long.
std::string quoted(std::string text)
{
    text.erase(std::find(text.begin(), text.end(), '\0'), text.end());
    if (text.size() > MAX_PRINTED_CHARACTERS) {
        return msg("\"", text.substr(0, MAX_PRINTED_CHARACTERS), "...\" (", text.size(),
                   " characters)");
    }
    return "\"" + text + "\"";
}

/// The elements of a string-array attribute, fixed or variable length.
std::vector<std::string> readStrings(const H5::Attribute& attribute, std::size_t count)
{
    const H5::DataType type = attribute.getDataType();
    std::vector<std::string> strings;
    if (H5Tis_variable_str(type.getId()) > 0) {
        std::vector<char*> pointers(count, nullptr);
        const H5::StrType memoryType(H5::PredType::C_S1, H5T_VARIABLE);
        attribute.read(memoryType, pointers.data());
        for (char* p : pointers) strings.emplace_back(p ? p : "");
        // Variable-length strings are allocated by HDF5: give them back.
        const H5::DataSpace space = attribute.getSpace();
        H5Dvlen_reclaim(memoryType.getId(), space.getId(), H5P_DEFAULT, pointers.data());
    } else {
        const std::size_t size = type.getSize();
        std::vector<char> buffer(size * count);
        attribute.read(type, buffer.data());
        for (std::size_t i = 0; i < count; ++i) strings.emplace_back(&buffer[i * size], size);
    }
    return strings;
}

/// Value of an attribute: numbers and strings are printed (short arrays in full), other
/// types by their type and shape only.
std::string attributeValue(const H5::Attribute& attribute)
{
    const H5::DataType type = attribute.getDataType();
    const H5::DataSpace space = attribute.getSpace();
    const hssize_t count = space.getSimpleExtentNpoints();
    const H5T_class_t typeClass = H5Tget_class(type.getId());
    const std::string shape = shapeOf(space);
    if (count < 1) return msg("(", typeName(type.getId()), ", ", shape, ")");
    if (typeClass == H5T_STRING && count == 1) {
        std::string text;
        attribute.read(type, text);
        return quoted(text);
    }
    if (typeClass == H5T_STRING && std::size_t(count) <= MAX_PRINTED_STRINGS) {
        std::string list;
        for (const std::string& text : readStrings(attribute, std::size_t(count))) {
            list += (list.empty() ? "" : ", ") + quoted(text);
        }
        return "[" + list + "]";
    }
    const bool numeric = typeClass == H5T_INTEGER || typeClass == H5T_FLOAT;
    if (!numeric || std::size_t(count) > MAX_PRINTED_VALUES) {
        return msg("(", typeName(type.getId()), ", ", shape, ")");
    }
    const std::size_t valueCount = static_cast<std::size_t>(count);
    std::string values;
    if (typeClass == H5T_FLOAT) {
        std::vector<double> v(valueCount);
        attribute.read(H5::PredType::NATIVE_DOUBLE, v.data());
        values = joinValues(v);
    } else if (H5Tget_sign(type.getId()) == H5T_SGN_NONE) {
        std::vector<unsigned long long> v(valueCount);
        attribute.read(H5::PredType::NATIVE_ULLONG, v.data());
        values = joinValues(v);
    } else {
        std::vector<long long> v(valueCount);
        attribute.read(H5::PredType::NATIVE_LLONG, v.data());
        values = joinValues(v);
    }
    return msg(values, " (", typeName(type.getId()), ")");
}

void describeAttributes(std::ostream& os, const H5::H5Object& object, const std::string& indent)
{
    const int n = object.getNumAttrs();
    for (int i = 0; i < n; ++i) {
        const H5::Attribute attribute = object.openAttribute(unsigned(i));
        std::string value;
        try {
            value = attributeValue(attribute);
        } catch (const H5::Exception& e) {
            value = msg("(unreadable: ", e.getDetailMsg(), ")");
        }
        os << indent << "@" << attribute.getName() << " = " << value << "\n";
    }
}

void describeGroup(std::ostream& os, const H5::Group& group, const std::string& path, int depth)
{
    const std::string indent(std::size_t(2 * depth + 2), ' ');
    describeAttributes(os, group, indent);
    const hsize_t n = group.getNumObjs();
    for (hsize_t i = 0; i < n; ++i) {
        const std::string name = group.getObjnameByIdx(i);
        const std::string childPath = (path == "/" ? "/" : path + "/") + name;
        H5O_type_t kind;
        try {
            kind = group.childObjType(name);
        } catch (const H5::Exception&) {
            os << indent << childPath << ": unresolved link\n";
            continue;
        }
        if (kind == H5O_TYPE_GROUP) {
            os << indent << childPath << "/  (group)\n";
            if (depth + 1 < MAX_GROUP_DEPTH) {
                describeGroup(os, group.openGroup(name), childPath, depth + 1);
            }
        } else if (kind == H5O_TYPE_DATASET) {
            const H5::DataSet dataset = group.openDataSet(name);
            const H5::DataType type = dataset.getDataType();
            os << indent << childPath << "  (dataset " << typeName(type.getId()) << " "
               << shapeOf(dataset.getSpace()) << ", " << sizeText(double(dataset.getStorageSize()))
               << " stored)\n";
            describeAttributes(os, dataset, indent + "  ");
        } else if (kind == H5O_TYPE_NAMED_DATATYPE) {
            os << indent << childPath << "  (named type)\n";
        } else {
            os << indent << childPath << "  (unknown object)\n";
        }
    }
}

std::string describeH5(const std::string& path)
{
    H5::Exception::dontPrint();
    if (H5Fis_hdf5(path.c_str()) <= 0) {
        throw IoError(msg("'", path, "': not an HDF5 file"));
    }
    try {
        H5::H5File file(path, H5F_ACC_RDONLY);
        std::ostringstream os;
        os << path << ": HDF5 file, " << sizeText(double(fs::file_size(path))) << " on disk\n";
        os << "  /  (group)\n";
        describeGroup(os, file.openGroup("/"), "/", 1);
        return os.str();
    } catch (const H5::Exception& e) {
        throw IoError(msg("'", path, "': cannot read as an HDF5 file (", e.getFuncName(), ": ",
                          e.getDetailMsg(), ")"));
    }
}

} // namespace

std::string describeFile(const std::string& path)
{
    std::error_code ec;
    if (!fs::exists(path, ec)) throw IoError(msg("'", path, "': no such file"));
    if (!fs::is_regular_file(path, ec)) throw IoError(msg("'", path, "': not a regular file"));
    const std::string ext = extensionOf(path);
    if (ext == ".vdb") return describeVdb(path);
    if (ext == ".h5" || ext == ".hdf5") return describeH5(path);
    throw IoError(
        msg("'", path, "': unknown kind of file '", ext, "': expected .vdb, .h5 or .hdf5"));
}

} // namespace vdbio
} // namespace ghostfx
