/// @file   Simulation.cc
/// @brief  What every simulation shares: the default refusals, the field statistics, and the
///         entry points that go through the method registry.
#include "Simulation.h"

#include "Methods.h"
#include "SimulationParts.h"

#include <ghostfx/sph/Exceptions.h>

#include <algorithm>
#include <cmath>

namespace ghostfx {
namespace cmd {

using sph::ParticleKind;
using sph::Real;
using sph::Vec3;

FieldStats fieldStats(const sph::ParticleSet& p, ParticleKind kind, double rho0,
                      const std::vector<Real>* skip)
{
    FieldStats s;
    double sum = 0;
    for (std::size_t i = 0; i < p.size(); ++i) {
        if (p.kinds()[i] != kind || (skip && (*skip)[i] != Real(0))) continue;
        ++s.count;
        s.maxSpeed = std::max(s.maxSpeed, double(p.velocities()[i].length()));
        const double e = std::abs(double(p.densities()[i]) / rho0 - 1.0);
        sum += e;
        s.errorMax = std::max(s.errorMax, e);
    }
    s.errorMean = s.count ? sum / double(s.count) : 0.0;
    return s;
}

std::vector<sph::Vec3> Simulation::prepareToShare()
{
    throw SceneError("only liquid scenes (method ghost) run on several processes yet; run this "
                     "scene as one process");
}

void Simulation::share(sph::ParticleExchange& /*exchange*/, bool /*ownPart*/)
{
    throw SceneError("only liquid scenes (method ghost) run on several processes yet; run this "
                     "scene as one process");
}

void Simulation::setSolidMotion(std::size_t /*index*/, sph::RigidMotion /*motion*/)
{
    throw ValueError("changing a solid's motion during a run is supported in liquid scenes only");
}

void Simulation::addSolid(const vdbio::SceneSolid& solid)
{
    throw ValueError("solid '" + solid.name
                     + "': adding solids from a script is supported in liquid scenes only");
}

std::pair<sph::Vec3d, sph::Vec3d> Simulation::liquidForceOn(std::size_t index) const
{
    throw ValueError(msg("solid ", index, " is not a dynamic solid"));
}

void Simulation::addBodyForce(std::size_t index, const sph::Vec3d& /*force*/,
                              const sph::Vec3d& /*torque*/)
{
    throw ValueError(msg("solid ", index, " is not a dynamic solid"));
}

void Simulation::addEmitter(const vdbio::SceneEmitter& emitter)
{
    throw ValueError("emitter '" + emitter.name
                     + "': adding emitters from a script is supported in liquid scenes only");
}

void Simulation::addGasSource(const vdbio::SceneGasSource& source)
{
    throw ValueError("gas source '" + source.name
                     + "': adding gas sources from a script is supported in gas and boiling "
                       "scenes only");
}

WritableParticles Simulation::writableParticles(ParticleKind /*kind*/) { return {}; }

std::size_t Simulation::addLiquid(const sph::LevelSet& shape, const Vec3& /*velocity*/,
                                  std::optional<double> /*viscosity*/)
{
    throw ValueError("liquid '" + shape.name()
                     + "': adding liquid from a script is supported in liquid scenes only");
}

std::size_t stateCount(const vdbio::Scene& scene)
{
    if (!scene.heaters.empty()) return 3;
    return scene.outputs.whitewaterFile.empty() ? 1 : 2;
}

namespace {

/// A liquid checkpoint with or without its whitewater fits a liquid scene either way: whitewater
/// asked for after the checkpoint starts at the resumed frame, and a whitewater state is
/// dropped once the scene asks for none.
bool liquidStatesFit(const vdbio::Scene& scene, const std::vector<sph::SolverState>& restored)
{
    if (!scene.heaters.empty() || restored.empty() || restored.size() > 2) return false;
    return restored.size() == 1 || restored[1].solver == "whitewater";
}

} // namespace

void checkSimulationSettings(const vdbio::Scene& scene) { methodOf(scene).check(scene); }

std::unique_ptr<Simulation> makeSimulation(const vdbio::Scene& scene,
                                           const std::vector<sph::SolverState>* restored)
{
    const Method& method = methodOf(scene);
    if (restored && restored->size() != stateCount(scene) && !liquidStatesFit(scene, *restored)) {
        throw SceneError(msg("scene '", scene.file, "': the checkpoint holds ", restored->size(),
                             " solver states, the scene needs ", stateCount(scene),
                             scene.heaters.empty() ? "" : " (a boiling liquid, its vapour and "
                                                          "the phase transition)"));
    }
    return method.make(scene, restored);
}

} // namespace cmd
} // namespace ghostfx
