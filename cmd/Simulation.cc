/// @file   Simulation.cc
/// @brief  The liquid, gas and boiling simulations behind `ghostfx run`.
#include "Simulation.h"

#include "GhostLiquidSide.h"
#include "LiquidScene.h"

#include <ghostfx/gas/GasSolver.h>
#include <ghostfx/gas/PhaseTransition.h>
#include <ghostfx/sph/Exceptions.h>
#include <ghostfx/sph/FrameSteps.h>

#include <algorithm>
#include <cmath>
#include <limits>

namespace ghostfx {
namespace cmd {

using ghost::GhostSolver;
using sph::ParticleKind;
using sph::Real;
using sph::Vec3;

namespace {

/// max |v| and the mean / max of |rho / rho0 - 1| over particles of `kind` (and not ambient air).
struct FieldStats
{
    std::size_t count = 0;
    double maxSpeed = 0, errorMean = 0, errorMax = 0;
};

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

// Liquid ------------------------------------------------------------------------------------------

/// 1 / (frame rate substeps), or 0 for CFL-limited steps.
template <typename Settings>
double fixedStep(const Settings& s)
{
    return s.substeps > 0 ? 1.0 / (double(s.frameRate) * s.substeps) : 0.0;
}

class LiquidSimulation : public Simulation
{
public:
    LiquidSimulation(const vdbio::Scene& scene, const sph::SolverState* restored)
        : mScene(scene)
        , mSolver(makeLiquidSolver(scene, liquidSettings(scene), restored))
    {}

    void advanceFrame() override { mSolver->advanceFrame(); }
    int frame() const override { return mSolver->frame(); }
    double time() const override { return mSolver->time(); }
    std::uint64_t stepCount() const override { return mSolver->stepCount(); }
    void beforeFrame(int frame) override { updateSolidSequences(mScene, *mSolver, frame); }
    double fixedTimeStep() const override { return fixedStep(mSolver->settings()); }
    double stabilityLimit() const override
    {
        return double(mSolver->stableTimeStep()) / double(mSolver->settings().cflNumber);
    }
    void setSolidMotion(std::size_t index, sph::RigidMotion motion) override
    {
        mSolver->setSolidMotion(index, std::move(motion));
    }
    void addSolid(const sph::LevelSet& shape, const Vec3& velocity) override
    {
        mSolver->addSolid(shape, velocity);
    }
    std::size_t addLiquid(const sph::LevelSet& shape, const Vec3& velocity) override
    {
        return mSolver->addLiquid(shape, velocity);
    }

    void setStepObserver(std::function<void(double)> observer) override
    {
        mSolver->setStepObserver([observer](const GhostSolver&, Real dt) { observer(double(dt)); });
    }

    vdbio::StatsRow statsRow(int frame, double dt) override
    {
        const GhostSolver& s = *mSolver;
        const FieldStats f =
            fieldStats(s.particles(), ParticleKind::Liquid, s.settings().restDensity, nullptr);
        const ghost::PhaseTimings& t = s.timings();
        vdbio::StatsRow row;
        row.values = {
            {"frame", frame},
            {"step", double(s.stepCount())},
            {"time", s.time()},
            {"dt", dt},
            {"count_liquid", double(f.count)},
            {"count_ghost_air", double(s.count(ParticleKind::GhostAir))},
            {"count_ghost_solid", double(s.count(ParticleKind::GhostSolid))},
            {"count_boundary", double(s.count(ParticleKind::Boundary))},
            {"max_speed", f.maxSpeed},
            {"density_error_mean", f.errorMean},
            {"density_error_max", f.errorMax},
            {"t_neighbors_density", t.neighborsAndDensity - mBefore.neighborsAndDensity},
            {"t_pressure_force", t.pressureForce - mBefore.pressureForce},
            {"t_xsph_boundary", t.xsphAndBoundary - mBefore.xsphAndBoundary},
            {"t_air_resampling", t.airResampling - mBefore.airResampling},
            {"t_emission", t.emission - mBefore.emission},
            {"t_step", t.total - mBefore.total},
            {"bytes_per_particle",
             particleCount() ? double(memoryBytes()) / double(particleCount()) : 0.0},
        };
        mBefore = t;
        return row;
    }

