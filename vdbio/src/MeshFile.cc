/// @file   MeshFile.cc
/// @brief  tools::volumeToMesh of the liquid surface, per-vertex normals and velocities, and
///         the PLY and OBJ writers (MeshFile.h).
#include <ghostfx/vdbio/MeshFile.h>

#include "FrameGridsDetail.h"

#include <ghostfx/sph/Exceptions.h>
#include <ghostfx/vdbio/AtomicFile.h>

#include <openvdb/tools/Interpolation.h>
#include <openvdb/tools/VolumeToMesh.h>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <sstream>

namespace ghostfx {
namespace vdbio {

void MeshOptions::validate() const
{
    if (!(adaptivity >= 0.0 && adaptivity <= 1.0)) {
        throw ValueError(msg("mesh output: adaptivity = ", adaptivity, ": expected in [0, 1]"));
    }
}

double SurfaceMesh::enclosedVolume() const
{
    double sum = 0;
    for (const openvdb::Vec3I& t : triangles) {
        const openvdb::Vec3d a(points[t[0]]), b(points[t[1]]), c(points[t[2]]);
        sum += a.dot(b.cross(c));
    }
    return sum / 6.0;
}

namespace {

/// The polygons of tools::volumeToMesh as triangles wound counter-clockwise from outside:
/// volumeToMesh winds a level set's polygons the other way (kept as they come, a sphere's
/// enclosed volume is negative; tests/vdbio/test_mesh_file.cc checks the sign), so each is
/// reversed. A quad (a, b, c, d) becomes
/// (a, d, c) and (a, c, b); corners that coincide (an adaptive mesh's collapsed quads) leave
/// no triangle.
std::vector<openvdb::Vec3I> windTriangles(const std::vector<openvdb::Vec3I>& triangles,
                                          const std::vector<openvdb::Vec4I>& quads)
{
    std::vector<openvdb::Vec3I> out;
    out.reserve(triangles.size() + 2 * quads.size());
    auto add = [&out](unsigned a, unsigned b, unsigned c) {
        if (a != b && b != c && c != a) out.emplace_back(a, b, c);
    };
    for (const openvdb::Vec3I& t : triangles) add(t[0], t[2], t[1]);
    for (const openvdb::Vec4I& q : quads) {
        add(q[0], q[3], q[2]);
        add(q[0], q[2], q[1]);
    }
    return out;
}

/// Unit vertex normals: the sum of the (area-weighted) normals of the triangles around each
/// vertex, normalised; a vertex no triangle uses gets (0, 0, 0).
std::vector<openvdb::Vec3s> vertexNormals(const SurfaceMesh& mesh)
{
    std::vector<openvdb::Vec3d> sum(mesh.points.size(), openvdb::Vec3d(0.0));
    for (const openvdb::Vec3I& t : mesh.triangles) {
        const openvdb::Vec3d a(mesh.points[t[0]]), b(mesh.points[t[1]]), c(mesh.points[t[2]]);
        const openvdb::Vec3d twiceArea = (b - a).cross(c - a); // |.| = 2 * area
        for (int k = 0; k < 3; ++k) sum[t[k]] += twiceArea;
    }
    std::vector<openvdb::Vec3s> normals(sum.size(), openvdb::Vec3s(0.0f));
    for (std::size_t v = 0; v < sum.size(); ++v) {
        const double length = sum[v].length();
        if (length > 0.0) normals[v] = openvdb::Vec3s(sum[v] / length);
    }
    return normals;
}

/// `velocity` read trilinearly at each of `points` (world space, m).
std::vector<openvdb::Vec3s> sampleVelocities(const openvdb::Vec3SGrid& velocity,
                                             const std::vector<openvdb::Vec3s>& points)
{
    std::vector<openvdb::Vec3s> v(points.size());
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, points.size(), 1024),
                      [&](const tbb::blocked_range<std::size_t>& range) {
        const openvdb::Vec3SGrid::ConstAccessor acc = velocity.getConstAccessor();
        const openvdb::tools::GridSampler<openvdb::Vec3SGrid::ConstAccessor,
                                          openvdb::tools::BoxSampler>
            sampler(acc, velocity.transform());
        for (std::size_t n = range.begin(); n != range.end(); ++n) {
            v[n] = sampler.wsSample(openvdb::Vec3d(points[n]));
        }
    });
    return v;
}

} // namespace

