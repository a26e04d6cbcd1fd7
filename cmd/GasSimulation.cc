/// @file   GasSimulation.cc
/// @brief  A gas scene ([RYY15] fast gas, or its ambient-air and uncorrected baselines) behind
///         Simulation.
#include "GasScene.h"
#include "OneSolverSimulation.h"
#include "SimulationParts.h"

#include <ghostfx/gas/GasFlowStats.h>

#include <cmath>
#include <limits>

namespace ghostfx {
namespace cmd {

using sph::ParticleKind;
using sph::Real;

void copyVisibleGas(const sph::ParticleSet& from, sph::ParticleSet& to)
{
    const bool hasAmbient = from.hasScalarChannel(gas::channel::AMBIENT);
    std::vector<std::uint8_t> remove(from.size(), 0);
    for (std::size_t i = 0; i < from.size(); ++i) {
        remove[i] = from.kinds()[i] != ParticleKind::Gas
                    || (hasAmbient && from.scalarChannel(gas::channel::AMBIENT)[i] != Real(0));
    }
    to = from;
    to.removeIf(remove);
}

WritableParticles writableGas(gas::GasSolver& s, ParticleKind kind)
{
    if (kind != ParticleKind::Gas) return {};
    sph::ParticleSet& p = s.particles();
    return {&p, p.hasScalarChannel(gas::channel::AMBIENT) ? &p.scalarChannel(gas::channel::AMBIENT)
                                                          : nullptr,
            {}};
}

OutputMedium gasMedium(const gas::GasSolver& s, const sph::ParticleSet& visible)
{
    OutputMedium m;
    m.name = "gas";
    m.particles = &visible;
    m.kinds = {ParticleKind::Gas};
    m.spacing = s.settings().spacing;
    m.support = s.settings().supportRadius();
    m.restDensity = s.settings().restDensity;
    m.gravity = s.settings().gravity;
    m.liquid = false;
    m.ambientTemperature = double(s.settings().ambientTemperature);
    m.pendingMass = [&s] { return s.stepCount() == 0 ? double(s.referenceParticleMass()) : 0.0; };
    return m;
}

std::vector<std::pair<std::string, double>> gasStats(const gas::GasSolver& s,
                                                     const gas::GasTimings& before)
{
    const sph::ParticleSet& p = s.particles();
    const std::vector<Real>* ambient = p.hasScalarChannel(gas::channel::AMBIENT)
                                           ? &p.scalarChannel(gas::channel::AMBIENT)
                                           : nullptr;
    const FieldStats f = fieldStats(p, ParticleKind::Gas, s.settings().restDensity, ambient);
    const gas::GasTimings& t = s.timings();
    // The flow's statistics once a frame, in the row of its last step (a step ends a frame
    // exactly on its time); NaN in the other rows.
    const double frames = s.time() * double(s.settings().frameRate);
    const double nan = std::numeric_limits<double>::quiet_NaN();
    gas::GasFlowStats flow{nan, nan, nan};
    if (std::abs(frames - std::round(frames)) < 1e-6) flow = gas::gasFlowStats(p, s.settings());
    return {
        {"count_gas", double(f.count)},
        {"count_ambient", double(s.ambientCount())},
        {"count_gas_boundary", double(s.count(ParticleKind::Boundary))},
        {"gas_max_speed", f.maxSpeed},
        {"gas_density_error_mean", f.errorMean},
        {"gas_density_error_max", f.errorMax},
        {"gas_kinetic_energy", flow.kineticEnergy},
        {"gas_enstrophy", flow.enstrophy},
        {"gas_spread_rate", flow.spreadRate},
        {"t_gas_emission", t.emission - before.emission},
        {"t_gas_neighbors", t.neighbors - before.neighbors},
        {"t_gas_density", t.density - before.density},
        {"t_gas_forces", t.forces - before.forces},
        {"t_gas_integration", t.integration - before.integration},
        {"t_gas_step", t.total - before.total},
    };
}

namespace {

class GasSimulation : public OneSolverSimulation<gas::GasSolver>
{
public:
    GasSimulation(const vdbio::Scene& scene, gas::Method method, const sph::SolverState* restored)
        : OneSolverSimulation(makeGasSolver(scene, readSettings(scene, method), restored))
    {}

    /// settings.gas, and then no other key of settings left unread.
    static gas::GasSettings readSettings(const vdbio::Scene& scene, gas::Method method)
    {
        const vdbio::JsonObject& s = scene.settings;
        const vdbio::JsonObject g = s.has("gas") ? s.object("gas") : vdbio::JsonObject();
        if (g.has("method")) {
            g.fail("method", "a gas scene's method is settings.method (settings.gas.method "
                             "chooses the vapour's method in a boiling scene)");
        }
        gas::GasSettings settings = gasSettings(scene, g, scene.spacing, method);
        s.finish();
        return settings;
    }

    void advanceFrame() override { mSolver->advanceFrame(); }
    void addGasSource(const vdbio::SceneGasSource& source) override
    {
        addSceneGasSource(*mSolver, source);
    }
    WritableParticles writableParticles(ParticleKind kind) override
    {
        return writableGas(*mSolver, kind);
    }

    vdbio::StatsRow statsRow(int frame, double dt) override
    {
        vdbio::StatsRow row;
        row.values = stepColumns(frame, dt);
        for (auto& v : gasStats(*mSolver, mBefore)) row.values.push_back(v);
        row.values.push_back(bytesPerParticle(*this));
        mBefore = mSolver->timings();
        return row;
    }

    std::string counts() const override
    {
        return msg(mSolver->visibleGasCount(), " gas, ", mSolver->ambientCount(), " ambient air, ",
                   mSolver->count(ParticleKind::Boundary), " boundary");
    }
    std::size_t particleCount() const override { return mSolver->particles().size(); }
    std::size_t memoryBytes() const override { return mSolver->particles().memoryBytes(); }

    std::vector<OutputMedium> media() const override
    {
        copyVisibleGas(mSolver->particles(), mVisible);
        return {gasMedium(*mSolver, mVisible)};
    }
    std::vector<MediumCount> mediumCounts() const override
    {
        return {{"gas", mSolver->visibleGasCount()}};
    }

private:
    gas::GasTimings mBefore;
    mutable sph::ParticleSet mVisible;
};

} // namespace

std::unique_ptr<Simulation> makeGasSimulation(const vdbio::Scene& scene, gas::Method method,
                                              const sph::SolverState* restored)
{
    return std::make_unique<GasSimulation>(scene, method, restored);
}

void checkGasSimulation(const vdbio::Scene& scene, gas::Method method)
{
    GasSimulation::readSettings(scene, method);
}

} // namespace cmd
} // namespace ghostfx