    std::string counts() const override
    {
        return msg(mSolver->count(ParticleKind::Liquid), " liquid, ",
                   mSolver->count(ParticleKind::GhostAir), " air, ",
                   mSolver->count(ParticleKind::GhostSolid)
                       + mSolver->count(ParticleKind::Boundary),
                   " solid ghosts");
    }
    std::size_t particleCount() const override { return liquidParticleCount(*mSolver); }
    std::size_t memoryBytes() const override { return mSolver->memoryBytes(); }

    std::vector<OutputMedium> media() const override { return {liquidMedium(*mSolver)}; }

    /// Liquid, air and solid particles.
    static std::size_t liquidParticleCount(const GhostSolver& s)
    {
        return s.particles().size() + s.count(ParticleKind::GhostSolid)
               + s.count(ParticleKind::Boundary);
    }

    std::vector<sph::SolverState> saveStates() const override { return {mSolver->saveState()}; }

    static OutputMedium liquidMedium(const GhostSolver& s)
    {
        OutputMedium m;
        m.name = "liquid";
        m.particles = &s.particles();
        m.kinds = {ParticleKind::Liquid};
        m.ghostKinds = {ParticleKind::GhostAir, ParticleKind::GhostSolid, ParticleKind::Boundary};
        m.withGhosts = [&s] { return s.allParticles(); };
        m.spacing = s.settings().spacing;
        m.support = s.settings().supportRadius();
        m.restDensity = s.settings().restDensity;
        m.gravity = s.settings().gravity;
        m.liquid = true;
        return m;
    }

private:
    const vdbio::Scene& mScene;
    std::unique_ptr<GhostSolver> mSolver;
    ghost::PhaseTimings mBefore;
};

// Gas ---------------------------------------------------------------------------------------------

/// The gas keys of the scene: settings.gas { ... }.
gas::GasSettings gasSettings(const vdbio::Scene& scene, const vdbio::JsonObject& g,
                             double defaultSpacing, const std::string& defaultVariant)
{
    gas::GasSettings s;
    s.method = gas::methodFromName(
        g.choice("variant", defaultVariant, {"fast", "ambient", "uncorrected"}));
    s.spacing = Real(g.positive("spacing", defaultSpacing));
    s.supportFactor = Real(g.inRange("kernel_support", s.supportFactor, 1.5, 5));
    s.particleMass = Real(g.nonNegative("particle_mass", s.particleMass));
    s.restDensity = Real(g.positive("rest_density", s.restDensity));
    s.kappa = Real(g.positive("kappa", s.kappa));
    s.clampNegativePressure = g.get<bool>("clamp_negative_pressure", s.clampNegativePressure);
    s.delta = Real(g.inRange("delta", s.delta, 0.4, 0.7));
    s.atmosphericPressure = Real(g.nonNegative("atmospheric_pressure", s.atmosphericPressure));
    s.interiorPressureScale =
        Real(g.inRange("interior_pressure_scale", s.interiorPressureScale, 0, 1));
    s.normalThreshold = Real(g.nonNegative("normal_threshold", s.normalThreshold));
    s.damping = Real(g.nonNegative("damping", s.damping));
    s.viscosity = Real(g.nonNegative("viscosity", s.viscosity));
    const auto gravity =
        g.get<std::array<double, 3>>("gravity", {s.gravity[0], s.gravity[1], s.gravity[2]});
    s.gravity = Vec3(Real(gravity[0]), Real(gravity[1]), Real(gravity[2]));
    s.ambientTemperature = Real(g.positive("ambient_temperature", s.ambientTemperature));
    s.diffusion = Real(g.nonNegative("diffusion", s.diffusion));
    s.radiationTime = Real(g.nonNegative("radiation_time", s.radiationTime));
    s.buoyancy = Real(g.nonNegative("buoyancy", s.buoyancy));
    const auto up = g.get<std::array<double, 3>>("buoyancy_direction", {0, 1, 0});
    s.buoyancyDirection = Vec3(Real(up[0]), Real(up[1]), Real(up[2]));
    s.vorticity = g.get<bool>("vorticity", s.vorticity);
    s.vorticityGeneration = Real(g.nonNegative("vorticity_generation", s.vorticityGeneration));
    s.vorticityStrength = Real(g.nonNegative("vorticity_strength", s.vorticityStrength));
    s.lifeStrength = Real(g.nonNegative("life_strength", s.lifeStrength));
    s.substeps = int(g.inRange("substeps", s.substeps, 0, 100000));
    s.cflNumber = Real(g.inRange("cfl", s.cflNumber, 1e-3, 10));
    s.maxSpeed = Real(g.nonNegative("max_speed", s.maxSpeed));
    s.seed = g.get<std::uint64_t>("seed", s.seed);
    s.frameRate = Real(scene.frameRate);
    s.domain = scene.killBox;
    // force_fields ([RYY15] Fig. 7): point attractors act on the gas.
    for (const vdbio::SceneForceField& field : scene.forceFields) {
        gas::Attractor a;
        a.position = Vec3(field.attractor.position);
        a.strength = Real(field.attractor.strength);
        a.radius = Real(field.attractor.radius);
        a.falloff = gas::falloffFromName(field.attractor.falloff);
        s.attractors.push_back(a);
    }
    g.finish();
    if (s.method == gas::Method::Ambient && s.domain.empty()) {
        g.failValue("variant",
                    "the ambient-air baseline fills a box with air: expected domain.kill_box");
    }
    s.validate();
    return s;
}

std::unique_ptr<gas::GasSolver> makeGasSolver(const vdbio::Scene& scene,
                                              const gas::GasSettings& settings,
                                              const sph::SolverState* restored)
{
    auto solver = std::make_unique<gas::GasSolver>(settings);
    if (restored) solver->restoreState(*restored);
    for (const vdbio::SceneSolid& solid : scene.solids) {
        if (solid.motion.keys.empty()) solver->addSolid(solid.shape, Vec3(solid.velocity));
        else solver->addMovingSolid(solid.shape, keyedMotion(solid.motion));
    }
    for (const vdbio::SceneGasSource& src : scene.gasSources) {
        gas::GasSource s;
        s.temperature = Real(src.temperature);
        s.velocity = Vec3(src.velocity);
        s.rate = Real(src.rate);
        s.start = src.start;
        s.end = src.end;
        if (!src.motion.keys.empty()) s.motion = keyedMotion(src.motion);
        solver->addSource(src.shape, s);
    }
    return solver;
}

/// Visible gas (not ambient air) copied into a set of its own for the outputs.
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
                                                     const gas::GasTimings& before,
                                                     const std::string& prefix)
{
    const sph::ParticleSet& p = s.particles();
    const std::vector<Real>* ambient = p.hasScalarChannel(gas::channel::AMBIENT)
                                           ? &p.scalarChannel(gas::channel::AMBIENT)
                                           : nullptr;
    const FieldStats f = fieldStats(p, ParticleKind::Gas, s.settings().restDensity, ambient);
    const gas::GasTimings& t = s.timings();
    return {
        {prefix + "count_gas", double(f.count)},
        {prefix + "count_ambient", double(s.ambientCount())},
        {prefix + "count_gas_boundary", double(s.count(ParticleKind::Boundary))},
        {prefix + "gas_max_speed", f.maxSpeed},
        {prefix + "gas_density_error_mean", f.errorMean},
        {prefix + "gas_density_error_max", f.errorMax},
        {prefix + "t_gas_emission", t.emission - before.emission},
        {prefix + "t_gas_neighbors", t.neighbors - before.neighbors},
        {prefix + "t_gas_density", t.density - before.density},
        {prefix + "t_gas_forces", t.forces - before.forces},
        {prefix + "t_gas_integration", t.integration - before.integration},
        {prefix + "t_gas_step", t.total - before.total},
    };
}

class GasSimulation : public Simulation
{
public:
    GasSimulation(const vdbio::Scene& scene, const sph::SolverState* restored)
    {
        const vdbio::JsonObject& s = scene.settings;
        const vdbio::JsonObject g = s.has("gas") ? s.object("gas") : vdbio::JsonObject();
        mSolver = makeGasSolver(scene, gasSettings(scene, g, scene.spacing, "fast"), restored);
        s.finish();
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
        for (auto& v : gasStats(*mSolver, mBefore, "")) row.values.push_back(v);
        row.values.push_back(
            {"bytes_per_particle",
             particleCount() ? double(memoryBytes()) / double(particleCount()) : 0.0});
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

    std::vector<sph::SolverState> saveStates() const override { return {mSolver->saveState()}; }

private:
    std::unique_ptr<gas::GasSolver> mSolver;
    gas::GasTimings mBefore;
    mutable sph::ParticleSet mVisible;
};

// Boiling -----------------------------------------------------------------------------------------

gas::PhaseSettings phaseSettings(const vdbio::JsonObject& p, double spacing, double heaterBandLimit)
{
    gas::PhaseSettings s;
    s.boilingPoint = Real(p.positive("boiling_point", s.boilingPoint));
    s.initialTemperature = Real(p.positive("initial_temperature", s.initialTemperature));
    s.latentHeat = Real(p.nonNegative("latent_heat", s.latentHeat));
    // Heated layer: 1.5 spacings, kept inside the heaters' narrow bands (phi is clamped beyond).
    s.heaterBand = Real(p.positive("heater_band", std::min(1.5 * spacing, 0.9 * heaterBandLimit)));
    s.heatingTime = Real(p.positive("heating_time", s.heatingTime));
    s.conductivity = Real(p.nonNegative("conductivity", s.conductivity));
    s.evaporationRate = Real(p.nonNegative("evaporation_rate", s.evaporationRate));
    s.evaporationOnset = Real(p.positive("evaporation_onset", s.evaporationOnset));
    s.surfaceThreshold = Real(p.nonNegative("surface_threshold", s.surfaceThreshold));
    s.mergeEverySteps = int(p.inRange("merge_every_steps", s.mergeEverySteps, 1, 100000));
    p.finish();
    s.validate();
    return s;
}

/// Default gas spacing of a boiling scene: a boiling liquid particle splits into 12 ([RYY15]
/// Sec. 4.2); at the density ratio rho_l / rho_g each child then has a volume of that many
/// spacings^3.
double vapourSpacing(const vdbio::Scene& scene, const ghost::GhostSettings& liquid)
{
    const gas::GasSettings probe;
    return scene.spacing * std::cbrt(double(liquid.restDensity / probe.restDensity) / 12.0);
}

class BoilingSimulation : public Simulation
{
public:
    explicit BoilingSimulation(const vdbio::Scene& scene) : mScene(scene)
    {
        const vdbio::JsonObject& s = scene.settings;
        const vdbio::JsonObject g = s.has("gas") ? s.object("gas") : vdbio::JsonObject();
        const ghost::GhostSettings liquid = liquidSettings(scene); // finishes settings
        mLiquid = makeLiquidSolver(scene, liquid);
        mGas = makeGasSolver(scene, gasSettings(scene, g, vapourSpacing(scene, liquid), "fast"),
                             nullptr);
        mSide = std::make_unique<coupling::GhostLiquidSide>(*mLiquid);
        double band = std::numeric_limits<double>::max();
        for (const vdbio::SceneHeater& h : scene.heaters)
            band = std::min(band, double(h.shape.bandWidth()));
        mPhase = std::make_unique<gas::PhaseTransition>(
            *mGas, *mSide, phaseSettings(scene.phaseTransition, scene.spacing, band));
        for (const vdbio::SceneHeater& h : scene.heaters)
            mPhase->addHeater(h.shape, Real(h.temperature));
        mFrameRate = liquid.frameRate;
        mSubsteps = liquid.substeps;
    }

