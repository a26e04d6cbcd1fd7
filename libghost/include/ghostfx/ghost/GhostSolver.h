/// @file   GhostSolver.h
/// @brief  The liquid solver of [SB12]: Ghost SPH (Algorithm 3) and the Basic SPH baseline.
/// @details A solver owns one ParticleSet holding liquid, ghost air and ghost solid particles
///          (Ghost SPH) or liquid and boundary particles (Basic SPH), told apart by their kind.
///          Solids are level sets; they are sampled once into a band one kernel radius deep
///          ([SB12] Sec. 4.4). Initial liquid comes from level sets (sampler, relaxation and the
///          mass scaling of Sec. 4.6) or from explicit positions.
///
///          Use:
///          @code
///          GhostSolver solver(settings);
///          solver.addSolid(tankLevelSet);
///          solver.addLiquid(waterLevelSet);
///          for (int f = 0; f < 100; ++f) solver.advanceFrame();
///          @endcode
///          Resuming a run (e.g. from a vdbio checkpoint) continues it bit for bit:
///          @code
///          GhostSolver solver(settings);          // the same settings as the original run
///          solver.restoreState(state);            // first, before any solid or emitter
///          solver.addSolid(tankLevelSet);         // the same solids and emitters, same order;
///          solver.addEmitter(nozzle, velocity);   // no liquid bodies (already in the state)
///          while (solver.frame() < 100) solver.advanceFrame();
///          @endcode
///          Solid particles live apart from the liquid and air, in two boundary blocks
///          (sph::BoundaryBlock): one for static solids, sorted once and never touched again, and
///          one for moving solids, re-placed every step. A step searches neighbours once
///          (sph::NeighborLists, from the liquid particles into the liquid-and-air grid and each
///          block's grid) and every pass reuses the lists, so a solid particle no liquid reaches
///          costs nothing: the cost of a step follows the liquid, not the tank.
///          Only the channels the scene needs exist: the ghost air channels (air_weight,
///          air_target) only for the Ghost method; the solid channels (normal, solid_index, and
///          for moving solids solid_v, solid_x, solid_n) only on the solid particles.
///          The solver never opens files; it reports per-phase timings for benchmarks ([SB12]
///          Sec. 5 breakdown) and throws NumericalError naming frame, step and the exceeded limit
///          when a run blows up.
#pragma once

#include <ghostfx/ghost/GhostSettings.h>
#include <ghostfx/ghost/LiquidStep.h>
#include <ghostfx/ghost/PressureSolver.h>
#include <ghostfx/sph/BoundaryBlock.h>
#include <ghostfx/sph/Kernels.h>
#include <ghostfx/sph/LevelSet.h>
#include <ghostfx/sph/NeighborGrid.h>
#include <ghostfx/sph/NeighborLists.h>
#include <ghostfx/sph/ParticleExchange.h>
#include <ghostfx/sph/ParticleSet.h>
#include <ghostfx/sph/RigidBody.h>
#include <ghostfx/sph/RigidContact.h>
#include <ghostfx/sph/RigidMotion.h>
#include <ghostfx/sph/SampleStore.h>
#include <ghostfx/sph/SolverState.h>

#include <openvdb/math/Mat3.h>

#include <chrono>
#include <cstdint>
#include <functional>
#include <limits>
#include <memory>
#include <optional>
#include <utility>
#include <vector>

