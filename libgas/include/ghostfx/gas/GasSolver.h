/// @file   GasSolver.h
/// @brief  Fast SPH gas without ambient air [RYY15] Secs. 3 and 5, its ambient-air baseline and
///         the uncorrected ablation.
/// @details The solver owns one ParticleSet: gas particles (kind Gas) and boundary particles
///          (kind Boundary) for solids, for the walls of the ambient baseline's domain and for
///          the external boundary a liquid coupler sets each step. In the ambient baseline the
///          air is gas particles marked by the channel "ambient" = 1.
///
///          One step (Method::Fast; the baselines switch parts off, see GasSettings.h):
///           1. emission from the sources (emit);
///           2. sort by cell and one neighbour search (sortParticles), uncorrected density
///              rho_bar_i = sum_j m_j W_ij (Eq. 1 without air, sumDensities);
///           3. density correction (GasCompensation): V_0 (Eq. 5) from
///              n_bar_i = sum_j m_j / rho_bar_j grad W_ij, rho_i = rho_bar_i (1 + V_0 W_ik)
///              (Eq. 8); p_i = kappa (rho_i - rho0) (Eq. 11);
///           4. forces (computeAccelerations): pressure (Eq. 9), normal (Eq. 12), viscosity and
///              gravity, with the parts' terms: the virtual particle's pressure (Eq. 10),
///              atmospheric pressure P_a n_i (Eq. 13, scaled by beta inside, Sec. 5) and damping
///              (Eq. 14) where |n_i| h_i > C_N (GasCompensation); temperature diffusion
///              (Eq. 15), radiation (Eq. 16) and buoyancy (Eq. 17) (GasTemperature); optional
///              vorticity (Eqs. 25 - 26, GasVorticity): Eq. 24; plus the point attractors of
///              GasSettings::attractors (Fig. 7) on visible gas;
///           5. symplectic Euler with the parts' temperature and vorticity updates (integrate);
///              solids move; collision projection; kill box; life strength of isolated
///              particles (Sec. 5); blow-up check.
///
///          Variable smoothing length: every particle carries its kernel support radius in the
///          channel "h" (the paper's h: W(r, h) vanishes for r >= h); a pair uses the symmetric
///          support (h_i + h_j) / 2, so pair sums stay antisymmetric and heat is conserved.
///          Kernels: Mueller et al. 2003 ([RYY15] ref. [20]): poly6 for densities, spiky gradient
///          for pressure, normals and diffusion, the viscosity kernel's Laplacian for viscosity.
///
///          Use:
///          @code
///          GasSolver solver(settings);
///          solver.addSolid(groundLevelSet);
///          GasSource chimney; chimney.temperature = 373; chimney.velocity = Vec3(0, 0.5f, 0);
///          solver.addSource(chimneyLevelSet, chimney);
///          for (int f = 0; f < 100; ++f) solver.advanceFrame();
///          @endcode
///          Resuming: construct with the same settings, restoreState(state), then add the same
///          solids and sources in the same order (solids are not sampled again) and no gas.
#pragma once

#include <ghostfx/gas/GasChannels.h>
#include <ghostfx/gas/GasCompensation.h>
#include <ghostfx/gas/GasEntrainment.h>
#include <ghostfx/gas/GasSettings.h>
#include <ghostfx/gas/GasTemperature.h>
#include <ghostfx/gas/GasVorticity.h>
#include <ghostfx/sph/LevelSet.h>
#include <ghostfx/sph/NeighborGrid.h>
#include <ghostfx/sph/NeighborLists.h>
#include <ghostfx/sph/ParticleSet.h>
#include <ghostfx/sph/RigidMotion.h>
#include <ghostfx/sph/SolverState.h>

#include <openvdb/math/Mat3.h>

#include <cstdint>
#include <functional>
#include <limits>
#include <memory>
#include <vector>

