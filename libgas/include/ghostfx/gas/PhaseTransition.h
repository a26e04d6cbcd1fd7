/// @file   PhaseTransition.h
/// @brief  Liquid-gas phase transition of [RYY15] Sec. 4: heating, boiling and evaporation by
///         particle splitting, merging of over-split liquid, and the liquid as a gas boundary.
/// @details A driver that advances a liquid solver (seen through the narrow `LiquidSide`
///          interface, so libgas never includes libghost, docs/architecture.md) and a GasSolver in lockstep.
///          One step(dt):
///           1. the liquid advances (LiquidSide::step);
///           2. heat: liquid particles within `heaterBand` of a heater level set relax towards
///              the heater's temperature, dT/dt = (T_heater - T) / heatingTime, and heat diffuses
///              among liquid particles by the SPH form of [RYY15] Eq. 15 with `conductivity`
///              (explicit, gathered, pair-symmetric, so diffusion alone conserves sum m T up to
///              round-off when masses are equal). Heat above the boiling point T_b is not
///              kept as temperature: T is clamped to T_b and the excess is stored in the channel
///              "latent" (K) until it reaches `latentHeat` (L / c_p, K);
///           3. boiling ([RYY15] Sec. 4.2): a liquid particle whose latent store is full splits
///              by the icosahedron pattern without centre, (epsilon, alpha) = (0.3, 0.9), and
///              all 12 daughters become gas;
///           4. evaporation (Sec. 4.2): a liquid particle at the free surface (colour-field
///              gradient of liquid and solid neighbours above `surfaceThreshold`) accumulates
///              `evaporationRate` * f(T) splits per second, f(T) rising linearly from 0 at
///              `evaporationOnset` to 1 at T_b; each whole split uses the cube pattern with
///              centre, (0.4, 0.9): the centre daughter stays liquid, the 8 corners become gas.
///              The split threshold is staggered per particle by a hash of its id in [0, 1), so
///              the mean rate is exactly evaporationRate f(T) without lockstep quantisation;
///           5. merging (Sec. 4.2, Fig. 3): liquid whose split count reached
///              `merge.splitThreshold` is merged by mass decentration (Eq. 20) and re-split
///              (SplitMerge.h mergeParticles);
///           6. the liquid becomes the gas's external boundary (GasSolver::setExternalBoundary),
///              coarsened to the gas resolution (see below), and the gas advances.
///
///          Density ratio (the paper's approach, Sec. 4.1-4.2): mass is never rescaled. A gas
///          daughter keeps exactly lambda_k m_N; what changes is its volume: it "experiences
///          density drop and volume expansion" and its smoothing radius is "enlarged ...
///          matching [the] expansion in effective volume". Here a gas daughter of mass m gets
///          the support radius a gas particle of that mass has at the gas rest density,
///          h = h_gas (m / m_gas)^(1/3) (h_gas, m_gas: the gas solver's support radius and
///          reference mass), i.e. its volume is m / rho0_gas, 1000 times what the mass occupied
///          as liquid when rho0_liquid / rho0_gas = 1000. With the paper's evaporation ratios a
///          corner daughter holds 0.001 m_N, so its gas volume equals the liquid particle's
///          volume: "keeps the effective volume of the gas particles similar to that of the
///          liquid particles" (Sec. 4.2). The liquid acts on the gas as boundary particles
///          ([RYY15] Sec. 3.3): liquid particles are binned into cells of the gas spacing and
///          each occupied cell gives one boundary particle (mean position and velocity) of the
///          gas reference mass, so the liquid weighs in the gas sums like gas at rest density
///          (weighing it with its own 1000x mass would put a 1000x density spike on every gas
///          particle next to the water). The gas does not act on the liquid (one-way: at
///          1/1000 of the density its pressure forces on the liquid are negligible).
///
///          Mass is conserved exactly up to round-off: splits put the Real rounding residual
///          on the largest daughter (SplitMerge.h), gas daughters move with their mass, merges
///          keep the group's mass. Gas removed by the gas solver's kill box or life strength is
///          counted in `gasMassRemoved()`, so liquid + gas + removed is the invariant.
///
///          Use:
///          @code
///          struct MyLiquid : gas::LiquidSide { ... };   // wraps the liquid solver
///          gas::PhaseTransition coupler(gasSolver, liquid, phaseSettings);
///          coupler.addHeater(panBottomLevelSet, 393.15f);
///          for (int k = 0; k < steps; ++k) coupler.step(dt);
///          @endcode
#pragma once