    void advanceFrame() override
    {
        const double frameEnd = double(mFrame + 1) / double(mFrameRate);
        sph::stepFrame(
            frameEnd, mFrameRate, mSubsteps, [this] { return mLiquid->time(); },
            [this] { return std::min(mLiquid->stableTimeStep(), mGas->stableTimeStep()); },
            [this](Real dt) { stepOnce(dt); });
        ++mFrame;
    }
    int frame() const override { return mFrame; }
    double time() const override { return mLiquid->time(); }
    double fixedTimeStep() const override
    {
        return mSubsteps > 0 ? 1.0 / (double(mFrameRate) * mSubsteps) : 0.0;
    }
    double stabilityLimit() const override
    {
        return std::min(double(mLiquid->stableTimeStep()) / double(mLiquid->settings().cflNumber),
                        double(mGas->stableTimeStep()) / double(mGas->settings().cflNumber));
    }
    std::uint64_t stepCount() const override { return mLiquid->stepCount(); }
    void beforeFrame(int frame) override { updateSolidSequences(mScene, *mLiquid, frame); }
    void setStepObserver(std::function<void(double)> observer) override
    {
        mObserver = std::move(observer);
    }

    vdbio::StatsRow statsRow(int frame, double dt) override
    {
        const FieldStats f = fieldStats(mLiquid->particles(), ParticleKind::Liquid,
                                        mLiquid->settings().restDensity, nullptr);
        const gas::MassBudget budget = mPhase->massBudget();
        vdbio::StatsRow row;
        row.values = {{"frame", frame},
                      {"step", double(stepCount())},
                      {"time", time()},
                      {"dt", dt},
                      {"count_liquid", double(f.count)},
                      {"count_ghost_air", double(mLiquid->count(ParticleKind::GhostAir))},
                      {"count_ghost_solid", double(mLiquid->count(ParticleKind::GhostSolid))},
                      {"max_speed", f.maxSpeed},
                      {"density_error_mean", f.errorMean},
                      {"density_error_max", f.errorMax},
                      {"boiled", double(mPhase->boiledCount())},
                      {"evaporated", double(mPhase->evaporatedCount())},
                      {"mass_liquid", budget.liquid},
                      {"mass_gas", budget.gas + budget.gasRemoved}};
        for (auto& v : gasStats(*mGas, mGasBefore, "")) row.values.push_back(v);
        row.values.push_back({"t_step", mPhase->timings().total - mPhaseBefore.total});
        row.values.push_back(
            {"bytes_per_particle",
             particleCount() ? double(memoryBytes()) / double(particleCount()) : 0.0});
        mGasBefore = mGas->timings();
        mPhaseBefore = mPhase->timings();
        return row;
    }

