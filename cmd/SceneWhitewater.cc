/// @file   SceneWhitewater.cc
#include "SceneWhitewater.h"

#include "FrameWriter.h"
#include "SettingReader.h"
#include "SolidGrids.h"

#include <ghostfx/sph/Exceptions.h>
#include <ghostfx/sph/MassProperties.h>
#include <ghostfx/sph/RigidBody.h>
#include <ghostfx/vdbio/FrameFiles.h>

#include <algorithm>
#include <limits>

namespace ghostfx {
namespace cmd {

using sph::Real;
using sph::Vec3;

ghost::WhitewaterSettings whitewaterSettings(const vdbio::Scene& scene)
{
    ghost::WhitewaterSettings w;
    if (scene.settings.has("whitewater")) {
        const vdbio::JsonObject o = scene.settings.object("whitewater");
        readSettingTable(o, ghost::whitewaterSettingTable(), w);
        o.finish();
    }
    validateSceneSettings(scene.file, w);
    return w;
}

namespace {

/// The column `name` of `points`, or null.
const vdbio::Column* columnNamed(const vdbio::PointsData& points, const char* name)
{
    for (const vdbio::Column& c : points.columns)
        if (c.name == name) return &c;
    return nullptr;
}

/// The column `name` with `components` components, or a SceneError naming `where`.
const vdbio::Column& requireColumn(const vdbio::PointsData& points, const char* name,
                                   int components, const std::string& where)
{
    const vdbio::Column* c = columnNamed(points, name);
    if (!c || c->components != components) {
        throw SceneError(msg(where, ": grid '", points.grid, "' has no ",
                             components == 3 ? "vector" : "scalar", " attribute '", name,
                             "': whitewater reads the liquid's P, v and id (outputs.points."
                             "channels must hold \"v\" and \"id\")"));
    }
    return *c;
}

} // namespace

ghost::LiquidSnapshot liquidOfPoints(const vdbio::PointsData& points,
                                     const ghost::GhostSettings& liquid, const std::string& where)
{
    ghost::LiquidSnapshot s;
    s.spacing = liquid.spacing;
    s.supportFactor = liquid.supportFactor;
    s.gravity = liquid.gravity;
    if (points.count == 0) return s;
    const vdbio::Column& p = requireColumn(points, "P", 3, where);
    const vdbio::Column& v = requireColumn(points, "v", 3, where);
    const vdbio::Column& id = requireColumn(points, "id", 1, where);
    const vdbio::Column* kind = columnNamed(points, "kind");
    for (std::size_t r = 0; r < points.count; ++r) {
        if (kind && kind->value(r, 0) != double(int(sph::ParticleKind::Liquid))) continue;
        s.positions.emplace_back(Real(p.value(r, 0)), Real(p.value(r, 1)), Real(p.value(r, 2)));
        s.velocities.emplace_back(Real(v.value(r, 0)), Real(v.value(r, 1)), Real(v.value(r, 2)));
        s.ids.push_back(sph::ParticleId(id.value(r, 0)));
    }
    return s;
}

vdbio::PointsData liquidPointsOf(const OutputMedium& liquid, const vdbio::SceneOutputs& out,
                                 double time)
{
    vdbio::PointsOptions options = pointsOptions(liquid, out, time);
    const bool ghosts = options.kinds.size() > 1;
    options.channels =
        ghosts ? std::vector<std::string>{"v", "id", "kind"} : std::vector<std::string>{"v", "id"};
    const openvdb::GridBase::Ptr grid =
        ghosts && liquid.withGhosts
            ? vdbio::makePointsGrid(liquid.withGhosts(), options, "whitewater")
            : vdbio::makePointsGrid(*liquid.particles, options, "whitewater");
    return vdbio::readPointsGrid(*grid, "whitewater");
}

std::vector<sph::RigidTransform> bodyPlacements(const vdbio::Scene& scene,
                                                const std::vector<vdbio::BodyRow>& rows, int frame,
                                                const std::string& csv)
{
    std::vector<sph::RigidTransform> placements(scene.solids.size());
    for (std::size_t i = 0; i < scene.solids.size(); ++i) {
        const vdbio::SceneSolid& solid = scene.solids[i];
        if (!solid.dynamic) continue;
        const auto row = std::find_if(rows.begin(), rows.end(), [&](const vdbio::BodyRow& r) {
            return r.frame == frame && r.name == solid.name;
        });
        if (row == rows.end()) {
            throw IoError(msg("ghostfx whitewater: '", csv, "' has no row of dynamic solid '",
                              solid.name, "' at frame ", frame));
        }
        // A body row is its centre of mass x and orientation q: world = R(q) (p - c) + x, c the
        // centre of mass of the geometry as given (BodyTable.h).
        const auto& v = row->values;
        const sph::Mat3d R = sph::rotationOf(sph::Quatd(v[4], v[5], v[6], v[3]));
        const sph::Vec3d c = sph::massProperties(solid.shape, 1.0).centre;
        const sph::Vec3d t = sph::Vec3d(v[0], v[1], v[2]) - R * c;
        for (int r = 0; r < 3; ++r) {
            for (int k = 0; k < 3; ++k) placements[i].rotation(r, k) = Real(R(r, k));
        }
        placements[i].translation = Vec3(t);
    }
    return placements;
}

double whitewaterRadius(const vdbio::Scene& scene)
{
    const double r = scene.outputs.whitewaterRadius;
    return r > 0 ? r : scene.spacing / 4;
}

SceneWhitewater::SceneWhitewater(const vdbio::Scene& scene, const ghost::GhostSettings& liquid)
    : mScene(scene)
    , mLiquid(liquid)
    , mWhitewater(whitewaterSettings(scene))
{
    mWhitewater.setKillBox(scene.killBox);
}

void SceneWhitewater::step(const vdbio::PointsData& points, int frame,
                           const std::vector<sph::RigidTransform>& placements,
                           const std::string& where)
{
    FrameSnapshot at;
    at.frame = frame;
    at.time = double(frame) / mScene.frameRate;
    std::vector<PlacedSolid> solids;
    for (std::size_t i = 0; i < mScene.solids.size(); ++i) {
        // Only a dynamic solid takes the solver's placement: the scene's motion places the
        // others, as it does in a post-process, which has no solver.
        at.solidPlacements.clear();
        if (mScene.solids[i].dynamic && i < placements.size()) at.solidPlacements = placements;
        solids.push_back(placedSolid(mScene, at, i));
    }
    mWhitewater.setSolids([solids = std::move(solids)](const Vec3& x) {
        Real nearest = std::numeric_limits<Real>::max();
        for (const PlacedSolid& s : solids) {
            const openvdb::Vec3d local =
                s.rotation.transpose() * (openvdb::Vec3d(x) - s.translation);
            nearest = std::min(nearest, s.shape.phi(Vec3(local)));
        }
        return nearest;
    });
    mWhitewater.step(liquidOfPoints(points, mLiquid, where), Real(1.0 / mScene.frameRate));
}

vdbio::WhitewaterPoints SceneWhitewater::points() const
{
    vdbio::WhitewaterPoints p;
    const ghost::Whitewater& w = mWhitewater;
    p.positions = w.positions();
    p.velocities = w.velocities();
    p.ids.assign(w.ids().begin(), w.ids().end());
    for (ghost::WhitewaterType t : w.types()) p.types.push_back(std::int32_t(t));
    p.ages.assign(w.ages().begin(), w.ages().end());
    return p;
}

void SceneWhitewater::restoreState(const sph::SolverState& state)
{
    try {
        mWhitewater.restoreState(state);
    } catch (const ValueError& e) {
        throw SceneError(msg("scene '", mScene.file, "': the checkpoint's whitewater: ", e.what()));
    }
}

void writeWhitewaterFiles(const vdbio::Scene& scene, const vdbio::WhitewaterPoints& points,
                          const std::string& path, const std::string& fogPath,
                          const openvdb::MetaMap& fileMeta)
{
    vdbio::WhitewaterGridOptions options;
    options.pscale = whitewaterRadius(scene);
    options.fogVoxelSize = fogPath.empty() ? 0 : scene.outputs.whitewaterFogVoxelSize;
    openvdb::GridPtrVec grids = vdbio::makeWhitewaterGrids(points, options);
    // The points alone in their file: Blender and pyopenvdb refuse a file that mixes them with
    // volumes.
    vdbio::writeWhitewaterFile(path, {grids.front()}, fileMeta);
    if (grids.size() > 1)
        vdbio::writeWhitewaterFile(fogPath, openvdb::GridPtrVec(grids.begin() + 1, grids.end()),
                                   fileMeta);
}

} // namespace cmd
} // namespace ghostfx