SurfaceMesh makeSurfaceMesh(const openvdb::FloatGrid& surface, const openvdb::Vec3SGrid* velocity,
                            const MeshOptions& options)
{
    options.validate();
    if (surface.getGridClass() != openvdb::GRID_LEVEL_SET) {
        throw ValueError(msg("mesh output: grid '", surface.getName(),
                             "' is not a level set (class ",
                             openvdb::GridBase::gridClassToString(surface.getGridClass()), ")"));
    }
    SurfaceMesh mesh;
    std::vector<openvdb::Vec3I> triangles;
    std::vector<openvdb::Vec4I> quads;
    openvdb::tools::volumeToMesh(surface, mesh.points, triangles, quads, /*isovalue=*/0.0,
                                 options.adaptivity);
    mesh.triangles = windTriangles(triangles, quads);
    mesh.normals = vertexNormals(mesh);
    if (velocity) mesh.velocities = sampleVelocities(*velocity, mesh.points);
    return mesh;
}

// ---------------------------------------------------------------------------------------------
// Files
// ---------------------------------------------------------------------------------------------

namespace {

/// Throw ValueError when the mesh's per-vertex arrays or triangle indices disagree with its
/// points.
void checkMesh(const std::string& path, const SurfaceMesh& mesh)
{
    const std::size_t n = mesh.points.size();
    if (mesh.normals.size() != n || !(mesh.velocities.empty() || mesh.velocities.size() == n)) {
        throw ValueError(msg("mesh output '", path, "': ", n, " points but ", mesh.normals.size(),
                             " normals and ", mesh.velocities.size(), " velocities"));
    }
    for (const openvdb::Vec3I& t : mesh.triangles) {
        if (t[0] >= n || t[1] >= n || t[2] >= n) {
            throw ValueError(msg("mesh output '", path, "': a triangle names vertex ",
                                 std::max(t[0], std::max(t[1], t[2])), " of ", n));
        }
    }
}

/// One line of text: line breaks in a comment would end the header early.
std::string oneLine(std::string text)
{
    for (char& c : text) {
        if (c == '\n' || c == '\r') c = ' ';
    }
    return text;
}

/// Append the little-endian bytes of `value` (this build targets little-endian x86-64 and
/// ARM64, whose native order is the file's).
template <typename T>
void appendBytes(std::string& out, const T& value)
{
    static_assert(std::is_trivially_copyable<T>::value, "plain values only");
    const char* bytes = reinterpret_cast<const char*>(&value);
    out.append(bytes, sizeof(T));
}

/// The whole PLY file as bytes: the header, then the vertices and faces.
std::string plyBytes(const SurfaceMesh& mesh, const std::vector<std::string>& comments)
{
    const bool withVelocity = !mesh.velocities.empty();
    std::ostringstream header;
    header << "ply\nformat binary_little_endian 1.0\ncomment written by ghostfx\n";
    for (const std::string& c : comments) header << "comment " << oneLine(c) << "\n";
    header << "element vertex " << mesh.points.size() << "\n"
           << "property float x\nproperty float y\nproperty float z\n"
           << "property float nx\nproperty float ny\nproperty float nz\n";
    if (withVelocity) header << "property float vx\nproperty float vy\nproperty float vz\n";
    header << "element face " << mesh.triangles.size() << "\n"
           << "property list uchar int vertex_indices\nend_header\n";
    std::string out = header.str();
    out.reserve(out.size() + mesh.points.size() * (withVelocity ? 36 : 24)
                + mesh.triangles.size() * 13);
    for (std::size_t v = 0; v < mesh.points.size(); ++v) {
        for (int k = 0; k < 3; ++k) appendBytes(out, mesh.points[v][k]);
        for (int k = 0; k < 3; ++k) appendBytes(out, mesh.normals[v][k]);
        if (withVelocity) {
            for (int k = 0; k < 3; ++k) appendBytes(out, mesh.velocities[v][k]);
        }
    }
    for (const openvdb::Vec3I& t : mesh.triangles) {
        appendBytes(out, std::uint8_t(3));
        for (int k = 0; k < 3; ++k) appendBytes(out, std::int32_t(t[k]));
    }
    return out;
}

/// The whole OBJ file as text; floats with 9 significant digits, which read back exactly.
std::string objText(const SurfaceMesh& mesh, const std::vector<std::string>& comments)
{
    std::string out = "# written by ghostfx\n";
    for (const std::string& c : comments) out += "# " + oneLine(c) + "\n";
    char line[160];
    for (const openvdb::Vec3s& p : mesh.points) {
        std::snprintf(line, sizeof(line), "v %.9g %.9g %.9g\n", p[0], p[1], p[2]);
        out += line;
    }
    for (const openvdb::Vec3s& n : mesh.normals) {
        std::snprintf(line, sizeof(line), "vn %.9g %.9g %.9g\n", n[0], n[1], n[2]);
        out += line;
    }
    for (const openvdb::Vec3I& t : mesh.triangles) {
        const unsigned a = t[0] + 1, b = t[1] + 1, c = t[2] + 1;
        std::snprintf(line, sizeof(line), "f %u//%u %u//%u %u//%u\n", a, a, b, b, c, c);
        out += line;
    }
    return out;
}

/// Write `bytes` to `tmp` (the temporary of `path`), checking the stream.
void writeBytes(const std::string& tmp, const std::string& path, const std::string& bytes)
{
    std::ofstream out(tmp, std::ios_base::out | std::ios_base::binary | std::ios_base::trunc);
    if (!out) {
        throw IoError(
            msg("mesh output '", path, "': cannot create it (", std::strerror(errno), ")"));
    }
    out.write(bytes.data(), std::streamsize(bytes.size()));
    out.close();
    if (out.fail()) {
        throw IoError(msg("mesh output '", path, "': cannot write it (",
                          errno != 0 ? std::strerror(errno) : "the stream failed", ")"));
    }
}

} // namespace

