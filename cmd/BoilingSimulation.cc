/// @file   BoilingSimulation.cc
/// @brief  A boiling liquid: the liquid solver and a [RYY15] fast gas for its vapour, coupled by
///         the Sec. 4 phase transition, behind Simulation.
#include "GasScene.h"
#include "GhostLiquidSide.h"
#include "LiquidScene.h"
#include "SettingReader.h"
#include "SimulationParts.h"

#include <ghostfx/gas/PhaseTransition.h>
#include <ghostfx/sph/FrameSteps.h>

#include <algorithm>
#include <cmath>
#include <limits>

namespace ghostfx {
namespace cmd {

using ghost::GhostSolver;
using sph::ParticleKind;
using sph::Real;

namespace {

/// The `phase_transition` keys of a boiling scene; the heated layer defaults to 1.5 spacings,
/// kept inside the heaters' narrow bands (phi is clamped beyond them).
gas::PhaseSettings phaseSettings(const vdbio::Scene& scene, double heaterBandLimit)
{
    gas::PhaseSettings s;
    s.heaterBand = Real(std::min(1.5 * scene.spacing, 0.9 * heaterBandLimit));
    readSettingTable(scene.phaseTransition, gas::phaseSettingTable(), s);
    scene.phaseTransition.finish();
    validateSceneSettings(scene.file, s);
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
    /// `restored`: the liquid's, the vapour's and the phase transition's states, as
    /// saveStates() gives them, or null for a fresh start.
    BoilingSimulation(const vdbio::Scene& scene, ghost::Method method,
                      const std::vector<sph::SolverState>* restored)
        : mScene(scene)
    {
        const Settings settings = readSettings(scene, method);
        mLiquid = makeLiquidSolver(scene, settings.liquid, restored ? &(*restored)[0] : nullptr);
        mGas = makeGasSolver(scene, settings.gas, restored ? &(*restored)[1] : nullptr);
        mSide = std::make_unique<coupling::GhostLiquidSide>(*mLiquid);
        double band = std::numeric_limits<double>::max();
        for (const vdbio::SceneHeater& h : scene.heaters)
            band = std::min(band, double(h.shape.bandWidth()));
        mPhase = std::make_unique<gas::PhaseTransition>(*mGas, *mSide, phaseSettings(scene, band));
        for (const vdbio::SceneHeater& h : scene.heaters)
            mPhase->addHeater(h.shape, Real(h.temperature));
        if (restored) mPhase->restoreState((*restored)[2]);
        mFrameRate = settings.liquid.frameRate;
        mSubsteps = settings.liquid.substeps;
        mFrame = mLiquid->frame();
    }

    struct Settings
    {
        ghost::GhostSettings liquid;
        gas::GasSettings gas;
    };

    /// settings (the liquid's keys) and settings.gas (the vapour's; settings.gas.method, default
    /// the [RYY15] fast gas, picks a gas baseline instead), every key read.
    static Settings readSettings(const vdbio::Scene& scene, ghost::Method method)
    {
        const vdbio::JsonObject& s = scene.settings;
        const vdbio::JsonObject g = s.has("gas") ? s.object("gas") : vdbio::JsonObject();
        Settings out;
        out.liquid = liquidSettings(scene, method); // finishes settings
        std::vector<std::string> names;
        for (const auto& entry : gasMethodNames()) names.push_back(entry.first);
        const gas::Method vapour = gasMethod(g.choice("method", "gas", names));
        out.gas = gasSettings(scene, g, vapourSpacing(scene, out.liquid), vapour);
        return out;
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
    double cflTimeStep() const override
    {
        return double(std::min(mLiquid->stableTimeStep(), mGas->stableTimeStep()));
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
        for (auto& v : gasStats(*mGas, mGasBefore)) row.values.push_back(v);
        row.values.push_back({"t_step", mPhase->timings().total - mPhaseBefore.total});
        row.values.push_back(bytesPerParticle(*this));
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
        return liquidParticleCount(*mLiquid) + mGas->particles().size();
    }
    std::size_t memoryBytes() const override
    {
        return mLiquid->memoryBytes() + mGas->particles().memoryBytes();
    }

    std::vector<OutputMedium> media() const override
    {
        copyVisibleGas(mGas->particles(), mVisible);
        return {liquidMedium(*mLiquid), gasMedium(*mGas, mVisible)};
    }
    std::vector<MediumCount> mediumCounts() const override
    {
        return {{"liquid", mLiquid->count(ParticleKind::Liquid)}, {"gas", mGas->visibleGasCount()}};
    }

    void addGasSource(const vdbio::SceneGasSource& source) override
    {
        addSceneGasSource(*mGas, source);
    }
    WritableParticles writableParticles(ParticleKind kind) override
    {
        GhostSolver* liquid = mLiquid.get();
        if (kind == ParticleKind::Liquid)
            return {&liquid->particles(), nullptr, [liquid] { liquid->liquidMoved(); }};
        return writableGas(*mGas, kind);
    }

    std::vector<sph::SolverState> saveStates() const override
    {
        sph::SolverState liquid = mLiquid->saveState();
        // The liquid solver counts frames by its own advanceFrame(); this simulation steps it
        // through the phase transition, so the frame is this simulation's.
        liquid.integers["frame"] = mFrame;
        return {std::move(liquid), mGas->saveState(), mPhase->saveState()};
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

std::unique_ptr<Simulation> makeBoilingSimulation(const vdbio::Scene& scene, ghost::Method method,
                                                  const std::vector<sph::SolverState>* restored)
{
    return std::make_unique<BoilingSimulation>(scene, method, restored);
}

void checkBoilingSimulation(const vdbio::Scene& scene, ghost::Method method)
{
    BoilingSimulation::readSettings(scene, method);
    phaseSettings(scene, std::numeric_limits<double>::max());
}

} // namespace cmd
} // namespace ghostfx
