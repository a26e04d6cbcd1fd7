/// @file   OutputChecks.cc
/// @brief  The outputs checked before the first step (OutputChecks.h).
#include "OutputChecks.h"

#include "FrameWriter.h"

#include <ghostfx/sph/Exceptions.h>
#include <ghostfx/vdbio/FrameFiles.h>

#include <algorithm>

namespace ghostfx {
namespace cmd {

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

} // namespace

void checkOutputs(const vdbio::Scene& scene, const Simulation& sim)
{
    const vdbio::SceneOutputs& out = scene.outputs;
    const std::vector<OutputMedium> media = sim.media();
    for (const OutputMedium& m : media) {
        const std::string key = msg("scene '", scene.file, "': outputs.", m.liquid ? "" : "gas_");
        if (!(m.liquid ? out.pointsFile : out.gasPointsFile).empty()) {
            vdbio::checkPointsOutput(*m.particles, pointsOptions(m, out, sim.time()), key + "points.channels");
        }
        if (!(m.liquid ? out.volumeFile : out.gasVolumeFile).empty()) {
            const vdbio::VolumeOptions vo = volumeOptions(m, out);
            vdbio::checkVolumeOutput(*m.particles, vo, key + "volume.grids");
        }
    }
    checkPreviewGrid(scene, media);
}

} // namespace cmd
} // namespace ghostfx