namespace ghostfx {
namespace ghost {

using sph::Index;
using sph::LevelSet;
using sph::ParticleKind;
using sph::ParticleSet;

using sph::RigidMotion;
using sph::RigidTransform;

/// A solid that the liquid moves and that moves the liquid (GhostSolver::addDynamicSolid): a
/// uniform rigid body given by its density or its mass.
struct DynamicSolid
{
    double density = 0;              ///< kg/m^3; or 0 and a mass
    double mass = 0;                 ///< kg; or 0 and a density
    sph::Vec3d velocity{0.0};        ///< initial, of the centre of mass (m/s)
    sph::Vec3d angularVelocity{0.0}; ///< initial (rad/s)
    sph::RigidBodyMaterial material; ///< restitution and friction of its contacts
};

/// Seconds spent in each phase of the step, accumulated since the last reset ([SB12] Sec. 5).
struct PhaseTimings
{
    double neighborsAndDensity =
        0;                    ///< sort + neighbour search + density (+ solid density extrapolation)
    double sortAndSearch = 0; ///< of which: the sort and the neighbour search
    double pressureForce = 0; ///< equation of state + pressure (and Basic viscosity/LJ) forces
    double xsphAndBoundary = 0; ///< ghost velocities, XSPH, positions, collisions
    double airResampling = 0;   ///< ghost air sampling
    double emission = 0;        ///< emitter sampling
    double exchange = 0;        ///< with other processes: migration, halos, reductions
    double total = 0;
    std::uint64_t steps = 0;
};

/// What the implicit viscosity's solves did (GhostSettings::viscosity > 0).
struct ViscositySolveStats
{
    std::uint64_t solves = 0;      ///< steps with a solve
    std::uint64_t iterations = 0;  ///< conjugate-gradient iterations, all steps
    std::uint64_t unconverged = 0; ///< solves stopped at GhostSettings::viscosityMaxIterations
    int lastIterations = 0;        ///< the last step's
    double lastResidual = 0;       ///< the last step's |r| / |b| at its end
    double seconds = 0;            ///< wall time of the solves
};

class ImplicitViscosity;
class SurfaceTension;

class GhostSolver
{
public:
    /// The particle channel of a liquid particle's own kinematic viscosity (m^2/s), where a
    /// liquid or an emitter has one (addLiquid()); without it every particle has
    /// settings.viscosity.
    static constexpr const char* VISCOSITY_CHANNEL = "viscosity";

    /// Called at the end of every step() with the solver and the step's dt (s), e.g. for
    /// progress, statistics or an interrupt (an exception thrown here leaves step() after a
    /// complete step, so the state stays consistent).
    using StepObserver = std::function<void(const GhostSolver&, Real dt)>;

    /// A solver with the pressure model `pressure`, or (null) the one the settings name
    /// (makePressureSolver).
    explicit GhostSolver(const GhostSettings& settings,
                         std::unique_ptr<PressureSolver> pressure = nullptr);
    ~GhostSolver();

    const GhostSettings& settings() const { return mSettings; }
    const sph::CubicSplineKernel& kernel() const { return mKernel; }
    /// The pressure model that runs each step (PressureSolver.h).
    const PressureSolver& pressureSolver() const { return *mPressure; }

    /// Add a static solid, or one moving rigidly with constant `velocity` (m/s). Its ghost
    /// (or boundary) particles are sampled at once, one kernel radius deep; after
    /// restoreState(), the solids the state already holds are not sampled again. A solid with
    /// zero velocity is static: its particles join the static block (sorted once).
    void addSolid(const LevelSet& solid, const Vec3& velocity = Vec3(0));
    /// Add a solid moving rigidly: at time t its level set (given in its local frame) sits at
    /// `motion(t)`. Its ghosts move with it and carry its velocity ([SB12] Sec. 4.4).
    void addMovingSolid(const LevelSet& solid, RigidMotion motion);
    /// Replace the shape of solid `solidIndex` (in the order added), e.g. with this frame's level
    /// set of a deforming solid: its ghosts are sampled anew, its motion is kept. Solids keep
    /// their index for the life of the solver.
    void setSolidShape(std::size_t solidIndex, const LevelSet& shape);
    /// Replace the motion of moving solid `solidIndex` from now on (a script steering a paddle):
    /// the motion should continue from the solid's current placement, or its ghosts jump. A
    /// solid added as static is refused (its ghosts are sorted once and never re-placed).
    /// Motions are not part of saveState(): a restored run uses what its caller adds.
    void setSolidMotion(std::size_t solidIndex, RigidMotion motion);
    std::size_t solidCount() const { return mSolids.size(); }

    /// Add a rigid body the liquid pushes and that pushes it back (GhostBodies.cc): its mass,
    /// centre and inertia from its level set (sph::massProperties), its ghost particles
    /// sampled as a moving solid's. Each step the liquid's pressure and wall drag on its
    /// ghosts, reversed, are its force and torque, with gravity and any force a caller adds;
    /// it then touches the other solids and bodies (level-set contact with its restitution
    /// and friction) and moves. Ghost SPH only (Tait or DFSPH), on one process. After
    /// restoreState() it continues from the state's body. Returns the solid's index.
    std::size_t addDynamicSolid(const LevelSet& solid, const DynamicSolid& body);
    /// Whether solid `solidIndex` is a dynamic one.
    bool isDynamic(std::size_t solidIndex) const;
    /// The body of dynamic solid `solidIndex` (its state at time()). ValueError for another.
    const sph::RigidBody& body(std::size_t solidIndex) const;
    /// Add a force (N, at the centre of mass) and a torque (N m) to what acts on dynamic solid
    /// `solidIndex` in every step until clearBodyForces().
    void addBodyForce(std::size_t solidIndex, const sph::Vec3d& force, const sph::Vec3d& torque);
    void clearBodyForces();
    /// The force and torque (about the centre of mass) the liquid gave dynamic solid
    /// `solidIndex` in the last step, as it acted (after the added-mass filter, GhostBodies.cc).
    std::pair<sph::Vec3d, sph::Vec3d> liquidForceOn(std::size_t solidIndex) const;
    /// Where solid `solidIndex` (in the order added) is now: its motion at time() (the
    /// identity for a static solid).
    RigidTransform solidPlacement(std::size_t solidIndex) const;

