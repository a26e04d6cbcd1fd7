/// @file   SceneWhitewater.h
/// @brief  A scene's whitewater (ghost::Whitewater: spray, foam and bubbles) over its frames,
///         inline in `ghostfx run` or over a written points sequence (`ghostfx whitewater`).
/// @details Both read the liquid as its points file holds it: world positions rebuilt from the
///          file's voxels and float offsets, float velocities, ids. Inline, the frame's points
///          grid is built in memory exactly as the points output writes it and read back the
///          same way a post-process reads the file, so a post-process over the files of a run
///          makes the same whitewater as the run did, bit for bit. Whitewater steps once per
///          frame by 1 / frame_rate; the scene's kill box and its solids where they are at the
///          frame's time remove it.
#pragma once

#include "Simulation.h"

#include <ghostfx/ghost/GhostSettings.h>
#include <ghostfx/ghost/Whitewater.h>
#include <ghostfx/vdbio/BodyTable.h>
#include <ghostfx/vdbio/Readers.h>
#include <ghostfx/vdbio/Scene.h>
#include <ghostfx/vdbio/WhitewaterFile.h>

#include <string>
#include <vector>

namespace ghostfx {
namespace cmd {

/// settings.whitewater of a liquid scene, every key read and checked; SceneError naming the
/// scene and the key.
ghost::WhitewaterSettings whitewaterSettings(const vdbio::Scene& scene);

/// The liquid particles of a points grid's columns (those of kind liquid where the grid has
/// "kind"): "P", "v" and "id". SceneError naming `where` when "v" or "id" is missing.
ghost::LiquidSnapshot liquidOfPoints(const vdbio::PointsData& points,
                                     const ghost::GhostSettings& liquid, const std::string& where);

/// The columns of the liquid's points grid as the points output would write it now (its
/// particles, kinds and voxel size), with only "v", "id" and, with ghosts, "kind".
vdbio::PointsData liquidPointsOf(const OutputMedium& liquid, const vdbio::SceneOutputs& out,
                                 double time);

/// Where a run's dynamic solids were at `frame`, from its bodies.csv `rows`: a placement per
/// scene solid (identity for the others). IoError naming `csv` for a dynamic solid without a
/// row at that frame.
std::vector<sph::RigidTransform> bodyPlacements(const vdbio::Scene& scene,
                                                const std::vector<vdbio::BodyRow>& rows, int frame,
                                                const std::string& csv);

/// The points radius ("pscale", m) of outputs.whitewater: its `radius`, else h / 4.
double whitewaterRadius(const vdbio::Scene& scene);

class SceneWhitewater
{
public:
    SceneWhitewater(const vdbio::Scene& scene, const ghost::GhostSettings& liquid);

    /// Move and make whitewater over frame `frame` (it ends at frame / frame_rate), in the
    /// liquid of `points` (liquidPointsOf, or a points file; `where` names it in errors).
    /// `placements`: where the solver put each solid; used for dynamic solids only (the
    /// others are where the scene's motion puts them, as a post-process places them).
    void step(const vdbio::PointsData& points, int frame,
              const std::vector<sph::RigidTransform>& placements, const std::string& where);

    const ghost::Whitewater& whitewater() const { return mWhitewater; }
    /// The particles as arrays for the files.
    vdbio::WhitewaterPoints points() const;

    sph::SolverState saveState() const { return mWhitewater.saveState(); }
    void restoreState(const sph::SolverState& state);

private:
    const vdbio::Scene& mScene;
    ghost::GhostSettings mLiquid;
    ghost::Whitewater mWhitewater;
};

/// The whitewater file and, with a fog voxel size, the fog file of outputs.whitewater for one
/// frame (paths already expanded; `fogPath` empty: none).
void writeWhitewaterFiles(const vdbio::Scene& scene, const vdbio::WhitewaterPoints& points,
                          const std::string& path, const std::string& fogPath,
                          const openvdb::MetaMap& fileMeta);

} // namespace cmd
} // namespace ghostfx
