/// @file   Simulation.h
/// @brief  What `ghostfx run` drives: one scene's solvers behind one small interface, so the
///         frame loop, outputs, checkpoints and statistics do not care which solver runs.
/// @details Three kinds exist: a liquid ([SB12] Ghost or Basic SPH), a gas ([RYY15] fast,
///          ambient-air or uncorrected), and a boiling liquid (both, coupled by the [RYY15]
///          Sec. 4 phase transition). Only the solvers a scene needs are created.
#pragma once

#include <ghostfx/sph/ParticleExchange.h>
#include <ghostfx/sph/ParticleSet.h>
#include <ghostfx/sph/RigidBody.h>
#include <ghostfx/sph/RigidMotion.h>
#include <ghostfx/sph/SolverState.h>
#include <ghostfx/vdbio/Scene.h>
#include <ghostfx/vdbio/Stats.h>
#include <ghostfx/vdbio/WhitewaterFile.h>

#include <functional>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace ghostfx {
namespace cmd {

/// Particles of one medium and how to turn them into output files.
struct OutputMedium
{
    std::string name; ///< "liquid" or "gas"
    const sph::ParticleSet* particles = nullptr;
    std::vector<sph::ParticleKind> kinds;      ///< kinds written as this medium
    std::vector<sph::ParticleKind> ghostKinds; ///< kinds written too with outputs.points.ghosts
    /// Every particle of the medium, ghosts included, when they live apart from `particles`
    /// (the liquid solver keeps its solid particles in blocks); empty: `particles` has them.
    std::function<sph::ParticleSet()> withGhosts;
    double spacing = 0, support = 0, restDensity = 0;
    sph::Vec3 gravity{0}; ///< the medium's gravity (m/s^2)
    double viscosity = 0; ///< a liquid's kinematic viscosity settings.viscosity (m^2/s)
    bool liquid = true;   ///< liquids get a surface; gases get temperature
    /// A gas's ambient temperature (K): its temperature grid's background; NaN: none.
    double ambientTemperature = std::numeric_limits<double>::quiet_NaN();
    /// Before the medium's first step: the mass (kg) that step gives the particles whose mass is
    /// still 0 (the solver scales it then); 0 once it has stepped.
    std::function<double()> pendingMass;
};

/// A solver's own particle set that holds a medium's particles of one kind, for scripts that
/// set positions or velocities: its particles of `kind` whose `skip` value (if any) is 0, in
/// order, are the ones media() lists.
struct WritableParticles
{
    sph::ParticleSet* set = nullptr; ///< null: no such particles can be set
    const std::vector<sph::Real>* skip = nullptr;
    /// To call after positions were set: the solver renews what it derives from them between
    /// steps (the liquid's ghost air); empty where nothing is.
    std::function<void()> moved;
};

class Simulation
{
public:
    virtual ~Simulation() = default;

    /// Advance one frame (substeps fixed or CFL-limited, as the scene says).
    virtual void advanceFrame() = 0;
    /// Frames advanced so far (the state is at t = frame / fps).
    virtual int frame() const = 0;
    virtual double time() const = 0;
    virtual std::uint64_t stepCount() const = 0;

    /// The scene's fixed step, 1 / (frame_rate substeps) (s), or 0 with CFL-limited steps.
    virtual double fixedTimeStep() const = 0;
    /// The largest stable step now (s): the solvers' limits at Courant number 1 (sound speed,
    /// forces, explicit diffusion), the CFL step divided by the scene's cfl.
    virtual double stabilityLimit() const = 0;
    /// The step (s) CFL-adaptive steps would take now: the stability limit times the scene's
    /// cfl (with DFSPH, bound by the flow speed and max_dt instead).
    virtual double cflTimeStep() const = 0;
    /// How deep (m) the boundary particles inside a solid must reach: the kernel support of a
    /// liquid with ghost solids or boundary particles; 0 where solids are not sampled so.
    virtual double boundaryLayerDepth() const { return 0; }
    /// Each liquid emitter's cross-section (m^2) and mass rate (kg/s) in the scene's order;
    /// empty where the scene's solver has no liquid emitters.
    struct EmitterRate
    {
        double crossSection, massRate;
    };
    virtual std::vector<EmitterRate> emitterRates() const { return {}; }
    /// Where each solid is now, in the order added (the scene's, then a script's): the
    /// placement its motion gives at time(), wherever a script steered it; empty where the
    /// solver does not place solids (then the scene's motion says where they are).
    virtual std::vector<sph::RigidTransform> solidPlacements() const { return {}; }

    /// One dynamic solid now: its index among the solids (the scene's order, then a
    /// script's), its body's state and angular velocity (rad/s, world).
    struct BodySample
    {
        std::size_t solid = 0;
        sph::RigidBodyState state;
        sph::Vec3d angularVelocity{0.0};
    };
    /// Every dynamic solid, in the order added; empty where there are none.
    virtual std::vector<BodySample> bodies() const { return {}; }