#include <ghostfx/gas/GasSolver.h>
#include <ghostfx/gas/SplitMerge.h>
#include <ghostfx/gas/SplitPatterns.h>
#include <ghostfx/sph/LevelSet.h>
#include <ghostfx/sph/NeighborLists.h>
#include <ghostfx/sph/ParticleSet.h>
#include <ghostfx/sph/SolverState.h>

#include <cstdint>
#include <optional>
#include <vector>

namespace ghostfx {
namespace gas {

/// The liquid solver as the phase transition sees it. Its particle set may hold other kinds
/// (ghost air, ghost solids, boundary particles); only ParticleKind::Liquid takes part in heat
/// and phase change. The coupler adds scalar channels to the set ("temperature", "h",
/// "splits", "latent", "evaporation"), removes liquid particles (boiling, the mothers of
/// splits and merges) and appends liquid particles with their own masses (centre daughters,
/// re-split daughters), always between two liquid steps.
class LiquidSide
{
public:
    virtual ~LiquidSide() = default;
    /// The liquid solver's particle set.
    virtual sph::ParticleSet& particles() = 0;
    /// Liquid rest density rho0 (kg/m^3).
    virtual Real restDensity() const = 0;
    /// Liquid kernel support radius (m).
    virtual Real supportRadius() const = 0;
    /// Mass of a full (never split) liquid particle (kg); valid after the first step.
    virtual Real particleMass() const = 0;
    /// Advance the liquid by dt (s).
    virtual void step(Real dt) = 0;
    /// Called after the coupler changed the particle set (particles removed or added).
    virtual void particlesChanged() {}
};

/// Settings of the phase transition (plain struct; each scene key of `phase_transition` is
/// declared once in phaseSettingTable(), GasSettings.cc).
struct PhaseSettings
{
    // Temperatures (K) and heat transfer --------------------------------------------------------
    Real boilingPoint = Real(373.15);       ///< T_b: water at 1 atm
    Real initialTemperature = Real(293.15); ///< of liquid particles that had none
    /// L / c_p: the heat, in kelvin of the liquid's own heat capacity, that a particle at T_b
    /// absorbs before it boils (water: 2.26e6 / 4186 = 540 K); 0 boils at once at T_b.
    Real latentHeat = Real(540);
    Real heaterBand = Real(0.02); ///< liquid this close (m) to a heater, or inside it, is heated
    Real heatingTime = Real(0.5); ///< relaxation time (s) towards the heater temperature
    /// D_c of [RYY15] Eq. 15 among liquid particles (kg/(m s)); D_c / (2 rho0) is the thermal
    /// diffusivity. The default 0.2 gives 1e-4 m^2/s, an effective (convective) diffusivity:
    /// still water's 1.4e-7 m^2/s would not move heat a particle spacing in a minute.
    Real conductivity = Real(0.2);
    Real diffusionEpsilon = Real(0.01); ///< gamma^2 of Eq. 15 / the squared support radius

    // Evaporation -------------------------------------------------------------------------------
    /// Evaporation splits per second of a surface particle at T_b (1/s, >= 0). Each split turns
    /// (1 - lambda_centre) of the particle's mass into vapour (0.008 with the paper's ratios).
    Real evaporationRate = Real(0.5);
    Real evaporationOnset = Real(273.15); ///< (K) no evaporation below; f(T) linear up to T_b
    /// A liquid particle is at the free surface when its colour-field gradient over liquid and
    /// solid neighbours, |sum_j V_j gradW_ij| R (dimensionless, R the liquid support radius,
    /// V_j = m_j / rho_j), exceeds this. Measured in a settled Ghost SPH pan: interior
    /// 0.03 - 0.26, top layer 0.57 - 1.26.
    Real surfaceThreshold = Real(0.4);