    /// Sample a liquid body from a level set ([SB12] Sec. 4.5 - 4.6) with initial velocity
    /// `velocity` (m/s). Returns the number of particles added. Throws ValueError after
    /// restoreState(): the restored particles already hold the liquid.
    /// A `viscosity` (m^2/s, in settings.viscosity's range) is this liquid's own: its
    /// particles carry it in the channel ImplicitViscosity::NU_CHANNEL, and every other
    /// liquid particle has settings.viscosity (two liquids of different thickness in a scene).
    std::size_t addLiquid(const LevelSet& shape, const Vec3& velocity = Vec3(0),
                          std::optional<Real> viscosity = std::nullopt);

    /// Continuous emission ([SB12] Sec. 4.5.2): from `startTime` to `endTime` (s) the emitter
    /// volume is kept full of liquid moving at `velocity` (m/s); new particles grow from the
    /// liquid already there (t = 8 attempts), at least r from every particle, so the new liquid
    /// joins the old without overlap. The mass emitted per second is rho0 times the speed
    /// times the emitter's cross-section (the shadow of its level set along the velocity):
    /// the fills are capped by that rate, since gaps filled a few millimetres a step pack
    /// more tightly than rest density. An emitter with zero velocity has no rate and keeps
    /// its shape full. A `viscosity` is the new liquid's own, as addLiquid()'s.
    void addEmitter(const LevelSet& shape, const Vec3& velocity, double startTime = 0,
                    double endTime = std::numeric_limits<double>::infinity(),
                    std::optional<Real> viscosity = std::nullopt);
    /// An emitter moving rigidly (a hose sweeping a floor): at time t its level set (given in
    /// its own frame) sits at `motion(t)`, and `velocity` is the liquid's in that frame. The
    /// liquid in it, and the new liquid, move at `velocity` rotated with the emitter plus the
    /// emitter's own velocity at the particle; the rate is addEmitter's, in the emitter's
    /// frame. Motions are not part of saveState(): a restored run uses what its caller adds.
    void addMovingEmitter(const LevelSet& shape, const Vec3& velocity, RigidMotion motion,
                          double startTime = 0,
                          double endTime = std::numeric_limits<double>::infinity(),
                          std::optional<Real> viscosity = std::nullopt);
    /// Each emitter's cross-section (m^2, the shadow of its shape along its velocity; 0 without
    /// velocity) and the mass it pours per second (kg/s, rho0 |velocity| times that), in the
    /// order added.
    struct EmitterRate
    {
        double crossSection, massRate;
    };
    std::vector<EmitterRate> emitterRates() const;

    /// Add liquid particles at given positions (m), e.g. a lattice for a test. Throws
    /// ValueError after restoreState(), like addLiquid().
    void addLiquidParticles(const std::vector<Vec3>& positions, const Vec3& velocity = Vec3(0),
                            std::optional<Real> viscosity = std::nullopt);

    /// Advance one frame: `substeps` fixed steps, or CFL-limited steps up to the frame end.
    /// With settings.pressure = dfsph the pressure channel is set by the frame's last step
    /// only (a step observer sees the last frame's pressure before it).
    void advanceFrame();
    /// One step of length dt (s): the pressure model's (Algorithm 3 for Ghost SPH, or Basic
    /// SPH's), then collisions, the kill box and the blow-up check.
    void step(Real dt) { step(dt, true); }
    /// The same; with reportPressure false a DFSPH step leaves the pressure channel as it was
    /// (only output reads it, and its pass costs about 3 % of the step): for drivers
    /// that end frames themselves and report on each frame's last step, as advanceFrame() does.
    void step(Real dt, bool reportPressure);
    /// The CFL-limited time step for the current state (s).
    Real stableTimeStep() const;
    /// |rho / rho0 - 1| over the liquid when the run started: mean and largest, as sampled
    /// and after the initial relaxation (zeros until then, or without relaxation).
    struct InitialDensityError
    {
        double meanSampled = 0, maxSampled = 0, meanRelaxed = 0, maxRelaxed = 0;
    };
    const InitialDensityError& initialDensityError() const { return mInitialError; }