    /// Called after every step with its dt (s).
    virtual void setStepObserver(std::function<void(double dt)> observer) = 0;
    /// The statistics row of the step just taken.
    virtual vdbio::StatsRow statsRow(int frame, double dt) = 0;
    /// Counts for log lines: "4418 liquid, 1140 air, 24467 solid ghosts".
    virtual std::string counts() const = 0;
    virtual std::size_t particleCount() const = 0;
    virtual std::size_t memoryBytes() const = 0;

    virtual std::vector<OutputMedium> media() const = 0;
    /// The whitewater particles now, where the scene asks for whitewater (liquid scenes with
    /// outputs.whitewater); none otherwise.
    virtual std::optional<vdbio::WhitewaterPoints> whitewater() const { return std::nullopt; }
    /// The particles of each medium of media(), by its name ("liquid": liquid particles, no
    /// ghosts; "gas": the visible gas), without copying them.
    struct MediumCount
    {
        std::string name;
        std::size_t count;
    };
    virtual std::vector<MediumCount> mediumCounts() const = 0;

    /// Solver states for a checkpoint (one per solver), and their restoration; the order is the
    /// simulation's own. `restore` is called on a simulation built from the same scene.
    virtual std::vector<sph::SolverState> saveStates() const = 0;
    /// Replace the motion of the scene's solid `index` (in scene order) from now on; refused
    /// for a static solid and where the scene's solver cannot (gas, boiling).
    virtual void setSolidMotion(std::size_t index, sph::RigidMotion motion);
    /// Add a solid (static without velocity or keys, as a scene solid), a liquid body, a liquid
    /// emitter or a gas source beside the scene's (scripts), as the scene's own are added;
    /// addLiquid returns the liquid particles added; a `viscosity` (m^2/s) is the liquid's own
    /// (GhostSolver::addLiquid). Solids, liquid bodies and emitters: liquid
    /// scenes only; gas sources: gas scenes and the vapour of boiling ones. The others refuse
    /// with a ValueError naming the shape.
    virtual void addSolid(const vdbio::SceneSolid& solid);
    virtual std::size_t addLiquid(const sph::LevelSet& shape, const sph::Vec3& velocity,
                                  std::optional<double> viscosity = std::nullopt);
    virtual void addEmitter(const vdbio::SceneEmitter& emitter);
    virtual void addGasSource(const vdbio::SceneGasSource& source);
    /// Dynamic solids (rigid bodies the liquid moves, added as solids with `dynamic`), for
    /// scripts: read the body of solid `index` and the liquid's force and torque on it in the
    /// last step, push it (force N at the centre of mass, torque N m, world axes) in every step
    /// until clearBodyForces(). Liquid scenes only: the others have none.
    /// The body of solid `index`, or null where it is not a dynamic solid.
    virtual const sph::RigidBody* body(std::size_t /*index*/) const { return nullptr; }
    virtual std::pair<sph::Vec3d, sph::Vec3d> liquidForceOn(std::size_t index) const;
    virtual void addBodyForce(std::size_t index, const sph::Vec3d& force, const sph::Vec3d& torque);
    virtual void clearBodyForces() {}
    /// The particles of `kind` a script may set (liquid and gas particles; ghosts are derived
    /// from them and cannot be set); the default: none.
    virtual WritableParticles writableParticles(sph::ParticleKind kind);
    /// Before simulating towards `frame`: per-frame inputs (deforming solid sequences).
    virtual void beforeFrame(int /*frame*/) {}

    /// One simulation over several processes (`mpirun -np N ghostfx run`): every process
    /// builds the same simulation, then prepareToShare() makes its first state (the same
    /// everywhere) and returns the positions the domain is cut by; share() keeps this process's
    /// part and exchanges with the others from then on (`ownPart`: the simulation was restored
    /// from this process's own part of a checkpoint, and keeps all of it). Liquid (Ghost SPH)
    /// scenes only; the others refuse with a SceneError.
    virtual std::vector<sph::Vec3> prepareToShare();
    virtual void share(sph::ParticleExchange& exchange, bool ownPart);
};

/// Build the simulation a scene asks for, fresh or continuing from `restored` states (as saved
/// by saveStates()). Reads and checks every solver-specific key of the scene.
std::unique_ptr<Simulation> makeSimulation(const vdbio::Scene& scene,
                                           const std::vector<sph::SolverState>* restored = nullptr);

/// Read and check every solver-specific key of `scene` (as makeSimulation does) without
/// building a solver or sampling a particle: a cheap check of a scene before a long job.
void checkSimulationSettings(const vdbio::Scene& scene);

/// How many solver states a checkpoint of this scene holds (1, or 3 for boiling: the liquid,
/// its vapour and the phase transition).
std::size_t stateCount(const vdbio::Scene& scene);

} // namespace cmd
} // namespace ghostfx
