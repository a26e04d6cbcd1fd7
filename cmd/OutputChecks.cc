/// @file   OutputChecks.cc
/// @brief  The outputs checked before the first step (OutputChecks.h).
#include "OutputChecks.h"

#include "FrameWriter.h"

#include <ghostfx/sph/Exceptions.h>
#include <ghostfx/vdbio/AtomicFile.h>
#include <ghostfx/vdbio/FrameFiles.h>
#include <ghostfx/vdbio/MeshFile.h>

#include <algorithm>
#include <filesystem>
#include <unistd.h>

namespace ghostfx {
namespace cmd {

namespace fs = std::filesystem;

namespace {

/// The grids a medium's volume file holds (the writer's order: surface, density, vel, then
/// the channels).
std::vector<std::string> volumeGridNames(const vdbio::VolumeOptions& vo)
{
    std::vector<std::string> names;
    if (vo.surface) names.push_back("surface");
    if (vo.density) names.push_back("density");
    if (vo.velocity) names.push_back("vel");
    names.insert(names.end(), vo.scalarChannels.begin(), vo.scalarChannels.end());
    return names;
}

bool contains(const std::vector<std::string>& names, const std::string& name)
{
    return std::find(names.begin(), names.end(), name) != names.end();
}

/// outputs.preview.grid (or its default: the liquid's surface, else its density; the gas's
/// density) must be a float grid that some medium's volume output builds.
void checkPreviewGrid(const vdbio::Scene& scene, const std::vector<OutputMedium>& media)
{
    const vdbio::SceneOutputs& out = scene.outputs;
    if (out.previewFile.empty()) return;
    bool found = false;
    for (const OutputMedium& m : media) {
        if ((m.liquid ? out.volumeFile : out.gasVolumeFile).empty()) continue;
        std::vector<std::string> built = volumeGridNames(volumeOptions(m, out));
        built.erase(std::remove(built.begin(), built.end(), "vel"), built.end()); // not a float
        if (!out.previewGrid.empty()) {
            found = found || contains(built, out.previewGrid);
        } else {
            found = found || contains(built, "density") || (m.liquid && contains(built, "surface"));
        }
    }
    if (found) return;
    throw SceneError(msg("scene '", scene.file, "': outputs.preview.grid = '",
                         out.previewGrid.empty() ? "(default)" : out.previewGrid,
                         "': the volume output has no such grid"));
}

/// outputs.mesh: the liquid's surface, so a scene with no liquid (a gas scene) has none to
/// mesh; the liquid's surface and velocity options as the volume output checks them.
void checkMesh(const vdbio::Scene& scene, const std::vector<OutputMedium>& media)
{
    const vdbio::SceneOutputs& out = scene.outputs;
    if (out.meshFile.empty()) return;
    const std::string key = msg("scene '", scene.file, "': outputs.mesh");
    bool liquid = false;
    for (const OutputMedium& m : media) {
        if (!m.liquid) continue;
        liquid = true;
        vdbio::checkVolumeOutput(*m.particles, meshVolumeOptions(m, out), key);
    }
    if (!liquid) {
        throw SceneError(msg(key, ": a mesh is made of the liquid's surface, and this ",
                             scene.method, " scene has no liquid (switch outputs.mesh off; "
                             "outputs.gas_volume writes the gas density)"));
    }
    vdbio::MeshOptions options;
    options.adaptivity = out.meshAdaptivity;
    options.validate();
}

} // namespace

void checkOutputFolders(const vdbio::Scene& scene, const std::string& folder)
{
    const vdbio::SceneOutputs& out = scene.outputs;
    if (out.meshFile.empty()) return;
    const fs::path dir =
        (fs::path(folder) / vdbio::expandFramePattern(out.meshFile, scene.firstFrame))
            .parent_path();
    std::error_code ec;
    const char* why = !fs::is_directory(dir, ec)        ? "does not exist or is not a folder"
                      : ::access(dir.c_str(), W_OK) != 0 ? "cannot be written"
                                                         : nullptr;
    if (!why) return;
    throw IoError(msg("scene '", scene.file, "': outputs.mesh.file = '", out.meshFile,
                      "': folder '", dir.string(), "' ", why));
}

void checkOutputs(const vdbio::Scene& scene, const Simulation& sim)
{
    const vdbio::SceneOutputs& out = scene.outputs;
    const std::vector<OutputMedium> media = sim.media();
    for (const OutputMedium& m : media) {
        const std::string key = msg("scene '", scene.file, "': outputs.", m.liquid ? "" : "gas_");
        if (!(m.liquid ? out.pointsFile : out.gasPointsFile).empty()) {
            vdbio::checkPointsOutput(*m.particles, pointsOptions(m, out), key + "points.channels");
        }
        if (!(m.liquid ? out.volumeFile : out.gasVolumeFile).empty()) {
            const vdbio::VolumeOptions vo = volumeOptions(m, out);
            vdbio::checkVolumeOutput(*m.particles, vo, key + "volume.grids");
        }
    }
    checkPreviewGrid(scene, media);
    checkMesh(scene, media);
}

} // namespace cmd
} // namespace ghostfx
