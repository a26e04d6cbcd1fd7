/// @file   LiquidSimulation.cc
/// @brief  A liquid scene ([SB12] Ghost SPH or the Basic SPH baseline) behind Simulation.
#include "LiquidScene.h"
#include "OneSolverSimulation.h"
#include "SceneWhitewater.h"
#include "SimulationParts.h"

#include <ghostfx/sph/Exceptions.h>

#include <cstdio>

namespace ghostfx {
namespace cmd {

using ghost::GhostSolver;
using sph::ParticleKind;
using sph::Real;
using sph::Vec3;

std::size_t liquidParticleCount(const GhostSolver& s)
{
    return s.particles().size() + s.count(ParticleKind::GhostSolid)
           + s.count(ParticleKind::Boundary);
}

OutputMedium liquidMedium(const GhostSolver& s)
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
    m.viscosity = s.settings().viscosity;
    m.liquid = true;
    m.pendingMass = [&s] { return s.initialized() ? 0.0 : double(s.startParticleMass()); };
    return m;
}

namespace {

class LiquidSimulation : public OneSolverSimulation<GhostSolver>
{
public:
    /// `restored`: the liquid's state, then the whitewater's where the checkpoint has it (a
    /// scene that asks for whitewater after its checkpoint starts it there).
    LiquidSimulation(const vdbio::Scene& scene, ghost::Method method,
                     const std::vector<sph::SolverState>* restored)
        : OneSolverSimulation(makeLiquidSolver(scene, liquidSettings(scene, method),
                                               restored ? &restored->front() : nullptr))
        , mScene(scene)
    {
        if (scene.outputs.whitewaterFile.empty()) return;
        mWhitewater = std::make_unique<SceneWhitewater>(scene, mSolver->settings());
        if (restored && restored->size() > 1) mWhitewater->restoreState(restored->at(1));
    }

    void advanceFrame() override
    {
        const std::uint64_t unconverged = mSolver->pressureSolveStats().unconverged;
        const std::uint64_t recomputed = mSolver->pressureSolveStats().recomputedSteps;
        mSolver->advanceFrame();
        if (mWhitewater) {
            mWhitewater->step(liquidPointsOf(liquidMedium(*mSolver), mScene.outputs,
                                             mSolver->time()),
                              mSolver->frame(), solidPlacements(), "whitewater");
        }
        warnAboutSolves(unconverged, recomputed);
    }
    std::optional<vdbio::WhitewaterPoints> whitewater() const override
    {
        if (!mWhitewater) return std::nullopt;
        return mWhitewater->points();
    }

    /// The warnings of the frame's DFSPH solves: the first recomputed gradients of the run,
    /// and solves that stopped above their error limit.
    void warnAboutSolves(std::uint64_t unconverged, std::uint64_t recomputed)
    {
        const ghost::PressureSolveStats& st = mSolver->pressureSolveStats();
        if (st.recomputedSteps > recomputed && !mWarnedRecomputed) {
            // Once a run: from here on the steps are slower, not wrong.
            mWarnedRecomputed = true;
            std::fprintf(stderr,
                         "ghostfx: warning: scene '%s', frame %d: the DFSPH solves recompute "
                         "their kernel gradients: keeping them would take %.3g GiB, above "
                         "dfsph.kept_gradients_gb = %g (the same solve, its pressure phase "
                         "about a third slower); raise the limit if memory allows\n",
                         mScene.file.c_str(), mSolver->frame(),
                         st.lastGradientBytes / (1024.0 * 1024.0 * 1024.0),
                         mSolver->settings().dfsph.keptGradientLimit / (1024.0 * 1024.0 * 1024.0));
        }
        if (st.unconverged > unconverged) {
            const ghost::DfsphSettings& d = mSolver->settings().dfsph;
            std::fprintf(stderr,
                         "ghostfx: warning: scene '%s', frame %d: %llu DFSPH solves stopped at "
                         "dfsph.max_iterations = %d above their error limit (last: density mean "
                         "%.2e, largest %.2e, against %.0e and %g x that; divergence %.2e, "
                         "largest %.2e, against %.0e); raise max_iterations or the limits, or "
                         "lower cfl / max_dt\n",
                         mScene.file.c_str(), mSolver->frame(),
                         static_cast<unsigned long long>(st.unconverged - unconverged),
                         d.maxIterations, st.lastDensityError, st.lastLargestDensityError,
                         double(d.densityError), ghost::DfsphSettings::PEAK_FACTOR,
                         st.lastDivergenceError, st.lastLargestDivergenceError,
                         double(d.divergenceError));
        }
    }
    void beforeFrame(int frame) override { updateSolidSequences(mScene, *mSolver, frame); }
    double boundaryLayerDepth() const override
    {
        return double(mSolver->settings().supportRadius());
    }
    std::vector<EmitterRate> emitterRates() const override
    {
        std::vector<EmitterRate> rates;
        for (const auto& r : mSolver->emitterRates()) rates.push_back({r.crossSection, r.massRate});
        return rates;
    }
    std::vector<sph::RigidTransform> solidPlacements() const override
    {
        std::vector<sph::RigidTransform> placements;
        for (std::size_t i = 0; i < mSolver->solidCount(); ++i)
            placements.push_back(mSolver->solidPlacement(i));
        return placements;
    }
    std::vector<BodySample> bodies() const override
    {
        std::vector<BodySample> bodies;
        for (std::size_t i = 0; i < mSolver->solidCount(); ++i) {
            if (!mSolver->isDynamic(i)) continue;
            const sph::RigidBody& b = mSolver->body(i);
            bodies.push_back({i, b.state(), b.angularVelocity()});
        }
        return bodies;
    }
    void setSolidMotion(std::size_t index, sph::RigidMotion motion) override
    {
        mSolver->setSolidMotion(index, std::move(motion));
    }
    void addSolid(const vdbio::SceneSolid& solid) override { addSceneSolid(*mSolver, solid); }
    void addEmitter(const vdbio::SceneEmitter& emitter) override
    {
        addSceneEmitter(*mSolver, emitter);
    }
    const sph::RigidBody* body(std::size_t index) const override
    {
        return mSolver->isDynamic(index) ? &mSolver->body(index) : nullptr;
    }
    std::pair<sph::Vec3d, sph::Vec3d> liquidForceOn(std::size_t index) const override
    {
        return mSolver->liquidForceOn(index);
    }
    void addBodyForce(std::size_t index, const sph::Vec3d& force, const sph::Vec3d& torque) override
    {
        mSolver->addBodyForce(index, force, torque);
    }
    void clearBodyForces() override { mSolver->clearBodyForces(); }
    WritableParticles writableParticles(ParticleKind kind) override
    {
        if (kind != ParticleKind::Liquid) return {};
        GhostSolver* solver = mSolver.get();
        return {&solver->particles(), nullptr, [solver] { solver->liquidMoved(); }};
    }
    std::size_t addLiquid(const sph::LevelSet& shape, const Vec3& velocity,
                          std::optional<double> viscosity) override
    {
        return mSolver->addLiquid(shape, velocity,
                                  viscosity ? std::optional<Real>(Real(*viscosity)) : std::nullopt);
    }