    std::string counts() const override
    {
        return msg(mLiquid->count(ParticleKind::Liquid), " liquid, ", mGas->visibleGasCount(),
                   " vapour, ", mPhase->boiledCount(), " boiled");
    }
    std::size_t particleCount() const override
    {
        return LiquidSimulation::liquidParticleCount(*mLiquid) + mGas->particles().size();
    }
    std::size_t memoryBytes() const override
    {
        return mLiquid->memoryBytes() + mGas->particles().memoryBytes();
    }

    std::vector<OutputMedium> media() const override
    {
        copyVisibleGas(mGas->particles(), mVisible);
        return {LiquidSimulation::liquidMedium(*mLiquid), gasMedium(*mGas, mVisible)};
    }

    std::vector<sph::SolverState> saveStates() const override
    {
        // The phase transition's own counters and merge schedule are not part of the solver
        // states yet, so a boiling run cannot be resumed bit for bit: no checkpoint is offered.
        return {};
    }

private:
    void stepOnce(Real dt)
    {
        mPhase->step(dt);
        if (mObserver) mObserver(double(dt));
    }

    const vdbio::Scene& mScene;
    std::unique_ptr<GhostSolver> mLiquid;
    std::unique_ptr<gas::GasSolver> mGas;
    std::unique_ptr<coupling::GhostLiquidSide> mSide;
    std::unique_ptr<gas::PhaseTransition> mPhase;
    std::function<void(double)> mObserver;
    Real mFrameRate = 30;
    int mSubsteps = 20;
    int mFrame = 0;
    gas::GasTimings mGasBefore;
    gas::PhaseTransitionTimings mPhaseBefore;
    mutable sph::ParticleSet mVisible;
};

} // namespace

void checkSimulationSettings(const vdbio::Scene& scene)
{
    const vdbio::JsonObject& s = scene.settings;
    const vdbio::JsonObject g = s.has("gas") ? s.object("gas") : vdbio::JsonObject();
    if (!scene.heaters.empty()) {
        if (scene.method == "gas")
            s.failValue("method", "heaters boil a liquid: expected 'ghost' or 'basic'");
        const ghost::GhostSettings liquid = liquidSettings(scene);
        gasSettings(scene, g, vapourSpacing(scene, liquid), "fast");
        phaseSettings(scene.phaseTransition, scene.spacing, std::numeric_limits<double>::max());
    } else if (scene.method == "gas") {
        gasSettings(scene, g, scene.spacing, "fast");
        s.finish();
    } else {
        if (s.has("gas")) s.fail("gas", "gas settings need method 'gas' or heaters (boiling)");
        liquidSettings(scene);
    }
}

std::size_t stateCount(const vdbio::Scene& scene) { return scene.heaters.empty() ? 1 : 0; }

void Simulation::setSolidMotion(std::size_t /*index*/, sph::RigidMotion /*motion*/)
{
    throw ValueError("changing a solid's motion during a run is supported in liquid scenes only");
}

void Simulation::addSolid(const sph::LevelSet& shape, const Vec3& /*velocity*/)
{
    throw ValueError("solid '" + shape.name()
                     + "': adding solids from a script is supported in liquid scenes only");
}

std::size_t Simulation::addLiquid(const sph::LevelSet& shape, const Vec3& /*velocity*/)
{
    throw ValueError("liquid '" + shape.name()
                     + "': adding liquid from a script is supported in liquid scenes only");
}

std::unique_ptr<Simulation> makeSimulation(const vdbio::Scene& scene,
                                           const std::vector<sph::SolverState>* restored)
{
    if (restored && restored->size() != stateCount(scene)) {
        throw SceneError(msg("scene '", scene.file, "': ",
                             scene.heaters.empty()
                                 ? "the checkpoint holds " + std::to_string(restored->size())
                                       + " solver states, the scene needs 1"
                                 : "a boiling scene (with heaters) cannot be resumed yet"));
    }
    const sph::SolverState* state = restored ? &restored->front() : nullptr;
    if (!scene.heaters.empty()) {
        if (scene.method == "gas")
            scene.settings.failValue("method",
                                     "heaters boil a liquid: expected 'ghost' or 'basic'");
        return std::make_unique<BoilingSimulation>(scene);
    }
    if (scene.method == "gas") return std::make_unique<GasSimulation>(scene, state);
    if (scene.settings.has("gas")) {
        scene.settings.fail("gas", "gas settings need method 'gas' or heaters (boiling)");
    }
    return std::make_unique<LiquidSimulation>(scene, state);
}

} // namespace cmd
} // namespace ghostfx