    // Patterns ([RYY15] Sec. 4.2) ---------------------------------------------------------------
    /// Boiling: empty = icosahedronPattern() (no centre, (0.3, 0.9), Eq. 18-optimal = equal
    /// masses). Every daughter becomes gas.
    std::optional<SplitPattern> boilingPattern;
    /// Evaporation: empty = paperCubePattern() (cube + centre at (0.4, 0.9) with the paper's
    /// ratios 0.992 / 0.001; why not the Eq. 18 optimum: libgas/README.md "Phase transition").
    /// Needs a centre daughter (it stays liquid).
    std::optional<SplitPattern> evaporationPattern;
    /// Merging of over-split liquid (Sec. 4.2, Fig. 3). Empty re-split pattern: an icosahedron
    /// without centre, alpha = 12^(-1/3) (volume kept), epsilon `liquidResplitEpsilon`.
    MergeSettings merge;
    /// Epsilon of the default liquid re-split: 0.15 puts the 12 daughters about one liquid
    /// spacing from the merged particle (support = 3 spacings, h' = 12^(1/3) h), where the
    /// group came from. The Eq. 18 optimum at that alpha (0.41) would put them 2.8 spacings
    /// out, into the neighbours' places, which an incompressible liquid answers with a
    /// pressure spike.
    Real liquidResplitEpsilon = Real(0.15);
    /// Run a merge pass every this many steps (>= 1).
    int mergeEverySteps = 10;

    /// Most liquid particles turned (boiled or evaporated) per step; 0 = no limit.
    std::size_t maxTransitionsPerStep = 0;

    /// Throws ValueError naming the field, the bad value and the range expected; also for
    /// evaporationOnset not below boilingPoint and an evaporation pattern without a centre.
    void validate() const;
};

/// The settings of scene object `phase_transition` that PhaseSettings holds.
const sph::SettingTable<PhaseSettings>& phaseSettingTable();

/// Wall-clock seconds per phase of PhaseTransition::step, accumulated since the last reset.
struct PhaseTransitionTimings
{
    double liquid = 0;     ///< LiquidSide::step
    double heat = 0;       ///< grid, heater, Eq. 15 diffusion, surface detection
    double transition = 0; ///< boiling / evaporation splits, merges, hand-over to the gas
    double boundary = 0;   ///< coarse liquid boundary for the gas
    double gas = 0;        ///< GasSolver::step
    double total = 0;
    std::uint64_t steps = 0;
};

/// Mass budget of the liquid's substance (kg), summed in double in index order.
struct MassBudget
{
    double liquid = 0; ///< liquid particles of the liquid set
    /// The vapour in the gas solver's gas particles (not ambient air, nor the air they
    /// entrained: sum m_i c_i with channel::SMOKE, GasEntrainment.h)
    double gas = 0;
    double gasRemoved = 0; ///< vapour removed by the gas solver (kill box, life strength)
    double total() const { return liquid + gas + gasRemoved; }
};

class PhaseTransition
{
public:
    /// Names of the channels added to the liquid set.
    static constexpr const char* TEMPERATURE = "temperature"; ///< T (K)
    static constexpr const char* LATENT = "latent";           ///< latent heat absorbed (K)
    static constexpr const char* EVAPORATION = "evaporation"; ///< pending evaporation splits

    /// The coupler keeps references to both solvers; they must outlive it. Adds the channels
    /// to the liquid set ("h" = the liquid support radius). Throws ValueError on bad settings.
    PhaseTransition(GasSolver& gas, LiquidSide& liquid, const PhaseSettings& settings);

    const PhaseSettings& settings() const { return mSettings; }

    /// Add a heater: liquid within heaterBand of `shape` (or inside it) relaxes towards
    /// `temperature` (K). A pan is usually both a liquid solid and a heater. Throws ValueError
    /// if heaterBand is not inside the level set's narrow band (phi is clamped beyond it).
    void addHeater(const sph::LevelSet& shape, Real temperature);

    /// Set the temperature (K) of every liquid particle (e.g. a pre-heated bath).
    void setLiquidTemperature(Real temperature);