namespace ghostfx {
namespace gas {

using sph::Index;
using sph::LevelSet;
using sph::ParticleKind;
using sph::ParticleSet;

/// solid_index of particles set by setExternalBoundary().
constexpr Real EXTERNAL_BOUNDARY = Real(-1);
/// solid_index of the ambient baseline's domain walls.
constexpr Real DOMAIN_WALL = Real(-2);

using sph::RigidMotion;
using sph::RigidTransform;

/// A gas source: while active, its volume is kept full of gas (new particles grow from the gas
/// already inside, at least 0.92 spacing from every particle), and the gas inside it is held at
/// `temperature`. In the ambient baseline the air inside it turns into visible gas instead.
struct GasSource
{
    Real temperature = Real(373.15); ///< temperature of the emitted gas (K)
    Vec3 velocity{0};                ///< velocity of new particles (m/s)
    /// Most particles emitted (or air particles converted) per second; 0 = as many as fit.
    Real rate = Real(0);
    double start = 0;                                     ///< active from (s)
    double end = std::numeric_limits<double>::infinity(); ///< active until (s)
    /// Placement of the source's level set at time t; empty = where the level set is.
    RigidMotion motion;
};

/// Seconds spent in each phase of the step, accumulated since the last reset.
struct GasTimings
{
    double emission = 0;    ///< sources (sampling, ambient conversion)
    double neighbors = 0;   ///< grid rebuild and sort
    double density = 0;     ///< Eqs. 1, 5, 7, 8, 11
    double forces = 0;      ///< Eqs. 10, 12 - 17, 22 - 26
    double integration = 0; ///< positions, solids, collisions, kill box, life strength, checks
    double total = 0;
    std::uint64_t steps = 0;
};

class GasSolver
{
public:
    /// Called at the end of every step() with the solver and the step's dt (s).
    using StepObserver = std::function<void(const GasSolver&, Real dt)>;

    explicit GasSolver(const GasSettings& settings);
    ~GasSolver();

    const GasSettings& settings() const { return mSettings; }

    /// Add a static solid, or one moving rigidly at constant `velocity` (m/s). Boundary particles
    /// are Poisson-sampled in a band one kernel radius deep ([RYY15] Sec. 3.3: boundary particles
    /// take part in every SPH sum). After restoreState() the restored solids are not resampled.
    void addSolid(const LevelSet& solid, const Vec3& velocity = Vec3(0));
    /// Add a solid whose level set (in its local frame) sits at `motion(t)` at time t.
    void addMovingSolid(const LevelSet& solid, RigidMotion motion);
    std::size_t solidCount() const { return mSolids.size(); }

    /// Sample a block of gas from a level set (Poisson-disk, 0.92 spacing; samples closer than
    /// that to existing particles or inside solids are dropped) with `velocity` (m/s) and
    /// `temperature` (K). Returns the number added. Throws ValueError after restoreState().
    std::size_t addGas(const LevelSet& shape, const Vec3& velocity, Real temperature);

    /// Add a continuous source (see GasSource).
    void addSource(const LevelSet& shape, const GasSource& source);
    std::size_t sourceCount() const { return mSources.size(); }

    /// Add gas particles at given positions (m), e.g. a lattice for a test. `mass` (kg) 0 means
    /// the solver's particle mass. Throws ValueError after restoreState().
    void addParticles(const std::vector<Vec3>& positions, const Vec3& velocity, Real temperature,
                      Real mass = Real(0));

    /// Add gas particles created elsewhere, e.g. vapour split off a liquid by a phase-transition
    /// coupler ([RYY15] Sec. 4.2), one entry per particle in each vector: position (m),
    /// velocity (m/s), temperature (K), mass (kg, finite > 0) and kernel support radius h (m,
    /// finite > 0). Unlike addParticles this is allowed at any time, also after restoreState()
    /// (a coupler adds vapour every step). Throws ValueError on mismatched sizes or bad values
    /// (nothing is added then). @return index of the first new particle
    Index addGasParticles(const std::vector<Vec3>& positions, const std::vector<Vec3>& velocities,
                          const std::vector<Real>& temperatures, const std::vector<Real>& masses,
                          const std::vector<Real>& supportRadii);