    /// Install (or, with an empty function, remove) the observer called after every step.
    void setStepObserver(StepObserver observer);

    /// The first air layer, the mass scaling and the initial relaxation, which the first step
    /// would otherwise make. Returns false while waiting for an emitter that starts later.
    bool prepare() { return initialize(); }

    /// Share this simulation with other processes (one MPI rank each): from now on this
    /// solver owns and computes only the liquid and air in `exchange`'s region, receives halo
    /// copies of its neighbours' particles every step and agrees with the others on the time
    /// step and on blow-ups (sph::ParticleExchange). Call it on every process after the same
    /// set-up and prepare(): the particles outside the region are dropped here (unless
    /// `ownPart`: the state was restored from this process's own part of a checkpoint), and
    /// new particles take ids of this process's own sequence. Emitters sample from their surroundings gathered from
    /// every process (all sample the same new liquid; each keeps what lies in its region);
    /// solids, moving or not, are whole on every process. Supported: Ghost SPH with the Tait
    /// pressure; anything else is refused with a ValueError. The exchange must outlive the
    /// solver's steps.
    void setExchange(sph::ParticleExchange* exchange, bool ownPart = false);
    sph::ParticleExchange* exchange() const { return mExchange; }

    /// Take the samples of solids and liquid bodies from `store` when it holds them, and keep
    /// new ones there (sph::SampleStore: the same samples, bit for bit, without sampling
    /// again). Call before adding solids and liquid; the store must outlive them. Null: none.
    void setSampleStore(sph::SampleStore* store) { mSampleStore = store; }

    /// Everything that decides how the run continues, as a SolverState with solver name
    /// methodName(method): all particles and channels, and
    ///  - reals: "time" (s), "particle_mass" (kg), "lennard_jones" (m^2/s^2), "max_acceleration"
    ///    (m/s^2, used by the CFL limit), "mean_neighbors" (diagnostic), "emitter_credit_E"
    ///    (kg each emitter E still owes), "emitter_fill_scale_E" (its fills' radius, in Poisson
    ///    radii), "air_phase_credit" (air resampling phases owed, a fraction);
    ///  - integers: "step", "frame", "initialized" (0/1), "emitted", "killed", "solids" and
    ///    "emitters" (how many the caller must add again after restoreState), "air_phase" (the
    ///    next resampling phase), "pressure_dfsph" and "air_weights_complete" (0/1: the
    ///    settings the state is valid for).
    /// vdbio migrates checkpoints of older schemas to these keys (Checkpoint.h).
    /// Per-step scratch (neighbour grid, nearest-liquid table) is rebuilt by every step and
    /// timings are not simulation state, so neither is saved.
    sph::SolverState saveState() const;
    /// Continue from a saved state. Call it on a freshly constructed solver with the same
    /// settings, before adding solids or emitters; then add the same solids (not sampled again:
    /// their particles are in the state) and emitters, in the original order, and no liquid.
    /// Throws ValueError if the state comes from another method ("ghost" / "basic"), lacks a
    /// key, or the solver is not fresh; step() throws if fewer solids or emitters were added
    /// again than the state had.
    void restoreState(const sph::SolverState& state);

    /// Particle mass (kg), the same for every particle; set at the first step by the mass
    /// scaling of [SB12] Sec. 4.6 unless set explicitly.
    Real particleMass() const { return mMass; }
    void setParticleMass(Real mass);
    /// The particle mass (kg) the first step gives the liquid added so far: particleMass() once
    /// set; before that, what the mass scaling of [SB12] Sec. 4.6 gives it, measured on a probe
    /// with its own air layer (this solver is not changed); 0 while there is no liquid.
    Real startParticleMass() const;
    /// The first step's set-up (air layer, mass scaling, relaxation) is done.
    bool initialized() const { return mRun.initialized; }
    /// After the liquid's positions were set from outside (a script moving it): a Ghost SPH
    /// solver samples its ghost air anew, a full layer at once as at the first step (the
    /// resampling renews a phase of it per step, and the old layer would stay where the liquid
    /// was). Nothing to redo before the first step or for Basic SPH.
    void liquidMoved();