    vdbio::StatsRow statsRow(int frame, double dt) override
    {
        const GhostSolver& s = *mSolver;
        const FieldStats f =
            fieldStats(s.particles(), ParticleKind::Liquid, s.settings().restDensity, nullptr);
        const ghost::PhaseTimings& t = s.timings();
        vdbio::StatsRow row;
        row.values = stepColumns(frame, dt);
        row.values.insert(
            row.values.end(),
            {
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
                bytesPerParticle(*this),
            });
        if (s.settings().pressure == ghost::PressureModel::Dfsph) {
            // Iterations per step of the frame's DFSPH solves.
            const ghost::PressureSolveStats& st = s.pressureSolveStats();
            const double steps = double(st.steps - mSolveBefore.steps);
            const auto perStep = [&](std::uint64_t now, std::uint64_t before) {
                return steps > 0 ? double(now - before) / steps : 0.0;
            };
            row.values.push_back({"density_iterations",
                                  perStep(st.densityIterations, mSolveBefore.densityIterations)});
            row.values.push_back(
                {"divergence_iterations",
                 perStep(st.divergenceIterations, mSolveBefore.divergenceIterations)});
            row.values.push_back({"density_solve_error", st.lastDensityError});
            mSolveBefore = st;
        }
        mBefore = t;
        return row;
    }

    std::string counts() const override
    {
        const sph::ParticleExchange* shared = mSolver->exchange();
        return msg(
            mSolver->count(ParticleKind::Liquid), " liquid, ",
            mSolver->count(ParticleKind::GhostAir), " air, ",
            mSolver->count(ParticleKind::GhostSolid) + mSolver->count(ParticleKind::Boundary),
            " solid ghosts",
            shared ? msg(" on process ", shared->rank(), " of ", shared->ranks()) : std::string());
    }
    std::size_t particleCount() const override { return liquidParticleCount(*mSolver); }
    std::size_t memoryBytes() const override { return mSolver->memoryBytes(); }

    std::vector<OutputMedium> media() const override { return {liquidMedium(*mSolver)}; }
    std::vector<MediumCount> mediumCounts() const override
    {
        return {{"liquid", mSolver->count(ParticleKind::Liquid)}};
    }

    std::vector<sph::SolverState> saveStates() const override
    {
        std::vector<sph::SolverState> states{mSolver->saveState()};
        if (mWhitewater) states.push_back(mWhitewater->saveState());
        return states;
    }

    std::vector<Vec3> prepareToShare() override
    {
        if (!mSolver->prepare()) {
            throw SceneError(msg("scene '", mScene.file,
                                 "': no liquid at the start (an emitter starting later): not "
                                 "supported on several processes yet"));
        }
        return mSolver->particles().positions();
    }
    void share(sph::ParticleExchange& exchange, bool ownPart) override
    {
        if (mWhitewater) {
            throw SceneError(msg("scene '", mScene.file, "': outputs.whitewater: whitewater is "
                                 "made on one process: run this scene without mpirun, or make "
                                 "it afterwards with 'ghostfx whitewater' over its points files"));
        }
        try {
            mSolver->setExchange(&exchange, ownPart);
        } catch (const ValueError& e) {
            throw SceneError(msg("scene '", mScene.file, "': ", e.what()));
        }
    }

private:
    const vdbio::Scene& mScene;
    ghost::PhaseTimings mBefore;
    ghost::PressureSolveStats mSolveBefore;
    bool mWarnedRecomputed = false; ///< the kept-gradient limit's warning was printed
    std::unique_ptr<SceneWhitewater> mWhitewater; ///< null: the scene asks for none
};

} // namespace

std::unique_ptr<Simulation> makeLiquidSimulation(const vdbio::Scene& scene, ghost::Method method,
                                                 const std::vector<sph::SolverState>* restored)
{
    if (!scene.heaters.empty()) return makeBoilingSimulation(scene, method, restored);
    return std::make_unique<LiquidSimulation>(scene, method, restored);
}

void checkLiquidSimulation(const vdbio::Scene& scene, ghost::Method method)
{
    if (!scene.heaters.empty()) {
        checkBoilingSimulation(scene, method);
        return;
    }
    liquidSettings(scene, method);
    whitewaterSettings(scene);
}

} // namespace cmd
} // namespace ghostfx