    /// Mass (kg) of a gas particle at the configured spacing: particleMass() once initialised,
    /// before that settings().particleMass or the automatic reference mass the first step will
    /// use. Lets a coupler size particles before the first gas step.
    Real referenceParticleMass() const;

    /// Replace the external boundary (e.g. liquid particles of a phase-transition coupler): from
    /// the next step these particles take part in every sum like solid boundary particles,
    /// carrying `mass` (kg) in the gas sums, until the next call replaces them.
    void setExternalBoundary(const std::vector<Vec3>& positions,
                             const std::vector<Vec3>& velocities, Real mass);

    /// Advance one frame: `substeps` fixed steps, or CFL-limited steps up to the frame end.
    void advanceFrame();
    /// One step of length dt (s).
    void step(Real dt);
    /// The CFL-limited time step for the current state (s).
    Real stableTimeStep() const;

    void setStepObserver(StepObserver observer);

    /// Everything that decides how the run continues, as a SolverState with solver name "gas":
    /// all particles and channels, and
    ///  - reals: "time" (s), "particle_mass" (kg), "max_acceleration" (m/s^2, CFL),
    ///    "mean_neighbors", "source_budget_<k>" (particles a rate-limited source may still emit);
    ///  - integers: "step", "frame", "initialized", "method" (as Method), "emitted", "killed",
    ///    "isolated_removed", "solids" and "sources" (how many the caller must add again).
    sph::SolverState saveState() const;
    /// Continue from a saved state on a freshly constructed solver with the same settings, then
    /// add the same solids and sources in the same order, and no gas. Throws ValueError if the
    /// state is from another solver or method, lacks a key, or the solver is not fresh.
    void restoreState(const sph::SolverState& state);

    /// Particle mass (kg) given to new particles; automatic (settings) at the first step.
    Real particleMass() const { return mMass; }

    ParticleSet& particles() { return mParticles; }
    const ParticleSet& particles() const { return mParticles; }
    std::size_t count(ParticleKind kind) const { return mParticles.count(kind); }
    /// Visible gas particles (gas that is not ambient air).
    std::size_t visibleGasCount() const;
    /// Ambient air particles (Method::Ambient).
    std::size_t ambientCount() const;

    double time() const { return mRun.time; }
    std::uint64_t stepCount() const { return mRun.step; }
    int frame() const { return mRun.frame; }

    const GasTimings& timings() const { return mTimings; }
    void resetTimings() { mTimings = GasTimings(); }
    /// Mean number of neighbours per gas particle in the last density pass (self included).
    double meanNeighbors() const { return mRun.meanNeighbors; }

    std::size_t emittedCount() const { return mRun.emitted; }
    std::size_t killedCount() const { return mRun.killed; }
    /// Isolated particles removed by the life strength rule (Sec. 5).
    std::size_t isolatedRemovedCount() const { return mIsolatedRemoved; }
    /// The emitted gas's mass the last step removed (kg; kill box, life strength): the sum of
    /// m_i c_i over the removed particles with entrainment (c_i their smoke share: the air they
    /// drew in is not counted), of m_i without.
    double removedLastStep() const { return mRemovedLastStep; }

private:
    struct Solid;
    struct Source;