    /// The moving particles: liquid and ghost air.
    ParticleSet& particles() { return mParticles; }
    const ParticleSet& particles() const { return mParticles; }
    /// The solid particles (ghost solids for Ghost SPH, boundary particles for Basic SPH) of the
    /// static solids and of the moving ones. Their density, pressure and velocity are those
    /// of the last step's extrapolation where liquid reached them ([SB12] Algorithm 3 lines
    /// 5-7 and 15-18), otherwise rho0, 0 and the solid's velocity.
    ParticleSet solidParticles() const;
    /// Every particle, liquid, air and solid, in one set: what saveState() stores.
    ParticleSet allParticles() const;
    /// Particles of one kind, in every set.
    std::size_t count(ParticleKind kind) const;
    /// Bytes held by the solver, by part: the capacity of every array it keeps from one step
    /// to the next (what the process holds), not the passes' temporaries.
    struct MemoryUse
    {
        std::size_t particles = 0;      ///< liquid and ghost air, every channel
        std::size_t grid = 0;           ///< their neighbour grid
        std::size_t lists = 0;          ///< the step's lists, liquid and air to liquid and air
        std::size_t solidParticles = 0; ///< ghost solid (or boundary) particles, every channel
        std::size_t solidGrids = 0;     ///< the solid blocks' grids
        std::size_t solidLists = 0;     ///< the step's lists, liquid to solid particles
        std::size_t stepArrays = 0;     ///< per-particle scratch: masks, nearest liquid, DFSPH

        std::size_t total() const
        {
            return particles + grid + lists + solidParticles + solidGrids + solidLists + stepArrays;
        }
    };
    MemoryUse memoryUse() const;
    /// memoryUse().total().
    std::size_t memoryBytes() const { return memoryUse().total(); }
    /// Of which the step's neighbour lists (rebuilt every step: about 1.4 bytes per pair).
    std::size_t neighborListBytes() const;

    double time() const { return mRun.time; }
    std::uint64_t stepCount() const { return mRun.step; }
    int frame() const { return mRun.frame; }

    const PhaseTimings& timings() const { return mTimings; }
    void resetTimings()
    {
        mTimings = PhaseTimings();
        mPressure->resetStats();
    }
    /// The implicit pressure solves' iterations and errors (settings.pressure = dfsph; zeros
    /// for a model without solves).
    const PressureSolveStats& pressureSolveStats() const;
    /// The implicit viscosity's statistics (all zero without GhostSettings::viscosity).
    const ViscositySolveStats& viscositySolveStats() const;
    /// Mean number of neighbours per liquid particle in the last density pass (self included).
    double meanNeighbors() const { return mRun.meanNeighbors; }
    /// Liquid-neighbour pairs in the last neighbour search, solid neighbours included.
    std::size_t lastPairCount() const { return mPairCount; }

    /// Liquid particles emitted and removed by the kill box since the start.
    std::size_t emittedCount() const { return mRun.emitted; }
    std::size_t killedCount() const { return mRun.killed; }
    /// Liquid particles put back where they started a step because they ended it deeper in a
    /// solid than its level set's band (sph::collideWithSolid), since the solver was made.
    std::uint64_t restoredFromSolidsCount() const { return mRestoredFromSolids; }

private:
    friend class LiquidStep;
    friend class DensitySummation;
    struct Solid;
    struct Emitter;
    struct Body;
    /// The nearest liquid particle of each particle of a solid block that some liquid reaches
    /// this step, as packed (distance, index) keys (GhostInternal.h, nearestKey) that the
    /// density pass lowers. Kept in pages of 2^PAGE_BITS particles, allocated only for the
    /// pages that the step's lists reach: most of a tank's ghosts are out of every liquid
    /// particle's reach (bench/history/diary-2026-11.md, "Bytes per particle over the double dam
    /// break's run").
    class NearestKeys
    {
    public:
        static constexpr unsigned PAGE_BITS = 8;
        /// Allocate the pages of a block of `particles` that `lists` (liquid -> block) reach,
        /// every key NO_LIQUID; the others hold no memory.
        void prepare(const sph::NeighborLists& lists, std::size_t particles);
        /// The key of particle s, whose page must be reached by the lists.
        std::uint64_t& operator[](Index s)
        {
            return mKeys[std::size_t(mPage[s >> PAGE_BITS]) + (s & PAGE_MASK)];
        }
        std::uint64_t operator[](Index s) const
        {
            return mKeys[std::size_t(mPage[s >> PAGE_BITS]) + (s & PAGE_MASK)];
        }
        void clear();
        std::size_t memoryBytes() const;