void writeMeshFile(const std::string& path, const SurfaceMesh& mesh,
                   const std::vector<std::string>& comments)
{
    const std::string ext = extensionOf(path);
    if (ext != ".ply" && ext != ".obj") {
        throw ValueError(msg("mesh output '", path, "': expected a name ending in .ply or .obj",
                             ext.empty() ? "" : msg(", not ", ext)));
    }
    checkMesh(path, mesh);
    detail::checkOutputFolder(path, "mesh output");
    const std::string bytes = ext == ".ply" ? plyBytes(mesh, comments) : objText(mesh, comments);
    writeAtomically(path, [&](const std::string& tmp) { writeBytes(tmp, path, bytes); });
}

std::vector<std::string> meshComments(const openvdb::MetaMap& fileMetadata)
{
    std::vector<std::string> lines;
    for (auto it = fileMetadata.beginMeta(); it != fileMetadata.endMeta(); ++it) {
        lines.push_back(it->first + " " + it->second->str());
    }
    return lines;
}

// ---------------------------------------------------------------------------------------------
// Reading PLY back
// ---------------------------------------------------------------------------------------------

namespace {

/// What a PLY header declares, as far as readPlyMeshFile reads it.
struct PlyLayout
{
    std::size_t vertices = 0, faces = 0;
    std::vector<std::string> vertexProperties; ///< float properties, in file order
    bool faceList = false;                     ///< `property list uchar int vertex_indices`
};

/// The header of the PLY stream `in` (through `end_header`); IoError naming `path` for another
/// format or layout.
PlyLayout readPlyHeader(std::istream& in, const std::string& path)
{
    auto fail = [&path](const std::string& why) {
        throw IoError(msg("mesh file '", path, "': ", why));
    };
    std::string line;
    if (!std::getline(in, line) || line != "ply") fail("not a PLY file");
    PlyLayout layout;
    std::string element;
    while (std::getline(in, line) && line != "end_header") {
        std::istringstream words(line);
        std::string word, type, name;
        words >> word;
        if (word == "format") {
            words >> type >> name;
            if (type != "binary_little_endian" || name != "1.0")
                fail("format '" + type + " " + name + "': expected binary_little_endian 1.0");
        } else if (word == "element") {
            words >> element;
            std::size_t& count = element == "vertex" ? layout.vertices : layout.faces;
            if (element != "vertex" && element != "face") fail("element '" + element + "'");
            words >> count;
        } else if (word == "property" && element == "vertex") {
            words >> type >> name;
            if (type != "float") fail("vertex property '" + name + "' is not a float");
            layout.vertexProperties.push_back(name);
        } else if (word == "property" && element == "face") {
            layout.faceList = line == "property list uchar int vertex_indices";
            if (!layout.faceList) fail("face property '" + line + "'");
        } else if (word != "comment" && word != "obj_info") {
            fail("header line '" + line + "'");
        }
    }
    if (line != "end_header") fail("no end_header");
    return layout;
}

/// The index of property `name` in `names`, or -1.
int propertyIndex(const std::vector<std::string>& names, const char* name)
{
    for (std::size_t k = 0; k < names.size(); ++k) {
        if (names[k] == name) return int(k);
    }
    return -1;
}

/// Read one value of type T from `in`.
template <typename T>
T readValue(std::istream& in)
{
    T value{};
    in.read(reinterpret_cast<char*>(&value), sizeof(T));
    return value;
}

/// The vertices of `layout` from `in` into `mesh`: positions, and normals and velocities
/// where the file has them.
void readPlyVertices(std::istream& in, const PlyLayout& layout, const std::string& path,
                     SurfaceMesh& mesh)
{
    const std::vector<std::string>& names = layout.vertexProperties;
    const int x = propertyIndex(names, "x"), nx = propertyIndex(names, "nx"),
              vx = propertyIndex(names, "vx");
    if (x < 0 || propertyIndex(names, "y") != x + 1 || propertyIndex(names, "z") != x + 2)
        throw IoError(msg("mesh file '", path, "': no vertex properties x y z in a row"));
    std::vector<float> row(names.size());
    for (std::size_t v = 0; v < layout.vertices; ++v) {
        in.read(reinterpret_cast<char*>(row.data()), std::streamsize(row.size() * sizeof(float)));
        mesh.points.emplace_back(row[std::size_t(x)], row[std::size_t(x) + 1],
                                 row[std::size_t(x) + 2]);
        if (nx >= 0) {
            mesh.normals.emplace_back(row[std::size_t(nx)], row[std::size_t(nx) + 1],
                                      row[std::size_t(nx) + 2]);
        }
        if (vx >= 0) {
            mesh.velocities.emplace_back(row[std::size_t(vx)], row[std::size_t(vx) + 1],
                                         row[std::size_t(vx) + 2]);
        }
    }
}

} // namespace

SurfaceMesh readPlyMeshFile(const std::string& path)
{
    std::ifstream in(path, std::ios_base::in | std::ios_base::binary);
    if (!in) throw IoError(msg("mesh file '", path, "': cannot open it"));
    const PlyLayout layout = readPlyHeader(in, path);
    if (layout.faces > 0 && !layout.faceList)
        throw IoError(msg("mesh file '", path, "': faces without vertex_indices"));
    SurfaceMesh mesh;
    readPlyVertices(in, layout, path, mesh);
    for (std::size_t f = 0; f < layout.faces && in; ++f) {
        if (readValue<std::uint8_t>(in) != 3)
            throw IoError(msg("mesh file '", path, "': face ", f, " is not a triangle"));
        openvdb::Vec3I t;
        for (int k = 0; k < 3; ++k) t[k] = openvdb::Index32(readValue<std::int32_t>(in));
        mesh.triangles.push_back(t);
    }
    if (!in) throw IoError(msg("mesh file '", path, "': shorter than its header says"));
    return mesh;
}

} // namespace vdbio
} // namespace ghostfx