    void initialize();
    /// Remove the particles marked in `remove`, adding their emitted mass to mRemovedLastStep.
    void removeMarked(const std::vector<std::uint8_t>& remove);
    void ensureSolidChannels();
    void checkRestoredInputs() const;
    void sampleSolid(std::size_t solidIndex);
    void buildDomainWalls();
    void fillAmbientAir();
    struct PlacedSource;
    /// Sources (dt in s): convert air, add new gas, heat the gas inside.
    void emit(Real dt);
    /// Ambient baseline: air inside the source turns into visible gas, at most `allowed`
    /// particles. Returns how many.
    std::size_t convertAmbientAir(const PlacedSource& at, std::size_t allowed);
    /// Fill the free room of source e with new gas, at most `room` particles. Returns how many.
    std::size_t addFreshGas(std::size_t e, const PlacedSource& at, std::size_t room);
    /// Samples of an empty source e clear of solids and `obstacles` (m, world).
    std::vector<Vec3> fillSource(std::size_t e, const PlacedSource& at,
                                 const std::vector<Vec3>& obstacles) const;
    /// New samples in source e grown from the gas already in it (`seeds`, m, world).
    std::vector<Vec3> growFromSeeds(std::size_t e, const PlacedSource& at,
                                    const std::vector<Vec3>& seeds,
                                    const std::vector<Vec3>& obstacles) const;
    /// Hold the visible gas inside the source at its temperature.
    void heatSourceGas(const PlacedSource& at);
    bool blockedBySolid(const Vec3& x) const;
    Real referenceMass() const;
    void assignMissingMasses();
    void sortParticles();
    /// Add the channels a step writes (those the constructor adds after "temperature" and
    /// "h"); present ones are kept.
    void addStepChannels();
    /// Density pass: Eq. 1, the parts' correction, Eq. 11.
    void computeDensity();
    /// Eq. 1 without air: rho_bar_i, the neighbour count and the isolated flags.
    void sumDensities();
    /// rho_i (Eq. 8 in the fast method, rho_bar_i otherwise) and p_i (Eq. 11).
    void correctDensities();
    /// The force pass (Eqs. 9 - 17, 22 - 26): every particle's acceleration (m/s^2, zero for
    /// boundary particles); the parts keep their rates for integrate().
    std::vector<Vec3> computeAccelerations();
    /// Symplectic Euler over dt (s) with `accel`, the parts' temperature and vorticity updates
    /// and the largest acceleration for the CFL limit.
    void integrate(Real dt, const std::vector<Vec3>& accel);
    /// Grow the support of particles born denser than the gas (added with an h below the one
    /// their mass has at rest: vapour born at the liquid's density) as they expand.
    void expandSupports();
    void moveSolids(double t1);
    void projectOutOfSolids(Real dt);
    void applyDomain();
    void applyLifeStrength(Real dt);
    void checkBlowUp(Real dt) const;
    /// After a frame: stop with a NumericalError when the gas is flying apart (median density
    /// below rho0 / 2 over 100 or more gas particles; not the uncorrected baseline).
    void checkHoldsTogether() const;
    std::vector<Vec3> sampleShape(const LevelSet& shape, std::uint64_t seed) const;

    GasSettings mSettings;
    GasCompensation mCompensation; ///< Eqs. 5, 8, 10, 13, 14 (Method::Fast)
    GasTemperature mTemperature;   ///< Eqs. 15 - 17
    GasVorticity mVorticity;       ///< Eqs. 25 - 26
    GasEntrainment mEntrainment;   ///< ambient air mixed in at the boundary ([MTT56])
    ParticleSet mParticles;
    sph::NeighborGrid mGrid;
    /// Each gas particle's neighbours (gas and boundary) within the grid's cell size, searched
    /// once per step in sortParticles() and read by the density and force passes.
    sph::NeighborLists mLists;
    std::vector<std::uint8_t> mQueryMask; ///< 1 for gas particles: the queries of mLists
    std::vector<std::unique_ptr<Solid>> mSolids;
    std::vector<std::unique_ptr<Source>> mSources;
    std::vector<std::uint8_t> mIsolated; ///< no neighbour this step (Sec. 5)
    Real mMass = 0;
    sph::RunCounters mRun; ///< clock and counters
    std::size_t mIsolatedRemoved = 0;
    double mRemovedLastStep = 0; ///< removedLastStep()
    GasTimings mTimings;
    StepObserver mObserver;
    bool mRestored = false;
    std::size_t mRestoredSolids = 0;
    std::size_t mRestoredSources = 0;
    std::vector<double> mRestoredBudgets;
};

} // namespace gas
} // namespace ghostfx