    private:
        static constexpr Index PAGE_MASK = (Index(1) << PAGE_BITS) - 1;
        std::vector<std::uint32_t> mPage; ///< per page: its first key in mKeys
        std::vector<std::uint64_t> mKeys;
    };
    /// Solid particles of one kind of solid (static or moving) and the step's scratch.
    struct SolidBlock
    {
        explicit SolidBlock(Real cellSize) : block(cellSize) {}
        sph::BoundaryBlock block;
        sph::NeighborLists lists; ///< this step: liquid particle -> block particles
        NearestKeys nearest;      ///< this step: the nearest liquid of the reached particles
        /// Particles some liquid reached this step. The step's density and pressure ([SB12]
        /// Algorithm 3 lines 5-10) and Eq. 3 velocity of a touched particle are kept in the
        /// block set's own density, pressure and velocity channels, which every other particle
        /// holds at rest values (see restSolidValues).
        std::vector<Index> touched;
    };

    /// Emit, sample the first air layer and scale the mass, once; false while there is no
    /// liquid yet and an emitter starts later.
    bool initialize();
    /// [SB12] Sec. 4.6's mass scaling (setParticleMass).
    void scaleMass();
    /// The mass that gives the liquid of `measured` (this solver, or a probe with its air layer
    /// sampled) a mean density of rho0.
    Real restDensityMass(const GhostSolver& measured) const;
    /// For Basic SPH's mass scaling: a Ghost SPH solver over the same liquid and solids, with
    /// its air layer sampled.
    std::unique_ptr<GhostSolver> massProbe() const;
    /// Basic SPH's Lennard-Jones strength: the setting's, or Monaghan 1994's 5 g H.
    Real basicLennardJones() const;
    void checkRestoredInputs() const;
    /// restoreState's checks that `state` was saved by a solver like this one, which is fresh.
    void checkStateFits(const sph::SolverState& state) const;
    /// 1 for each solid particle of `state`, checking that it names one of its `solids`.
    static std::vector<std::uint8_t> solidParticlesOf(const sph::SolverState& state,
                                                      std::int64_t solids);
    void addSolidBody(const LevelSet& solid, RigidMotion motion, bool moving,
                      std::unique_ptr<Body> body = nullptr);
    /// Sampler settings for a liquid body, an emitter or a solid's band ([SB12] Sec. 4.5):
    /// the spacing's Poisson radius, the settings' relaxation and tiling, and `seed`.
    sph::PoissonSettings bodySampling(std::uint64_t seed) const;
    SolidBlock& blockOf(std::size_t solidIndex);
    void clearSolidScratch(SolidBlock& block);
    /// Put the values of a particle that no liquid reaches (rest density, zero pressure, the
    /// solid's velocity) back into the block set's channels of the particles the last step
    /// touched, and forget them. Call before the block's particles are removed or reordered.
    void restSolidValues(SolidBlock& block) const;
    /// The block's particles with rest values everywhere (what a checkpoint stores).
    ParticleSet restingParticles(const SolidBlock& block) const;
    void prepareSolidBlocks();
    void sampleSolid(std::size_t solidIndex);
    /// The level set a solid's ghosts are sampled in: its own, or a dynamic solid's eroded.
    LevelSet ghostShapeOf(const Solid& solid) const;
    /// A solid block's set gives its next particles ids above every id given so far.
    void startSolidIds(ParticleSet& set);
    void claimRestoredSolid(std::size_t solidIndex);
    /// Remove the liquid within half a spacing of the inside of solid `solidIndex`.
    void clearLiquidFrom(std::size_t solidIndex);
    /// Algorithm 3 line 1: new liquid from every emitter open now ([SB12] Sec. 4.5.2).
    void emit();
    void emitFrom(std::size_t emitter);
    /// The emitter's new particles: grown from the liquid in it (`seeds`) at least r from
    /// `obstacles`, or with no seed its shape sampled whole.
    std::vector<Vec3> emitterFill(std::size_t emitter, const std::vector<Vec3>& seeds,
                                  const std::vector<Vec3>& obstacles, const sph::Aabb& box) const;
    /// Add to every emitter's credit the mass it emits over [t0, t1) (s).
    void accrueEmission(double t0, double t1);
    /// Keep no more of `fresh` (emitter `e`'s new particles) than its credit pays for.
    void limitToCredit(Emitter& em, std::size_t e, std::vector<Vec3>& fresh) const;
    /// New liquid and air take ids from `next` on (over several processes: this process's
    /// sequence, the first of its ids at or above `next`).
    void continueIdsFrom(sph::ParticleId next);
    void applyKillBox();
    /// No liquid particle is left (over several processes: on any of them).
    bool liquidIsGone() const;
    /// Remove every ghost air particle (the liquid they surrounded is gone).
    void dropAir();
    /// A step with no liquid: time, the solids and (`accrue`) the emitters' credit advance.
    void stepWithoutLiquid(Real dt, std::chrono::steady_clock::time_point start, bool accrue);
    bool blockedBySolid(const Vec3& x) const;
    /// Give the liquid particles from `first` on their own kinematic viscosity `nu` (checked
    /// against settings.viscosity's range; `what` names them in the error), making the
    /// channel and the viscosity solve where the run has none yet.
    void giveViscosity(Index first, Real nu, const std::string& what);
    /// The viscosity solve and its channels, where settings.viscosity or a liquid's own asks
    /// for one.
    void enableViscosity();
    void appendSolidPositionsInBox(const sph::Aabb& box, std::vector<Vec3>& out) const;
    /// Resample the air in the blocks of `count` phases from `phase` on (phase < 0:
    /// everywhere), see AirResampling.h.
    void resampleAir(int phase, int count = 1);
    /// Move every fading air particle's weight towards its target by span / airResampleSteps
    /// (span: GhostSettings::airResampleSpan).
    void fadeAir(Real span);
    void searchNeighbors();
    /// Eq. 1's density of every liquid particle (ghost solids: their nearest liquid's), with
    /// what `pass` asks for in the same pass over the pairs (DFSPH's factors), then the
    /// pressure model's equation of state, if it has one.
    void computeDensity(const DensityPass& pass = DensityPass());
    /// Move the liquid towards rest density before the first step (GhostSettings::
    /// initialRelaxation), recording the density error before and after.
    void relaxInitialLiquid();
    /// One relaxation pass's move of each liquid particle down its density gradient.
    void relaxationShift(std::vector<Vec3>& shift) const;
    void extrapolateSolidVelocity();
    /// Algorithm 3 lines 1-7 (LiquidStep::searchAndDensity).
    void searchAndDensity(const DensityPass& pass);
    /// Algorithm 3 lines 15-28 after the pressure (LiquidStep::finish). Reads VSTAR.
    void finishGhostStep(Real dt, const std::vector<Vec3>& gradMass);
    /// Lines 19-21: XSPH (Eq. 2) from v* into the liquid's velocities, with the walls' drag.
    void applyXsph(Real dt);
    /// Lines 22-25: each air particle takes its nearest liquid particle's new velocity.
    void airFollowsLiquid();
    /// Particle shifting down the concentration gradient (GhostSettings::shiftingCoefficient),
    /// `gradMass` each particle's sum_j m_j grad W_ij.
    void shiftParticles(Real dt, const std::vector<Vec3>& gradMass);
    /// Each solid particle liquid reaches takes its nearest liquid particle's pressure.
    void pressureToSolids();
    void moveSolids(double time);
    void projectOutOfSolids(Real dt);
    /// The error of liquid particle i left inside a solid deeper than its band.
    [[noreturn]] void throwStuckInSolid(std::size_t i) const;
    // Dynamic solids (GhostBodies.cc) ----------------------------------------------------------
    Body& bodyOf(std::size_t solidIndex) const;
    /// A restored dynamic solid's body: its state and mass properties from mRestoredBodies.
    void restoreBody(Body& body, std::size_t index, const std::string& name) const;
    bool hasBodies() const;
    /// Per particle of the moving block: 1 for a dynamic solid's ghost (empty with no bodies).
    std::vector<char> bodyGhostFlags() const;
    /// Each solid's place among the dynamic solids (0, 1, ... in solid order), -1 for others.
    std::vector<int> bodySlots() const;
    /// The bodies' centres of mass, in slot order.
    std::vector<sph::Vec3d> bodyCentres(const std::vector<int>& slot) const;
    /// The world box of a body's contact points where it is, grown by `margin` (m).
    sph::Aabb bodyBox(const Body& b, double margin) const;
    /// The fastest owned liquid particle (m/s), over every process.
    Real fastestOwnedLiquid() const;
    /// The body's contact points: its ghost particles on its surface, in its own frame.
    void findContactPoints(std::size_t solidIndex);
    /// The liquid's pressure and drag on each body this step (before the particles move).
    void gatherBodyForces(Real dt);
    /// Each body's wetShare: the share of its ghosts the liquid reached this step.
    void measureWetShares(const std::vector<int>& slot);
    /// Each body over the step: forces, contacts, then its motion.
    void advanceBodies(Real dt);
    void resolveBodyContacts(Real dt);
    /// One sweep of dynamic solid e's contacts: with the bodies after it, or with the solids.
    /// Returns the contact points touching.
    int contactsOf(std::size_t e, bool bodies, Real dt, sph::ContactSettings settings);
    /// The momentum the collision projection took from liquid particles hitting each body.
    void giveCollisionImpulses(const std::vector<Vec3>& impulse,
                               const std::vector<std::uint32_t>& hit);
    /// The fastest point of any body's box (m/s), for the time step.
    Real fastestBody() const;
    void saveBodies(sph::SolverState& state) const;
    void readRestoredBodies(const sph::SolverState& state);
    void checkBlowUp() const;
    Index nearestLiquid(const Vec3& x, Real maxRadius) const;
    /// The halo flags of mParticles (HALO_CHANNEL) when shared with other processes, else null.
    const Real* haloFlags() const
    {
        return mExchange ? mParticles.scalarChannel(sph::HALO_CHANNEL).data() : nullptr;
    }

