/// @file   Scene.cc
/// @brief  Scene reading: strict JSON, role-tagged .vdb scenes, level-set loading.
#include <ghostfx/vdbio/Scene.h>

#include "FogRegion.h"

#include <ghostfx/sph/Exceptions.h>
#include <ghostfx/sph/LevelSetGrid.h>
#include <ghostfx/vdbio/AtomicFile.h>

#include <openvdb/openvdb.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

#include <unistd.h>

namespace ghostfx {
namespace vdbio {

namespace fs = std::filesystem;

namespace {
/// Memory per particle for the budget check (bytes): the most a run measured, neighbour lists
/// included (bench/history/diary-2026-11.md, "memory").
constexpr double BYTES_PER_PARTICLE = 350;
} // namespace
using sph::Vec3d;

// Level sets -----------------------------------------------------------------------------------

namespace {

/// Read one float grid from a .vdb file, with errors naming the file, the grid and `context`.
openvdb::FloatGrid::Ptr loadFloatGrid(const std::string& file, const std::string& grid,
                                      const std::string& context)
{
    std::error_code ec;
    if (!fs::exists(file, ec)) {
        throw IoError(msg(context, ": file '", file, "' does not exist"));
    }
    openvdb::io::File vdb(file);
    try {
        vdb.open(/*delayLoad=*/false);
    } catch (const openvdb::Exception& e) {
        throw IoError(
            msg(context, ": file '", file, "' is not a readable .vdb file (", e.what(), ")"));
    }
    if (!vdb.hasGrid(grid)) {
        std::string names;
        for (auto it = vdb.beginName(); it != vdb.endName(); ++it)
            names += (names.empty() ? "'" : ", '") + *it + "'";
        vdb.close();
        throw GridError(msg(context, ": file '", file, "' has no grid '", grid,
                            "' (grids: ", names.empty() ? "none" : names, ")"));
    }
    openvdb::GridBase::Ptr base;
    try {
        base = vdb.readGrid(grid);
    } catch (const openvdb::Exception& e) {
        vdb.close();
        throw IoError(
            msg(context, ": grid '", grid, "' in '", file, "' cannot be read (", e.what(), ")"));
    }
    vdb.close();
    auto floatGrid = openvdb::gridPtrCast<openvdb::FloatGrid>(base);
    if (!floatGrid) {
        throw GridError(msg(context, ": grid '", grid, "' in '", file, "' holds ",
                            base->valueType(), " values, expected a float level set"));
    }
    return floatGrid;
}

} // namespace

sph::LevelSet loadLevelSet(const std::string& file, const std::string& grid,
                           const std::string& context)
{
    openvdb::FloatGrid::Ptr floatGrid = loadFloatGrid(file, grid, context);
    try {
        return sph::makeLevelSet(floatGrid, grid);
    } catch (const GridError& e) {
        throw GridError(msg(context, ": '", file, "': ", e.what()));
    }
}

namespace {

Vec3d vec(const std::array<double, 3>& a) { return Vec3d(a[0], a[1], a[2]); }

std::string resolve(const std::string& folder, const std::string& path)
{
    if (path.empty() || fs::path(path).is_absolute()) return path;
    return (fs::path(folder) / path).lexically_normal().string();
}

/// How much of a shape the solvers fill with particles: all of it (liquid, gas source) or a
/// band under its surface (solid ghosts and boundary particles: a kernel radius, 2 spacings).
enum class Sampled { Volume, Band, None };

/// The physical memory of this machine (bytes), 0 if unknown.
double physicalMemory()
{
    const long pages = ::sysconf(_SC_PHYS_PAGES), size = ::sysconf(_SC_PAGE_SIZE);
    return pages > 0 && size > 0 ? double(pages) * double(size) : 0.0;
}

/// Refuse a built-in shape whose particles cannot fit in this machine's memory, before its
/// level set is built (which alone can take hours at a spacing far too fine for the shape).
/// Particles: the volume, or the surface area times the band depth, over spacing^3; bytes per
/// particle: 350, the most a run measured with its neighbour lists
/// (bench/history/diary-2026-11.md).
void checkParticleBudget(const JsonObject& g, double spacing, double voxel, Sampled sampled,
                         const char* kind)
{
    const JsonObject shape = g.object(kind);
    double volume = 0, area = 0;
    if (std::string(kind) == "sphere") {
        const double r = shape.get<double>("radius", 0);
        volume = 4.0 / 3.0 * M_PI * r * r * r;
        area = 4.0 * M_PI * r * r;
    } else {
        const auto lo = shape.get<std::array<double, 3>>("min", {0, 0, 0});
        const auto hi = shape.get<std::array<double, 3>>("max", {0, 0, 0});
        const double a = std::abs(hi[0] - lo[0]), b = std::abs(hi[1] - lo[1]),
                     c = std::abs(hi[2] - lo[2]);
        volume = a * b * c;
        area = 2 * (a * b + b * c + c * a);
        if (std::string(kind) == "container") {
            const double w = shape.get<double>("wall", 3 * spacing);
            volume = (a + 2 * w) * (b + 2 * w) * (c + 2 * w) - volume;
            area += 2
                    * ((a + 2 * w) * (b + 2 * w) + (b + 2 * w) * (c + 2 * w)
                       + (c + 2 * w) * (a + 2 * w));
        }
    }
    const double memory = physicalMemory();
    if (sampled == Sampled::None) {
        // Only the level set: a narrow band of 2 x 3 voxels over the surface, about 8 bytes a
        // voxel with OpenVDB's tree.
        const double bytes = 8 * 6 * area / (voxel * voxel);
        if (memory > 0 && bytes > memory) {
            g.fail(kind, msg("at voxel size ", voxel, " m this shape's level set needs about ",
                             bytes / double(1ULL << 30), " GiB, more than this machine's ",
                             memory / double(1ULL << 30), " GiB: expected a smaller shape"));
        }
        return;
    }
    if (sampled == Sampled::Band) volume = std::min(volume, area * 2 * spacing);
    const double particles = volume / (spacing * spacing * spacing);
    const double bytes = particles * BYTES_PER_PARTICLE;
    if (memory > 0 && bytes > memory) {
        const double fits = spacing * std::cbrt(bytes / memory);
        g.fail(kind, msg("at spacing ", spacing, " m this shape needs about ", particles,
                         " particles (", bytes / double(1ULL << 30), " GiB at ", BYTES_PER_PARTICLE,
                         " bytes each), more than this "
                         "machine's ",
                         memory / double(1ULL << 30), " GiB: expected a spacing of at least ", fits,
                         " m"));
    }
}

/// A point of a built-in shape, `s.key`, within OpenVDB's index range at `voxel` (m): about a
/// billion voxels from the origin on every axis (coordinates are 32-bit voxel indices).
Vec3d point(const JsonObject& s, const char* key, double voxel)
{
    const Vec3d x = vec(s.require<std::array<double, 3>>(key));
    const double reach = double(1 << 30) * voxel;
    for (int a = 0; a < 3; ++a) {
        if (!(std::abs(x[a]) < reach)) {
            s.failValue(key, msg("expected coordinates within +-", reach,
                                 " m (OpenVDB's index range at voxel size ", voxel, " m)"));
        }
    }
    return x;
}

/// A shape from a .vdb file, `g.file` with grid `g.grid`: a level set or, with `allowFog`, a
/// fog volume whose region is where the density exceeds `g.threshold`.
sph::LevelSet readFileGeometry(const JsonObject& g, const Scene& scene, std::string& description,
                               bool allowFog)
{
    const std::string path = resolve(scene.folder, g.require<std::string>("file"));
    const std::string grid = g.require<std::string>("grid");
    description = path + ":" + grid;
    const std::string context = msg("scene '", scene.file, "': ", g.path());
    if (allowFog) {
        // A gas source may be a fog volume: its region is where the density exceeds `threshold`.
        const double threshold = g.nonNegative("threshold", 0.5);
        g.finish();
        openvdb::FloatGrid::Ptr fog = loadFloatGrid(path, grid, context);
        if (fog->getGridClass() == openvdb::GRID_FOG_VOLUME) {
            try {
                return fogRegionToLevelSet(*fog, float(threshold), grid);
            } catch (const GridError& e) {
                throw GridError(msg(context, ": '", path, "': ", e.what()));
            }
        }
        return loadLevelSet(path, grid, context);
    }
    g.finish();
    return loadLevelSet(path, grid, context);
}

/// The built-in sphere `s` ({center, radius}) as a level set of voxel `voxel` (m).
openvdb::FloatGrid::Ptr readSphere(const JsonObject& s, double voxel, std::string& description)
{
    const Vec3d c = point(s, "center", voxel);
    const double r = s.positive("radius", 0);
    s.finish();
    if (r < 2 * voxel) s.failValue("radius", msg("expected at least 2 voxels (", 2 * voxel, " m)"));
    description = msg("sphere r = ", r, " m");
    return sph::makeSphereLevelSet(sph::Vec3(c), sph::Real(r), sph::Real(voxel));
}

/// The built-in box `b` ({min, max}) or, with `container`, a closed tank around that empty box
/// (walls of thickness `b.wall`, default three spacings), as a level set of voxel `voxel` (m).
openvdb::FloatGrid::Ptr readBox(const JsonObject& b, bool container, double voxel, double spacing,
                                std::string& description)
{
    const Vec3d lo = point(b, "min", voxel);
    const Vec3d hi = point(b, "max", voxel);
    for (int a = 0; a < 3; ++a) {
        if (!(hi[a] - lo[a] >= 2 * voxel)) {
            b.failValue("max", msg("expected max > min + 2 voxels on every axis (axis ", a, ")"));
        }
    }
    if (!container) {
        b.finish();
        description = "box";
        return sph::makeBoxLevelSet(sph::Vec3(lo), sph::Vec3(hi), sph::Real(voxel));
    }
    const double wall = b.positive("wall", 3 * spacing);
    b.finish();
    const Vec3d w(wall);
    description = msg("container, wall ", wall, " m");
    // Walls: outside the inner box and inside the outer one, max(-inner, outer).
    return sph::levelSetFromSdf(
        [lo, hi, w](const openvdb::Vec3d& x) {
        return std::max(-sph::boxSignedDistance(x, lo, hi),
                        sph::boxSignedDistance(x, lo - w, hi + w));
        },
        sph::Aabb{sph::Vec3(lo - w), sph::Vec3(hi + w)}, sph::Real(voxel));
}

/// A shape: a grid in a file, or a built-in sphere, box or container (a closed tank: solid walls
/// of thickness `wall` around the empty box [min, max]).
sph::LevelSet readGeometry(const JsonObject& g, const Scene& scene, std::string& description,
                           Sampled sampled, bool allowFog = false)
{
    const bool file = g.has("file"), sphere = g.has("sphere"), box = g.has("box"),
               container = g.has("container");
    if (int(file) + int(sphere) + int(box) + int(container) != 1) {
        g.fail("", "expected exactly one of 'file' (with 'grid'), 'sphere', 'box' or 'container'");
    }
    if (file) return readFileGeometry(g, scene, description, allowFog);
    const double voxel = g.positive("voxel_size", 0.5 * scene.spacing);
    if (voxel < MIN_SPACING / 2) {
        g.failValue("voxel_size", msg("expected at least ", MIN_SPACING / 2,
                                      " m (OpenVDB's smallest usable voxel)"));
    }
    const char* kind = sphere ? "sphere" : box ? "box" : "container";
    checkParticleBudget(g, scene.spacing, voxel, sampled, kind);
    const openvdb::FloatGrid::Ptr grid =
        sphere ? readSphere(g.object(kind), voxel, description)
               : readBox(g.object(kind), container, voxel, scene.spacing, description);
    g.finish();
    try {
        return sph::makeLevelSet(grid, g.path());
    } catch (const GridError& e) {
        throw SceneError(msg("scene '", scene.file, "': ", e.what()));
    }
}

/// The `grids` of an output section: each one of `allowed`, or a one-line error with the
/// closest name.
std::vector<std::string> readGridNames(const JsonObject& s,
                                       const std::vector<std::string>& fallback,
                                       const std::vector<std::string>& allowed)
{
    const auto grids = s.get<std::vector<std::string>>("grids", fallback);
    for (const std::string& g : grids) {
        if (std::find(allowed.begin(), allowed.end(), g) != allowed.end()) continue;
        std::string list;
        for (const std::string& a : allowed) list += (list.empty() ? "" : ", ") + a;
        const std::string near = closestKey(g, allowed);
        s.failValue("grids", msg("grid '", g, "' is not one of ", list,
                                 near.empty() ? "" : " (did you mean '" + near + "'?)"));
    }
    return grids;
}

/// The file name `s.key` (a frame pattern) must end in one of `extensions`, the formats that
/// output is written in; `what` names them ("OpenVDB (.vdb)").
std::string outputFile(const JsonObject& s, const char* key, const std::string& fallback,
                       const std::vector<std::string>& extensions, const char* what)
{
    const std::string file = s.get<std::string>(key, fallback);
    const std::string ext = extensionOf(file);
    if (std::find(extensions.begin(), extensions.end(), ext) != extensions.end()) return file;
    std::string names;
    for (const std::string& e : extensions) names += (names.empty() ? "" : " or ") + e;
    s.failValue(key, msg("this output is written as ", what, ": expected a name ending in ", names,
                         ext.empty() ? "" : msg(", not ", ext)));
}

/// One section of `outputs`: an object that `read` reads, false or null to switch the output
/// off (its `file` cleared), true for its defaults.
template <typename Read>
void readSection(const JsonObject& o, const char* key, std::string& file, Read&& read)
{
    const Json* v = o.raw(key);
    if (!v) return;
    if (v->is_null() || (v->is_boolean() && !v->get<bool>())) {
        file.clear();
        return;
    }
    if (v->is_boolean()) return; // true: defaults
    const JsonObject s = o.object(key);
    read(s);
    s.finish();
}

/// outputs.preview's camera, image and background.
void readPreview(const JsonObject& s, SceneOutputs& out)
{
    out.previewFile =
        outputFile(s, "file", "preview.$F4.exr", {".exr", ".png"}, "an EXR or PNG image");
    out.previewGrid = s.get<std::string>("grid", out.previewGrid);
    out.previewWidth = int(s.inRange("width", out.previewWidth, 16, 8192));
    out.previewHeight = int(s.inRange("height", out.previewHeight, 16, 8192));
    out.previewSolids = s.get<bool>("solids", out.previewSolids);
    out.previewAzimuth = s.inRange("azimuth", out.previewAzimuth, -360, 360);
    out.previewElevation = s.inRange("elevation", out.previewElevation, -90, 90);
    if (const Json* bg = s.raw("background")) {
        if (bg->is_string() && bg->get<std::string>() == "transparent") {
            out.previewBackground.reset();
        } else {
            const auto c = s.get<std::array<double, 3>>("background", {0, 0, 0});
            for (double v : c) {
                if (!(v >= 0 && v <= 1))
                    s.failValue("background",
                                "expected [r, g, b] in 0 to 1 (linear), or \"transparent\"");
            }
            out.previewBackground = c;
        }
    }
    if (auto box = s.optionalObject("frame")) {
        const Vec3d lo = vec(box->require<std::array<double, 3>>("min"));
        const Vec3d hi = vec(box->require<std::array<double, 3>>("max"));
        box->finish();
        if (!(hi[0] > lo[0] && hi[1] > lo[1] && hi[2] > lo[2]))
            s.failValue("frame", "expected max > min on every axis");
        out.previewFrame = sph::Aabb{sph::Vec3(lo), sph::Vec3(hi)};
    }
}

/// outputs.volume: its file, grids, surface method and voxel sizes.
void readVolume(const JsonObject& s, SceneOutputs& out)
{
    out.volumeFile = outputFile(s, "file", out.volumeFile, {".vdb"}, "OpenVDB grids");
    out.volumeGrids =
        readGridNames(s, out.volumeGrids, {"surface", "density", "vel", "temperature"});
    const std::string method =
        s.choice("surface_method", sph::nameOf(SURFACE_METHOD_NAMES, out.surfaceMethod),
                 surfaceMethodNames());
    out.surfaceMethod = sph::valueOf(SURFACE_METHOD_NAMES, method, "surface method");
    out.voxelSize = s.nonNegative("voxel_size", out.voxelSize);
    out.densityVoxelSize = s.nonNegative("density_voxel_size", out.densityVoxelSize);
    out.volumeSolids = s.get<bool>("solids", out.volumeSolids);
}

/// With outputs.volume.solids, every solid's grid is named after it: the names must differ
/// from each other and from the volume's own grids.
void checkSolidGridNames(const Scene& scene)
{
    if (!scene.outputs.volumeSolids || scene.outputs.volumeFile.empty()) return;
    std::vector<std::string> taken = {"surface", "density", "vel", "temperature"};
    for (const SceneSolid& solid : scene.solids) {
        if (std::find(taken.begin(), taken.end(), solid.name) != taken.end()) {
            throw SceneError(msg("scene '", scene.file, "': outputs.volume.solids: solid name '",
                                 solid.name,
                                 "' is taken by another grid of the volume file: "
                                 "expected solid names unlike each other and surface, density, "
                                 "vel, temperature"));
        }
        taken.push_back(solid.name);
    }
}

/// outputs.mesh's surface: the volume output's method and voxel size, which the mesh section
/// may set where the volume file is not written (else they must be the volume's).
void readMeshSurface(const JsonObject& s, SceneOutputs& out)
{
    const std::string volumeMethod = sph::nameOf(SURFACE_METHOD_NAMES, out.surfaceMethod);
    const std::string method = s.choice("surface_method", volumeMethod, surfaceMethodNames());
    out.meshVoxelSize = s.nonNegative("voxel_size", out.voxelSize);
    if (out.volumeFile.empty()) {
        out.meshSurfaceMethod = sph::valueOf(SURFACE_METHOD_NAMES, method, "surface method");
    } else if (method != volumeMethod) {
        s.failValue("surface_method", msg("expected outputs.volume.surface_method (\"",
                                          volumeMethod, "\"): the mesh is the volume's surface"));
    } else if (out.meshVoxelSize != out.voxelSize) {
        s.failValue("voxel_size", msg("expected outputs.volume.voxel_size (", out.voxelSize,
                                      "): the mesh is the volume's surface"));
    }
}

/// outputs.mesh: its file (a frame pattern, .ply or .obj), adaptivity and surface; `true` for
/// the defaults.
void readMesh(const JsonObject& o, SceneOutputs& out)
{
    const char* const fallback = "liquid.$F4.ply";
    out.meshSurfaceMethod = out.surfaceMethod;
    out.meshVoxelSize = out.voxelSize;
    const Json* v = o.raw("mesh");
    if (v && v->is_boolean() && v->get<bool>()) out.meshFile = fallback;
    readSection(o, "mesh", out.meshFile, [&](const JsonObject& s) {
        out.meshFile = outputFile(s, "file", fallback, {".ply", ".obj"},
                                  "a PLY or OBJ triangle mesh");
        if (!hasFrameToken(out.meshFile)) {
            s.failValue("file", "expected a frame pattern with $F (e.g. liquid.$F4.ply): "
                                "every frame writes its own mesh");
        }
        out.meshAdaptivity = s.inRange("adaptivity", out.meshAdaptivity, 0, 1);
        readMeshSurface(s, out);
    });
}

/// outputs.whitewater: its points file, its fog file and voxel size, the points' radius;
/// `true` for the defaults.
void readWhitewater(const JsonObject& o, SceneOutputs& out)
{
    const char* const fallback = "whitewater.$F4.vdb";
    const Json* v = o.raw("whitewater");
    if (v && v->is_boolean() && v->get<bool>()) out.whitewaterFile = fallback;
    readSection(o, "whitewater", out.whitewaterFile, [&](const JsonObject& s) {
        out.whitewaterFile = outputFile(s, "file", fallback, {".vdb"}, "OpenVDB points");
        out.whitewaterFogFile =
            outputFile(s, "fog_file", out.whitewaterFogFile, {".vdb"}, "OpenVDB grids");
        out.whitewaterFogVoxelSize = s.nonNegative("fog_voxel_size", out.whitewaterFogVoxelSize);
        out.whitewaterRadius = s.nonNegative("radius", out.whitewaterRadius);
        const std::pair<const char*, const std::string*> files[] = {
            {"file", &out.whitewaterFile}, {"fog_file", &out.whitewaterFogFile}};
        for (const auto& [key, file] : files) {
            if (!hasFrameToken(*file)) {
                s.failValue(key, "expected a frame pattern with $F (e.g. whitewater.$F4.vdb): "
                                 "every frame writes its own");
            }
        }
    });
}

void readOutputs(const JsonObject& o, SceneOutputs& out)
{
    const std::vector<std::string> vdb{".vdb"}, h5{".h5", ".hdf5"};
    out.directory = o.get<std::string>("directory", out.directory);
    readSection(o, "points", out.pointsFile, [&](const JsonObject& s) {
        out.pointsFile = outputFile(s, "file", out.pointsFile, vdb, "OpenVDB points");
        out.pointChannels = s.get<std::vector<std::string>>("channels", out.pointChannels);
        out.pointGhosts = s.get<bool>("ghosts", out.pointGhosts);
    });
    readSection(o, "volume", out.volumeFile, [&](const JsonObject& s) { readVolume(s, out); });
    readMesh(o, out);
    readWhitewater(o, out);
    readSection(o, "gas_points", out.gasPointsFile, [&](const JsonObject& s) {
        out.gasPointsFile = outputFile(s, "file", out.gasPointsFile, vdb, "OpenVDB points");
        out.gasPointChannels = s.get<std::vector<std::string>>("channels", out.gasPointChannels);
    });
    readSection(o, "gas_volume", out.gasVolumeFile, [&](const JsonObject& s) {
        out.gasVolumeFile = outputFile(s, "file", out.gasVolumeFile, vdb, "OpenVDB grids");
        out.gasVolumeGrids =
            readGridNames(s, out.gasVolumeGrids, {"density", "vel", "temperature", "smoke"});
        out.gasVoxelSize = s.nonNegative("voxel_size", out.gasVoxelSize);
    });
    out.previewFile.clear();
    readSection(o, "preview", out.previewFile, [&](const JsonObject& s) { readPreview(s, out); });
    if (!out.previewFile.empty() && out.volumeFile.empty() && out.gasVolumeFile.empty()) {
        o.fail("preview", "a preview renders a grid of the volume output, which is off");
    }
    readSection(o, "checkpoint", out.checkpointFile, [&](const JsonObject& s) {
        out.checkpointFile = outputFile(s, "file", out.checkpointFile, h5, "HDF5");
        out.checkpointEvery = int(s.inRange("every", out.checkpointEvery, 0, 1e6));
    });
    readSection(o, "stats", out.statsFile, [&](const JsonObject& s) {
        out.statsFile = outputFile(s, "file", out.statsFile, h5, "HDF5 (and CSV beside it)");
    });
    o.finish();
}

/// Build the JSON document of a role-tagged .vdb scene: every float level-set grid with a
/// ROLE_METADATA string becomes a solid, liquid, emitter or gas source; settings are defaults
/// with the particle spacing at twice the finest voxel size.
Json documentFromRoles(const std::string& path)
{
    std::error_code ec;
    if (!fs::exists(path, ec)) throw IoError(msg("scene '", path, "': file does not exist"));
    openvdb::io::File vdb(path);
    try {
        vdb.open(false);
    } catch (const openvdb::Exception& e) {
        throw IoError(msg("scene '", path, "': not a readable .vdb file (", e.what(), ")"));
    }
    openvdb::GridPtrVecPtr grids = vdb.readAllGridMetadata();
    vdb.close();
    Json doc = {{"ghostfx_scene", SCENE_FORMAT_VERSION}, {"settings", Json::object()}};
    const std::string name = fs::path(path).filename().string();
    double finest = 0;
    for (const auto& grid : *grids) {
        const auto role = grid->getMetadata<openvdb::StringMetadata>(ROLE_METADATA);
        if (!role) continue;
        Json entry = {{"name", grid->getName()},
                      {"geometry", {{"file", name}, {"grid", grid->getName()}}}};
        const std::string r = role->value();
        if (r == "solid") doc["solids"].push_back(entry);
        else if (r == "liquid") doc["liquids"].push_back(entry);
        else if (r == "emitter") doc["emitters"].push_back(entry);
        else if (r == "source") doc["gas_sources"].push_back(entry);
        else {
            throw SceneError(msg("scene '", path, "': grid '", grid->getName(), "' has ",
                                 ROLE_METADATA, " '", r,
                                 "': expected solid, liquid, emitter or source"));
        }
        const double dx = grid->voxelSize()[0];
        if (dx > 0 && (finest == 0 || dx < finest)) finest = dx;
    }
    if (!doc.contains("liquids") && !doc.contains("emitters") && !doc.contains("gas_sources")) {
        throw SceneError(
            msg("scene '", path, "': no grid has ", ROLE_METADATA,
                " 'liquid', 'emitter' or 'source' (a .vdb scene needs grids tagged with roles;"
                " 'ghostfx mesh2sdf --role' writes them)"));
    }
    doc["settings"]["spacing"] = 2 * finest;
    // Sources without liquid: a gas scene.
    if (doc.contains("gas_sources") && !doc.contains("liquids") && !doc.contains("emitters")) {
        doc["settings"]["method"] = "gas";
    }
    return doc;
}

/// A shaped scene entry (solid, liquid, emitter, gas source, heater): its name (default: its
/// path) and its geometry, sampled as `sampled` says.
template <typename Entry>
Entry readShaped(const JsonObject& o, const Scene& scene, Sampled sampled, bool allowFog = false)
{
    const std::string name = o.get<std::string>("name", o.path());
    std::string geometry;
    sph::LevelSet shape = readGeometry(o.object("geometry"), scene, geometry, sampled, allowFog);
    return Entry(name, geometry, std::move(shape));
}

/// `start` (>= 0, default 0) and `end` (> start, default never) of an emitting entry (s).
void readInterval(const JsonObject& o, double& start, double& end)
{
    start = o.nonNegative("start", 0);
    end = o.get<double>("end", std::numeric_limits<double>::infinity());
    if (!(end > start)) o.failValue("end", msg("expected end > start (", start, " s)"));
}

} // namespace

sph::KeyedMotion readMotion(const JsonObject& motion)
{
    sph::KeyedMotion m;
    for (const JsonObject& k : motion.objects("keys")) {
        sph::RigidKey key;
        key.time = k.require<double>("time");
        key.translate = vec(k.get<std::array<double, 3>>("translate", {0, 0, 0}));
        key.rotateDegrees = vec(k.get<std::array<double, 3>>("rotate", {0, 0, 0}));
        k.finish();
        if (!m.keys.empty() && !(key.time > m.keys.back().time)) {
            k.failValue("time", "expected key times in increasing order");
        }
        m.keys.push_back(key);
    }
    if (m.keys.empty()) motion.fail("keys", "expected at least one key");
    motion.finish();
    return m;
}

std::string Scene::simulationFingerprint(const std::vector<std::string>& freeOnResume) const
{
    Json copy = *document;
    copy.erase("outputs");
    if (copy.contains("settings") && copy["settings"].is_object())
        copy["settings"].erase("frame_range");
    for (const std::string& pointer : freeOnResume) {
        const Json::json_pointer key(pointer);
        if (copy.contains(key) && copy[key.parent_pointer()].is_object())
            copy[key.parent_pointer()].erase(key.back());
    }
    return copy.dump();
}

namespace {

/// The scene's document: a .json file, or the role-tagged grids of a .vdb; then the -D
/// overrides.
Json sceneDocument(const std::string& path, const std::vector<std::string>& overrides)
{
    Json doc = extensionOf(path) == ".vdb" ? documentFromRoles(path) : readJsonFile(path, "scene");
    for (const std::string& o : overrides) {
        try {
            applyOverride(doc, o);
        } catch (const SceneError& e) {
            throw SceneError(msg("scene '", path, "': ", e.what()));
        }
    }
    return doc;
}

/// The settings every solver shares; the solver-specific rest is read by the caller.
void readSharedSettings(const JsonObject& root, Scene& scene)
{
    scene.version = root.require<int>("ghostfx_scene");
    if (scene.version != SCENE_FORMAT_VERSION) {
        root.failValue("ghostfx_scene",
                       msg("this ghostfx reads scene format ", SCENE_FORMAT_VERSION));
    }
    scene.settings = root.object("settings");
    const JsonObject& s = scene.settings;
    scene.method = s.get<std::string>("method", "ghost");
    scene.spacing = s.positive("spacing", 0.02);
    if (scene.spacing < MIN_SPACING) {
        s.failValue("spacing",
                    msg("expected at least ", MIN_SPACING,
                        " m (OpenVDB refuses transforms with voxels "
                        "below about 1.5e-5 m, and grids use voxels of half the spacing)"));
    }
    scene.frameRate = s.positive("frame_rate", 30);
    const std::vector<double> range = s.get<std::vector<double>>("frame_range", {1, 24});
    if (range.size() != 2 || !(range[0] >= 1) || !(range[1] >= range[0]) || !(range[1] <= MAX_FRAME)
        || range[0] != std::floor(range[0]) || range[1] != std::floor(range[1])) {
        s.failValue("frame_range", msg("expected [first, last] with 1 <= first <= last <= ",
                                       MAX_FRAME, ", whole numbers"));
    }
    scene.firstFrame = int(range[0]);
    scene.lastFrame = int(range[1]);
}

void readDomain(const JsonObject& root, Scene& scene)
{
    auto domain = root.optionalObject("domain");
    if (!domain) return;
    if (auto kill = domain->optionalObject("kill_box")) {
        const Vec3d lo = vec(kill->require<std::array<double, 3>>("min"));
        const Vec3d hi = vec(kill->require<std::array<double, 3>>("max"));
        kill->finish();
        if (!(hi[0] > lo[0] && hi[1] > lo[1] && hi[2] > lo[2])) {
            domain->failValue("kill_box", "expected max > min on every axis");
        }
        scene.killBox = sph::Aabb{sph::Vec3(lo), sph::Vec3(hi)};
    }
    domain->finish();
}

/// A solid's `dynamic` object: exactly one of `density` and `mass` (> 0), the initial
/// `velocity` and `angular_velocity`, `restitution` (0 to 1) and `friction` (>= 0).
SceneDynamic readDynamic(const JsonObject& d)
{
    SceneDynamic body;
    if (d.has("density") == d.has("mass")) {
        d.finish(); // a misspelt key is reported as an unknown key with the closest one
        d.fail("", "expected exactly one of 'density' (kg/m^3) or 'mass' (kg)");
    }
    if (d.has("density")) body.density = d.positive("density", 0);
    else body.mass = d.positive("mass", 0);
    const auto finiteVector = [&d](const char* key, const char* unit) {
        const Vec3d v = vec(d.get<std::array<double, 3>>(key, {0, 0, 0}));
        if (!std::isfinite(v[0]) || !std::isfinite(v[1]) || !std::isfinite(v[2]))
            d.failValue(key, msg("expected [x, y, z] in ", unit, ", finite numbers"));
        return v;
    };
    body.velocity = finiteVector("velocity", "m/s");
    body.angularVelocity = finiteVector("angular_velocity", "rad/s");
    body.restitution = d.inRange("restitution", body.restitution, 0, 1);
    body.friction = d.nonNegative("friction", body.friction);
    d.finish();
    return body;
}

/// A dynamic solid moves by the liquid and its contacts alone: a `velocity`, a `motion` or a
/// `sequence` of shapes beside `dynamic` is refused, naming the key.
void refuseDrivenDynamic(const JsonObject& o)
{
    const char* why = "a dynamic solid is moved by the liquid and its contacts: expected no ";
    if (o.has("velocity"))
        o.fail("velocity", msg(why, "'velocity' beside 'dynamic' (its start velocity is "
                                    "dynamic.velocity)"));
    if (o.has("motion")) o.fail("motion", msg(why, "'motion' beside 'dynamic'"));
    if (o.has("sequence"))
        o.fail("sequence", msg(why, "'sequence' beside 'dynamic' (its shape sets its mass)"));
}

SceneSolid readSolid(const JsonObject& o, const Scene& scene)
{
    if (o.has("dynamic")) {
        refuseDrivenDynamic(o);
        SceneSolid solid = readShaped<SceneSolid>(o, scene, Sampled::Band);
        solid.dynamic = readDynamic(o.object("dynamic"));
        o.finish();
        return solid;
    }
    SceneSolid solid = readShaped<SceneSolid>(o, scene, Sampled::Band);
    solid.velocity = vec(o.get<std::array<double, 3>>("velocity", {0, 0, 0}));
    if (auto motion = o.optionalObject("motion")) {
        solid.motion = readMotion(*motion);
        if (solid.velocity != Vec3d(0))
            o.fail("velocity", "give either 'velocity' or 'motion', not both");
    }
    if (auto seq = o.optionalObject("sequence")) {
        solid.sequenceFile = resolve(scene.folder, seq->require<std::string>("file"));
        solid.sequenceGrid = seq->require<std::string>("grid");
        seq->finish();
        if (!hasFrameToken(solid.sequenceFile)) {
            seq->failValue("file", "expected a frame pattern with $F (e.g. paddle.$F4.vdb)");
        }
    }
    o.finish();
    return solid;
}

SceneGasSource readGasSource(const JsonObject& o, const Scene& scene)
{
    SceneGasSource source =
        readShaped<SceneGasSource>(o, scene, Sampled::Volume, /*allowFog=*/true);
    source.velocity = vec(o.get<std::array<double, 3>>("velocity", {0, 0, 0}));
    source.temperature = o.positive("temperature", source.temperature);
    source.rate = o.nonNegative("rate", 0);
    readInterval(o, source.start, source.end);
    if (auto motion = o.optionalObject("motion")) source.motion = readMotion(*motion);
    o.finish();
    return source;
}

SceneForceField readForceField(const JsonObject& o)
{
    SceneForceField field;
    field.name = o.get<std::string>("name", o.path());
    if (!o.has("attractor")) {
        o.finish(); // a misspelt kind is reported as an unknown key with the closest one
        o.fail("attractor",
               "missing; expected a field kind: 'attractor' { \"position\": [x, y, z], "
               "\"strength\": S, \"radius\": R }");
    }
    const JsonObject a = o.object("attractor");
    SceneAttractor& at = field.attractor;
    at.position = vec(a.require<std::array<double, 3>>("position"));
    const double strength = a.require<double>("strength");
    if (!std::isfinite(strength))
        a.failValue("strength", "expected a finite number (m/s^2; < 0 repels)");
    at.strength = strength;
    at.radius = a.positive("radius", at.radius);
    at.falloff = a.choice("falloff", at.falloff, {"inverse_square", "constant"});
    a.finish();
    o.finish();
    return field;
}

/// Liquid bodies and emitters: a shape and a few values each.
void readLiquidEntries(const JsonObject& root, Scene& scene)
{
    for (const JsonObject& o : root.objects("liquids")) {
        SceneLiquid liquid = readShaped<SceneLiquid>(o, scene, Sampled::Volume);
        liquid.velocity = vec(o.get<std::array<double, 3>>("velocity", {0, 0, 0}));
        if (o.has("viscosity")) liquid.viscosity = o.require<double>("viscosity");
        o.finish();
        scene.liquids.push_back(std::move(liquid));
    }
    for (const JsonObject& o : root.objects("emitters")) {
        SceneEmitter emitter = readShaped<SceneEmitter>(o, scene, Sampled::Volume);
        emitter.velocity = vec(o.get<std::array<double, 3>>("velocity", {0, 0, 0}));
        readInterval(o, emitter.start, emitter.end);
        if (o.has("viscosity")) emitter.viscosity = o.require<double>("viscosity");
        if (auto motion = o.optionalObject("motion")) emitter.motion = readMotion(*motion);
        o.finish();
        scene.emitters.push_back(std::move(emitter));
    }
}

SceneHeater readHeater(const JsonObject& o, const Scene& scene)
{
    SceneHeater heater = readShaped<SceneHeater>(o, scene, Sampled::None);
    heater.temperature = o.positive("temperature", heater.temperature);
    o.finish();
    return heater;
}

} // namespace

Scene readScene(const std::string& path, const std::vector<std::string>& overrides)
{
    Scene scene;
    scene.file = path;
    scene.folder = fs::path(path).parent_path().string();
    auto shared = std::make_shared<const Json>(sceneDocument(path, overrides));
    scene.document = shared;
    const JsonObject root(shared, shared.get(), "", path);

    readSharedSettings(root, scene);
    readDomain(root, scene);
    for (const JsonObject& o : root.objects("solids")) scene.solids.push_back(readSolid(o, scene));
    readLiquidEntries(root, scene);
    for (const JsonObject& o : root.objects("gas_sources"))
        scene.gasSources.push_back(readGasSource(o, scene));
    for (const JsonObject& o : root.objects("heaters"))
        scene.heaters.push_back(readHeater(o, scene));
    for (const JsonObject& o : root.objects("force_fields"))
        scene.forceFields.push_back(readForceField(o));
    if (auto phase = root.optionalObject("phase_transition")) {
        if (scene.heaters.empty())
            root.fail("phase_transition",
                      "expected heaters: a phase transition needs at least one");
        scene.phaseTransition = *phase;
    }
    if (auto outputs = root.optionalObject("outputs")) readOutputs(*outputs, scene.outputs);
    root.finish();
    checkSolidGridNames(scene);

    // What the method's medium can simulate (gas sources without liquid, heaters with it) is
    // checked by the program's method registry (cmd/Methods.cc), which knows the methods.
    return scene;
}

} // namespace vdbio
} // namespace ghostfx
