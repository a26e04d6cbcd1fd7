/// @file   FrameOutputs.cc
/// @brief  A frame's files from its snapshot (FrameWriter.h, writeFrameOutputs): each medium's
///         points and volume files, the liquid's mesh and whitewater, and the preview of the scene with its
///         solids where they are.
#include "FrameWriter.h"
#include "SceneWhitewater.h"
#include "SolidGrids.h"

#include <ghostfx/sph/Exceptions.h>
#include <ghostfx/sph/LevelSetGrid.h>
#include <ghostfx/vdbio/AtomicFile.h>
#include <ghostfx/vdbio/FrameFiles.h>
#include <ghostfx/vdbio/MeshFile.h>
#include <ghostfx/vdbio/Preview.h>
#include <ghostfx/vdbio/Scene.h>
#include <ghostfx/vdbio/ScenePreview.h>

#include <openvdb/openvdb.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <optional>

namespace ghostfx {
namespace cmd {

namespace fs = std::filesystem;

namespace {

/// The world box of the media's active voxels.
openvdb::BBoxd mediaBox(const std::vector<vdbio::PreviewLayer>& media)
{
    openvdb::BBoxd box;
    for (const vdbio::PreviewLayer& l : media) {
        const openvdb::CoordBBox ibox = l.grid->evalActiveVoxelBoundingBox();
        if (ibox.empty()) continue;
        box.expand(l.grid->indexToWorld(ibox.min()));
        box.expand(l.grid->indexToWorld(ibox.max()));
    }
    return box;
}

/// The scene's solids where they are at the snapshot's time (rigid motion from the scene's keys
/// or velocity, a per-frame shape from its file), as preview layers. A solid around the media's
/// centre (the centre is inside its box but outside the solid: a tank) is cut away so what it
/// holds shows.
std::vector<vdbio::PreviewLayer> solidLayers(const vdbio::Scene& scene,
                                             const FrameSnapshot& snapshot,
                                             const openvdb::BBoxd& media)
{
    std::vector<vdbio::PreviewLayer> layers;
    for (std::size_t i = 0; i < scene.solids.size(); ++i) {
        const vdbio::SceneSolid& solid = scene.solids[i];
        const PlacedSolid placed = placedSolid(scene, snapshot, i);
        const sph::LevelSet& shape = placed.shape;
        vdbio::PreviewLayer layer;
        layer.name = solid.name;
        layer.grid = sph::gridOf(shape);
        layer.albedo = vdbio::SOLID_ALBEDO;
        // A solid that neither moves nor changes shape looks the same in every frame.
        layer.fixed = solid.isStatic();
        layer.rotation = placed.rotation;
        layer.translation = placed.translation;
        if (media.max().x() >= media.min().x()) {
            const openvdb::Vec3d centre = media.getCenter();
            const openvdb::Vec3d local = layer.rotation.transpose() * (centre - layer.translation);
            // The level set keeps its active box (walking a large solid's tree every frame cost
            // more than drawing it).
            const sph::Aabb b = shape.bounds();
            const openvdb::BBoxd box(openvdb::Vec3d(b.min), openvdb::Vec3d(b.max));
            layer.cutaway = box.isInside(local) && shape.phi(sph::Vec3(local)) > 0;
        }
        layers.push_back(layer);
    }
    return layers;
}

/// Write one medium's points and volume files for `frame`; returns its grids (for previews).
/// `time` (s): the frame's time. `built`: the grids already built (a run over several processes),
/// else built here.
openvdb::GridPtrVec writeMedium(const OutputMedium& m, const vdbio::SceneOutputs& out,
                                const std::string& pointsPath, const std::string& volumePath,
                                const openvdb::MetaMap& fileMeta, double time,
                                const BuiltGrids* built, const openvdb::GridPtrVec& solids)
{
    if (!pointsPath.empty()) {
        if (built) {
            vdbio::writePointsGridFile(pointsPath, built->points, fileMeta);
        } else if (out.pointGhosts && m.withGhosts) {
            vdbio::writePointsFile(pointsPath, m.withGhosts(), pointsOptions(m, out, time), fileMeta);
        } else {
            vdbio::writePointsFile(pointsPath, *m.particles, pointsOptions(m, out, time), fileMeta);
        }
    }
    if (volumePath.empty()) return {};
    const openvdb::GridPtrVec grids =
        built ? built->volumes : vdbio::makeVolumeGrids(*m.particles, volumeOptions(m, out));
    openvdb::GridPtrVec written = grids;
    written.insert(written.end(), solids.begin(), solids.end());
    vdbio::writeVolumeFile(volumePath, written, fileMeta);
    return grids;
}

/// The grid of `grids` named `name` as a `GridT`, or null.
template <typename GridT>
typename GridT::Ptr gridNamed(const openvdb::GridPtrVec& grids, const std::string& name)
{
    for (const openvdb::GridBase::Ptr& g : grids) {
        if (g->getName() == name) return openvdb::gridPtrCast<GridT>(g);
    }
    return nullptr;
}

/// Write the liquid's mesh file `path` of `frame` from the "surface" and "vel" grids of the
/// volume file (`volumeGrids`) when it holds both, else from grids made for the mesh
/// (meshVolumeOptions: the same surface and velocity); returns the log line (its counts, the
/// volume it encloses, and the seconds meshing and writing took).
std::string writeMesh(const OutputMedium& m, const vdbio::SceneOutputs& out,
                      const openvdb::GridPtrVec& volumeGrids, const std::string& path, int frame,
                      const openvdb::MetaMap& fileMeta, const BuiltGrids* built)
{
    openvdb::GridPtrVec grids;
    if (!out.volumeFile.empty() && volumeHoldsMeshGrids(volumeOptions(m, out))) {
        grids = volumeGrids;
    } else if (built) {
        grids = built->mesh;
    } else {
        grids = vdbio::makeVolumeGrids(*m.particles, meshVolumeOptions(m, out));
    }
    const openvdb::FloatGrid::Ptr surface = gridNamed<openvdb::FloatGrid>(grids, "surface");
    const openvdb::Vec3SGrid::Ptr vel = gridNamed<openvdb::Vec3SGrid>(grids, "vel");
    if (!surface || !vel) {
        throw SceneError(msg("outputs.mesh: frame ", frame, " has no liquid surface and velocity "
                             "grids to mesh"));
    }
    vdbio::MeshOptions options;
    options.adaptivity = out.meshAdaptivity;
    const auto start = std::chrono::steady_clock::now();
    const vdbio::SurfaceMesh mesh = vdbio::makeSurfaceMesh(*surface, vel.get(), options);
    vdbio::writeMeshFile(path, mesh, vdbio::meshComments(fileMeta));
    const double seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    char took[32];
    std::snprintf(took, sizeof(took), "%.2f s", seconds);
    return msg("mesh of frame ", frame, " '", path, "': ", mesh.points.size(), " vertices, ",
               mesh.triangles.size(), " triangles, ", mesh.enclosedVolume(), " m^3 enclosed, ",
               took);
}

/// The file metadata every frame file carries: the scene, its method, the frame and its time.
openvdb::MetaMap frameMetadata(const vdbio::Scene& scene, const FrameSnapshot& snapshot)
{
    openvdb::MetaMap meta;
    meta.insertMeta("ghostfx_scene", openvdb::StringMetadata(scene.file));
    meta.insertMeta("ghostfx_method", openvdb::StringMetadata(scene.method));
    meta.insertMeta("frame", openvdb::Int32Metadata(snapshot.frame));
    meta.insertMeta("time", openvdb::DoubleMetadata(snapshot.time));
    return meta;
}

/// The preview layer of one medium's grids: outputs.preview.grid where the medium has it, else
/// its default (the liquid's surface, else its density; the gas's density). Sets
/// `namedGridFound` when the one drawn is outputs.preview.grid.
std::optional<vdbio::PreviewLayer> mediumLayer(const OutputMedium& m,
                                               const openvdb::GridPtrVec& grids,
                                               const std::string& previewGrid,
                                               bool& namedGridFound)
{
    std::vector<std::string> wanted = m.liquid ? std::vector<std::string>{"surface", "density"}
                                               : std::vector<std::string>{"density"};
    if (!previewGrid.empty()) wanted.insert(wanted.begin(), previewGrid);
    for (const std::string& name : wanted) {
        auto g = std::find_if(grids.begin(), grids.end(),
                              [&](const auto& grid) { return grid->getName() == name; });
        auto floatGrid = g == grids.end() ? nullptr : openvdb::gridPtrCast<openvdb::FloatGrid>(*g);
        if (!floatGrid) continue;
        vdbio::PreviewLayer layer;
        layer.name = m.name + " " + name;
        layer.grid = floatGrid;
        layer.kind = floatGrid->getGridClass() == openvdb::GRID_LEVEL_SET
                         ? vdbio::PreviewLayer::Kind::Surface
                         : vdbio::PreviewLayer::Kind::Fog;
        layer.albedo = m.liquid ? vdbio::LIQUID_ALBEDO : vdbio::GAS_ALBEDO;
        namedGridFound = namedGridFound || name == previewGrid;
        return layer;
    }
    return std::nullopt;
}

/// The whitewater as a white fog layer: every class's volume fraction (WhitewaterFile.h) at the
/// fog output's voxel size, else h / 2, with the extinction of spheres of its radius r: spheres
/// much larger than the wavelength remove light over twice their cross-section pi r^2, which is
/// 1.5 / r per metre at volume fraction 1.
vdbio::PreviewLayer whitewaterLayer(const vdbio::Scene& scene, const vdbio::WhitewaterPoints& w)
{
    const double fog = scene.outputs.whitewaterFogVoxelSize;
    const double radius = whitewaterRadius(scene);
    vdbio::PreviewLayer layer;
    layer.name = "whitewater";
    layer.grid = vdbio::makeWhitewaterFog(w, -1, fog > 0 ? fog : scene.spacing / 2, radius,
                                          "whitewater");
    layer.kind = vdbio::PreviewLayer::Kind::Fog;
    layer.albedo = vdbio::WHITEWATER_ALBEDO;
    layer.extinction = 1.5 / radius;
    return layer;
}

/// The camera and image of outputs.preview.
vdbio::PreviewOptions previewOptions(const vdbio::SceneOutputs& out)
{
    vdbio::PreviewOptions pv;
    pv.width = out.previewWidth;
    pv.height = out.previewHeight;
    pv.azimuth = out.previewAzimuth;
    pv.elevation = out.previewElevation;
    if (out.previewBackground) {
        const auto& c = *out.previewBackground;
        pv.background = {float(c[0]), float(c[1]), float(c[2]), 1.0f};
    }
    return pv;
}

/// Render the preview of a frame from its media's layers, the solids drawn where they are.
void writePreview(const vdbio::Scene& scene, const FrameSnapshot& snapshot,
                  const std::vector<vdbio::PreviewLayer>& media, const std::string& path,
                  vdbio::PreviewCache* previewCache)
{
    const vdbio::SceneOutputs& out = scene.outputs;
    std::vector<vdbio::PreviewLayer> layers;
    if (out.previewSolids) layers = solidLayers(scene, snapshot, mediaBox(media));
    layers.insert(layers.end(), media.begin(), media.end());
    openvdb::BBoxd framed; // empty: the camera frames everything drawn
    if (!out.previewFrame.empty()) {
        framed = openvdb::BBoxd(openvdb::Vec3d(out.previewFrame.min),
                                openvdb::Vec3d(out.previewFrame.max));
    }
    vdbio::renderScenePreview(layers, previewOptions(out), framed, path, previewCache);
}

} // namespace

std::vector<std::string> writeFrameOutputs(const vdbio::Scene& scene,
                                           const FrameSnapshot& snapshot,
                                           const std::string& folder,
                                           vdbio::PreviewCache* previewCache)
{
    const vdbio::SceneOutputs& out = scene.outputs;
    auto inFolder = [&](const std::string& pattern) {
        return pattern.empty() ? std::string()
                               : (fs::path(folder) / vdbio::expandFramePattern(pattern, snapshot.frame))
                                     .string();
    };
    const openvdb::MetaMap fileMeta = frameMetadata(scene, snapshot);
    std::vector<vdbio::PreviewLayer> media;
    std::vector<std::string> notes;
    bool namedGridFound = false;
    for (std::size_t index = 0; index < snapshot.media.size(); ++index) {
        const OutputMedium& m = snapshot.media[index];
        const BuiltGrids* built = index < snapshot.built.size() ? &snapshot.built[index] : nullptr;
        const openvdb::GridPtrVec grids = writeMedium(
            m, out, inFolder(m.liquid ? out.pointsFile : out.gasPointsFile),
            inFolder(m.liquid ? out.volumeFile : out.gasVolumeFile), fileMeta, snapshot.time, built,
            m.liquid && out.volumeSolids && !out.volumeFile.empty()
                ? placedSolidGrids(scene, snapshot)
                : openvdb::GridPtrVec());
        if (m.liquid && !out.meshFile.empty()) {
            notes.push_back(writeMesh(m, out, grids, inFolder(out.meshFile), snapshot.frame,
                                      fileMeta, built));
        }
        if (out.previewFile.empty()) continue;
        if (auto layer = mediumLayer(m, grids, out.previewGrid, namedGridFound))
            media.push_back(*layer);
    }
    if (snapshot.whitewater && !out.whitewaterFile.empty()) {
        writeWhitewaterFiles(scene, *snapshot.whitewater, inFolder(out.whitewaterFile),
                             out.whitewaterFogVoxelSize > 0 ? inFolder(out.whitewaterFogFile)
                                                            : std::string(),
                             fileMeta);
    }
    if (out.previewFile.empty()) return notes;
    // checkOutputs() refused this before the first step; a medium's grids can still be missing
    // (a frame written by a script).
    if (media.empty() || (!out.previewGrid.empty() && !namedGridFound)) {
        throw SceneError(msg("scene '", scene.file, "': outputs.preview.grid = '",
                             out.previewGrid.empty() ? "(default)" : out.previewGrid,
                             "': the volume output has no such grid"));
    }
    if (snapshot.whitewater) media.push_back(whitewaterLayer(scene, *snapshot.whitewater));
    writePreview(scene, snapshot, media, inFolder(out.previewFile), previewCache);
    return notes;
}

} // namespace cmd
} // namespace ghostfx