    sph::SampleStore* mSampleStore = nullptr;
    GhostSettings mSettings;
    sph::CubicSplineKernel mKernel;
    ParticleSet mParticles;         ///< liquid and ghost air
    sph::NeighborGrid mGrid;        ///< over mParticles, rebuilt (and mParticles sorted) each step
    sph::NeighborLists mFluidLists; ///< this step: liquid particle -> mParticles
    /// This step, over several processes only: 1 for the liquid and air this process owns
    /// (their lists; on one process every particle of mParticles is one).
    std::vector<std::uint8_t> mQueryMask;
    std::vector<Real> mScratch;  ///< per particle scratch of a pass
    SolidBlock mStatic, mMoving; ///< solid particles of static and of moving solids
    ParticleSet mPendingSolids;  ///< restored solid particles until their solid is added
    std::vector<std::unique_ptr<Solid>> mSolids;
    std::vector<std::unique_ptr<Emitter>> mEmitters;
    std::uint64_t mRestoredFromSolids = 0;
    Real mMass = 0;
    Real mLennardJones = 0;
    Real mMaxSolidSpeed = 0; ///< fastest moving-solid particle (m/s), for the collision test
    bool mProjectAll = true; ///< a solid changed shape: test every liquid particle for collision
    sph::RunCounters mRun;   ///< clock and counters (maxAcceleration: of the liquid)
    /// The air's next resampling phase, counted without the modulus (the step's index while
    /// every step spans one phase), and the fraction of a phase the steps so far have spanned
    /// beyond the phases resampled (GhostSettings::airResampleSpan).
    std::uint64_t mAirPhase = 1;
    double mAirPhaseCredit = 0;
    PhaseTimings mTimings;
    /// Whether this step sets the pressure channel (step()'s reportPressure).
    bool mReportPressure = true;
    std::unique_ptr<PressureSolver> mPressure;
    /// The implicit viscosity, with GhostSettings::viscosity > 0 (ImplicitViscosity.h).
    std::unique_ptr<ImplicitViscosity> mViscosity;
    /// The surface tension, with GhostSettings::surfaceTension > 0 (SurfaceTension.h).
    std::unique_ptr<SurfaceTension> mSurfaceTension;
    InitialDensityError mInitialError;
    std::size_t mPairCount = 0;
    StepObserver mObserver;
    sph::ParticleExchange* mExchange = nullptr; ///< other processes of this simulation, if any
    bool mRestored = false;            ///< restoreState() was called: no liquid may be added
    std::size_t mRestoredSolids = 0;   ///< solids whose particles came with the restored state
    std::size_t mRestoredEmitters = 0; ///< emitters the restored run had
    /// Their Emitter::credit and fillScale, by index.
    std::vector<std::pair<double, double>> mRestoredEmitterFills;
    /// The restored state's body of each dynamic solid, by solid index (empty for others).
    std::vector<std::vector<double>> mRestoredBodies;
};

} // namespace ghost
} // namespace ghostfx
