/// @file   GasSimulation.cc
/// @brief  A gas scene ([RYY15] fast gas, or its ambient-air and uncorrected baselines) behind
///         Simulation.
#include "GasScene.h"
#include "SimulationParts.h"

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
    return {
        {"count_gas", double(f.count)},
        {"count_ambient", double(s.ambientCount())},
        {"count_gas_boundary", double(s.count(ParticleKind::Boundary))},
        {"gas_max_speed", f.maxSpeed},
        {"gas_density_error_mean", f.errorMean},
        {"gas_density_error_max", f.errorMax},
        {"t_gas_emission", t.emission - before.emission},
        {"t_gas_neighbors", t.neighbors - before.neighbors},
        {"t_gas_density", t.density - before.density},
        {"t_gas_forces", t.forces - before.forces},
        {"t_gas_integration", t.integration - before.integration},
        {"t_gas_step", t.total - before.total},
    };
}

namespace {

class GasSimulation : public Simulation
{
public:
    GasSimulation(const vdbio::Scene& scene, gas::Method method, const sph::SolverState* restored)
        : mSolver(makeGasSolver(scene, readSettings(scene, method), restored))
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
    int frame() const override { return mSolver->frame(); }
    double time() const override { return mSolver->time(); }
    std::uint64_t stepCount() const override { return mSolver->stepCount(); }
    double fixedTimeStep() const override { return fixedStep(mSolver->settings()); }
    double stabilityLimit() const override
    {
        return double(mSolver->stableTimeStep()) / double(mSolver->settings().cflNumber);
    }

    double cflTimeStep() const override { return double(mSolver->stableTimeStep()); }

    void setStepObserver(std::function<void(double)> observer) override
    {
        mSolver->setStepObserver(
            [observer](const gas::GasSolver&, Real dt) { observer(double(dt)); });
    }

    vdbio::StatsRow statsRow(int frame, double dt) override
    {
        vdbio::StatsRow row;
        row.values = {{"frame", frame},
                      {"step", double(mSolver->stepCount())},
                      {"time", mSolver->time()},
                      {"dt", dt}};
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

    std::vector<sph::SolverState> saveStates() const override { return {mSolver->saveState()}; }

private:
    std::unique_ptr<gas::GasSolver> mSolver;
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