    /// One coupled step of length dt (s): see the file comment.
    void step(Real dt);

    /// Liquid particles boiled (split into 12 gas daughters) since the start.
    std::size_t boiledCount() const { return mBoiled; }
    /// Evaporation splits (one liquid centre + 8 gas corners) since the start.
    std::size_t evaporatedCount() const { return mEvaporated; }
    /// Liquid merge groups (merge + re-split) since the start.
    std::size_t mergeCount() const { return mMerges; }
    /// Gas particles handed to the gas solver since the start.
    std::size_t vapourParticlesCreated() const { return mVapourCreated; }
    /// Mass (kg) handed from liquid to gas since the start (double sum).
    double vapourMassCreated() const { return mVapourMass; }
    /// Gas mass (kg) the gas solver removed (kill box, life strength) since the start.
    double gasMassRemoved() const { return mGasRemoved; }
    /// Boundary particles given to the gas in the last step.
    std::size_t boundaryCount() const { return mBoundaryCount; }

    MassBudget massBudget() const;

    /// The coupler's own state for a checkpoint (solver "phase_transition", no particles): its
    /// counters, mass sums and merge schedule. The liquid's channels travel with the liquid
    /// solver's state, the vapour with the gas solver's.
    sph::SolverState saveState() const;
    /// Continue from saveState()'s state, on a coupler built with the same settings, heaters
    /// and restored solvers. Throws ValueError for another solver's state or a missing key.
    void restoreState(const sph::SolverState& state);

    const PhaseTransitionTimings& timings() const { return mTimings; }
    void resetTimings() { mTimings = PhaseTransitionTimings(); }

private:
    struct Heater
    {
        sph::LevelSet shape;
        Real temperature;
        /// The level set's active box padded by two voxels: outside it phi is the background.
        sph::Aabb reach;
    };

    void ensureChannels();
    /// Heater relaxation and Eq. 15 among liquid particles over dt (s); finds the surface.
    void heat(Real dt);
    /// Build mHeatLists: every liquid particle's neighbours within the liquid support radius.
    void searchHeatNeighbours();
    /// Take the heat pass's new temperatures Tnew (K): T clamped at T_b, the excess stored as
    /// latent heat. Throws NumericalError on a non-finite temperature.
    void storeHeat(std::vector<Real>& Tnew);
    /// Boiling and evaporation of the step (dt in s, Sec. 4.2): returns the liquid particles
    /// turned.
    std::size_t transfer(Real dt);
    /// Liquid-set indices of the particles that boil this step.
    std::vector<sph::Index> selectBoiling() const;
    /// Ids of the surface particles that evaporate this step (dt in s), `boiling` of the
    /// step's transitions taken by boiling; advances their pending splits.
    std::vector<sph::ParticleId> selectEvaporation(Real dt, std::size_t boiling);
    /// Split the boiling particles (all daughters gas) and the evaporating ones (the centre
    /// stays liquid).
    void splitLiquid(const std::vector<sph::Index>& boil,
                     const std::vector<sph::ParticleId>& evaporate);
    /// Move every gas daughter from the liquid set to the gas solver.
    void handVapourToGas();
    void mergeLiquid();
    void updateBoundary();
    double gasMass() const;

    GasSolver& mGas;
    LiquidSide& mLiquid;
    PhaseSettings mSettings;
    std::vector<Heater> mHeaters;
    std::vector<std::uint8_t> mSurface; ///< per liquid-set index, from the last heat pass
    /// The heat pass's search over the liquid set: one grid and one list per liquid particle,
    /// kept between steps for their capacity.
    sph::NeighborLists mHeatLists;
    std::vector<std::uint8_t> mHeatQueries;
    SplitPattern mBoilPattern, mEvapPattern;
    MergeSettings mMerge;
    std::size_t mBoiled = 0, mEvaporated = 0, mMerges = 0, mVapourCreated = 0;
    std::size_t mBoundaryCount = 0;
    double mVapourMass = 0, mGasRemoved = 0;
    std::uint64_t mStep = 0;
    PhaseTransitionTimings mTimings;
};

} // namespace gas
} // namespace ghostfx
