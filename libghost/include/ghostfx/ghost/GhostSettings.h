/// @file   GhostSettings.h
/// @brief  Settings of the liquid solver: Ghost SPH [SB12] or the "Basic SPH" baseline (Sec. 3).
/// @details Plain struct with the paper's defaults. Each scene key's range, unit and meaning is
///          declared once, in liquidSettingTable() and dfsphSettingTable() (GhostSettings.cc):
///          the scene reader, `validate()` (a ValueError naming the field, the bad value and the
///          range) and docs/scene-format.md's tables follow them. The solver copies its
///          settings at construction.
#pragma once

#include <ghostfx/sph/PoissonSampler.h>
#include <ghostfx/sph/SettingSpec.h>
#include <ghostfx/sph/Types.h>

#include <cstdint>
#include <string>

namespace ghostfx {
namespace ghost {

using sph::Real;
using sph::Vec3;

/// Which method advances the liquid. Chosen by name in scenes ("ghost", "basic").
enum class Method {
    Ghost, ///< [SB12] Sec. 4: ghost air and ghost solid particles, XSPH on velocities
    Basic, ///< [SB12] Sec. 3: no ghosts, Lennard-Jones walls, Becker-Teschner viscosity, XSPH on positions
};

/// "ghost" or "basic".
const char* methodName(Method method);
/// Parse a method name; throws ValueError listing the valid names.
Method methodFromName(const std::string& name);

/// How the liquid's pressure is found. Chosen by name in scenes (settings.pressure).
enum class PressureModel {
    Tait, ///< [SB12] Sec. 3: weakly compressible, p = k ((rho / rho0)^7 - 1), acoustic time steps
    Dfsph ///< divergence-free SPH (Bender and Koschier 2015, 2017): an implicit solve that holds
          ///< the density within a set error, time steps bound by the flow speed
};

/// "tait" or "dfsph".
const char* pressureName(PressureModel model);
/// Parse a pressure model name; throws ValueError listing the valid names.
PressureModel pressureFromName(const std::string& name);

/// The implicit pressure solve of PressureModel::Dfsph ([BK15] Algorithms 2 and 3).
struct DfsphSettings
{
    /// The constant-density solve stops when the mean |rho* - target| / rho0 of the liquid is
    /// at most this (a fraction: 1e-3 = 0.1 %), rho* the density the step's velocities lead to
    /// and target = rho0 + (1 - densityRelaxation) (rho - rho0).
    Real densityError = Real(1e-3);
    /// The divergence solve stops when the mean |D rho / Dt| dt / rho0 of the liquid, the
    /// density change the velocity field would make in one step, is at most this ([BK17]: 0.1 %).
    Real divergenceError = Real(1e-3);
    /// Share beta of the density error rho - rho0 the density solve removes in one step
    /// (Asai et al. 2012's relaxed density invariance; the velocity divergence is removed in
    /// full). 1 is [BK15]'s solve; at 0.2 the few-percent errors of emitted particles become
    /// velocity kicks (a tap poured 29 % more at CFL 0.4 than at 0.1, its fastest particle at
    /// 4.1 m/s), and larger shares grow without bound (bench/history/diary-2026-11.md, "DFSPH").
    /// 0.1 with the mirrored walls: at 0.05 a still tank's settled density error stays at
    /// 0.5-0.7 % (a solve that stops at its limit leaves up to limit / beta;
    /// bench/history/diary-2026-11.md, "DFSPH: ghost solids as mirror images").
    /// This share is per step of the length that CFL number RELAXATION_CFL (the default, 0.4)
    /// gives; a shorter step (a smaller CFL number, a frame's last step) takes a share in
    /// proportion, dt / that step (0.0125 at CFL 0.1), so that the velocity its correction asks
    /// for, about beta (rho - rho0) h / (rho0 dt), does not grow as the steps shrink: at CFL
    /// 0.1 the whole share ran away (bench/history/diary-2026-11.md, "DFSPH at small steps"). Steps
    /// held at dfsph.max_dt by a calm scene keep the whole share at any CFL number.
    Real densityRelaxation = Real(0.1);
    static constexpr Real RELAXATION_CFL = Real(0.4);
    /// Besides its mean error, a solve must bring every particle's error within this many times
    /// its limit (3 % at the default 0.1 %): on the mean alone a few particles in 100k can be
    /// squeezed to 2.7 rho0 without one iteration (a 1 m/s landing then blew up). Measured on
    /// the 98k dam break (bench/history/diary-2026-11.md, "DFSPH: a peak limit"): 10 and 20 also
    /// hold the landing but cost 45 % and 17 % more per step; 30 costs nothing measurable.
    static constexpr double PEAK_FACTOR = 30;
    /// How a ghost solid's pressure enters the solves (DfsphPressure.cc, file comment). Scenes
    /// always use Mirror; Own is for library code that compares with SPlisHSPlasH's term.
    enum class WallPressure : std::uint8_t {
        /// The liquid particle's mirror image: its pressure term, extrapolated down the
        /// hydrostatic gradient, and its reflected velocity (Adami et al. 2012's wall pressure
        /// in the symmetric form): a still tank's pressure within 1 % of rho0 g d, and tension
        /// that holds liquid under a ceiling.
        Mirror,
        /// The liquid particle's own pressure term, once (SPlisHSPlasH's DFSPH boundary
        /// term), to compare with that solver: pressure 0.6-1.4 % too steep in a still tank,
        /// and a slab under a ceiling slides a spacing or two.
        Own
    };
    WallPressure wallPressure = WallPressure::Mirror;
    /// How much of the ghost air's mass a liquid particle's density counts. Chosen by name in
    /// scenes (settings.dfsph.air_density).
    enum class AirDensity : std::uint8_t {
        /// All of it ([SB12] Eq. 1). The default.
        Full,
        /// Only what the liquid and solids around the particle lack of rho0: the air completes
        /// a surface particle's neighbourhood and never compresses it. Air moves with the
        /// liquid and crowds where a sheet lands or runs up a wall; between resamplings it
        /// raised such particles to 1.3-1.5 rho0, and the solves threw them at up to 8.6 m/s
        /// off a 0.77 m/s landing at 2.5 h support (3.5 m/s at 3 h); with Fill 2.2-2.7 m/s
        /// (1.6-2.2 at 3 h). Not the default: with the air filling to rho0 whatever the
        /// spacing, the density solve no longer sees a surface layer pressed into the one
        /// below (only the divergence solve holds it), and under load it compacts: its
        /// liquid-only density rose from 0.82-0.84 to 0.86-0.91 rho0 in a still tank and to
        /// 0.99 in one accelerating at g / 2, whose pressure offset grew from 1.8 to 3.9 % of
        /// rho0 g D (bench/history/diary-2026-11.md, "DFSPH: ghost air that fills and never
        /// compresses", and "DFSPH: the air resampled as often as [SB12]'s steps"). The Tait step
        /// does not take it: there the air's excess balances the surface's pull, and without it a
        /// zero-gravity cube shrinks 4 % in 2 s.
        Fill
    };
    AirDensity airDensity = AirDensity::Full;
    /// How often the ghost air is resampled and faded (GhostSettings::airResampleSpan). Chosen
    /// by name in scenes (settings.dfsph.air_resampling).
    enum class AirResampling : std::uint8_t {
        /// One phase of the layer a step, as in the Tait step. The default.
        Step,
        /// As far per second as [SB12]'s steps take it: a DFSPH step spans 2 to 5 of them at
        /// the defaults and resamples that many phases. Between the longer steps' resamplings
        /// the air crowds where a sheet lands or runs up a wall: the landing block of
        /// test_tank.cc threw particles at 2.0-3.5 m/s with Step and 1.5-2.0 with Time (2.5 h
        /// support: 3.6-8.6 against 2.2-2.6). Not the default: about 7 % of a dam-break step
        /// and 10 % of the column tank's run, and the tank accelerating at g / 2 (test_dfsph.cc)
        /// has a pressure slope of -1.7 to +0.5 % over six sample realisations against -0.9 to
        /// +0.5 % (bench/history/diary-2026-11.md, "DFSPH: the air resampled as often as [SB12]'s
        /// steps").
        Time
    };
    AirResampling airResampling = AirResampling::Step;
    /// Iteration cap of each solve; a solve that reaches it is counted as unconverged
    /// (GhostSolver::pressureSolveStats) and the step goes on with the velocity it reached.
    int maxIterations = 100;
    /// CFL steps (substeps 0): dt = cfl h / |v|max, limited to [minTimeStep, maxTimeStep] (s).
    Real minTimeStep = Real(1e-5);
    Real maxTimeStep = Real(5e-3);
    /// Start each solve from the last step's pressure ([BK15] Sec. 4.3).
    bool warmStart = true;
    /// With warmStart: the divergence solve starts from its last pressure too. Off, it starts
    /// from zero. Here the divergence solve only sees what advection left, which has little to
    /// do with the last step's correction, and it almost never iterates: the column tank's
    /// pressure phase is 28 % cheaper (193 -> 33 divergence iterations over 216 -> 212 steps).
    /// The cost is a noisier still tank: interior density error 0.32 -> 0.46 %, worst layer
    /// 3.5 -> 5.1 % of rho0 g D, fastest interior particle 0.15 -> 0.19 m/s in float, 0.17 ->
    /// 0.32 in double (bench/history/diary-2026-11.md, "DFSPH: the divergence solve from zero"). A
    /// look-development trade, not the default.
    bool divergenceWarmStart = true;
    /// Keep each liquid pair's m_j grad W_ij for the step (12 bytes a pair in float, about
    /// 1 kB a liquid particle at [SB12]'s 3 h support), so the solves' passes read them instead
    /// of gathering positions and evaluating the kernel again: the dam break's pressure phase
    /// takes a third less time (bench/history/diary-2026-11.md, "DFSPH: the pairs' kernel gradients
    /// kept for the step"). Off: the same solve, recomputed each pass, for scenes memory bounds.
    bool keepGradients = true;
    /// The most memory (bytes) one process's kept gradients may take in a step: 4 GiB, about
    /// 360M pairs, 4M liquid particles at [SB12]'s 3 h support. A step whose pairs would need
    /// more recomputes them in every pass, the same solve as keepGradients false, and is
    /// counted in PressureSolveStats::recomputedSteps: a run that outgrows the limit (an
    /// emitter filling a tank) gets slower instead of running out of memory. 0: never keep.
    double keptGradientLimit = 4.0 * 1024 * 1024 * 1024;
};

/// Boundary condition at solids for Ghost SPH ([SB12] Sec. 4.4).
enum class SolidSlip {
    Free,  ///< Eq. 3: normal velocity of the solid + tangential velocity of the nearest liquid
    NoSlip ///< ghost velocity = the solid's velocity: tangential drag, "stickiness" via solidEpsilon
};

/// How the ghost air's weights (its mass over a liquid particle's) are set at a resampling
/// (GhostAir.cc, step 6). Scenes always use Complete; Matched is for library code that
/// compares with the weights nearest [SB12]'s.
enum class AirWeights {
    /// min(1, n0 / sigma_a): an air particle weighs less where the air around it is packed
    /// closer than the liquid ([SB12]'s weight 1 elsewhere), the weights nearest the paper's:
    /// the kept air's mass grows at every resampling and a zero-gravity cube spreads by 4-6 %
    /// in 2 s (bench/history/diary-2026-11.md, "Air that completes the liquid's density").
    Matched,
    /// What the liquid next to the air lacks: the weight that brings the neighbouring liquid
    /// particles' density sums to rest density (least squares over them, within [0, 1]).
    /// Keeps a zero-gravity cube together for 2 s and holds a still tank. The default.
    Complete
};

struct GhostSettings
{
    Method method = Method::Ghost;
    /// The pressure model of the Ghost method (Basic SPH is Tait only, as [SB12] defines it).
    PressureModel pressure = PressureModel::Tait;
    DfsphSettings dfsph;

    // Discretisation ---------------------------------------------------------------------------
    Real spacing = Real(0.01);    ///< particle spacing h (m)
    Real supportFactor = Real(3); ///< kernel support radius / h ([SB12] Sec. 3: 3)

    // Liquid -----------------------------------------------------------------------------------
    Real restDensity = Real(1000);   ///< rho0 (kg/m^3)
    Real stiffness = Real(2000);     ///< Tait k (Pa): p = k ((rho / rho0)^7 - 1) ([SB12]: 2000)
    Vec3 gravity{0, Real(-9.81), 0}; ///< (m/s^2)

    /// Kinematic viscosity nu (m^2/s) of the liquid: water 1e-6, honey about 1e-2 to 10; 0 =
    /// none (the default: [SB12]'s liquid, whose XSPH alone smooths it). Solved implicitly
    /// ([WKBB18], ImplicitViscosity.h), stable at the flow's step whatever nu is.
    Real viscosity = Real(0);
    /// The viscosity solve stops when |r| <= viscosityError |b| (its momenta, relative).
    Real viscosityError = Real(1e-4);
    int viscosityMaxIterations = 500; ///< iteration cap of each viscosity solve
    /// Surface tension coefficient sigma (N/m): water 0.072; 0 = none (the default). A
    /// continuum surface force over the liquid and its ghost air (SurfaceTension.h).
    Real surfaceTension = Real(0);

    // Ghost SPH ([SB12] Sec. 4) ------------------------------------------------------------------
    Real xsphEpsilon = Real(0.05); ///< epsilon of Eq. 2 (XSPH on velocities)
    /// Epsilon of Eq. 2 for ghost-solid neighbours: the wall drag of one reference step
    /// (solidDragReferenceStep()); a step of dt applies solidEpsilon dt / dt_ref, so the drag is
    /// a rate that does not grow with the number of steps (a stiffer k or a smaller CFL).
    Real solidEpsilon = Real(0.05);
    /// Particle shifting (Skillen et al. 2013's form): after each step a liquid particle moves
    /// by -A h |v| dt grad C, C the summed particle concentration with the ghosts, towards an
    /// even spacing (at most 0.1 h a step). It keeps the density noise of a stiff k from
    /// growing; ghost air gives surface particles a full neighbourhood, so no surface special
    /// case is needed. 0 = off; negative = automatic (shifting()).
    Real shiftingCoefficient = Real(-1);
    SolidSlip solidSlip = SolidSlip::Free;
    /// Passes that move the sampled liquid towards rest density before the first step (Ghost
    /// SPH; GhostSolver::relaxInitialLiquid). The Poisson samples are not at rest density:
    /// where a liquid face meets a solid, both samplings put a layer on the same plane
    /// (density error up to 13 % at 10 mm, 3 % mean). 0 = off; negative = automatic
    /// (relaxationPasses()).
    int initialRelaxation = -1;
    int airResampleSteps = 10; ///< resample the ghost air every N steps ([SB12]: about 10)
    /// At a resampling, air particles closer than this fraction of the Poisson radius r to the
    /// liquid are replaced; the others stay (temporal coherence). 0 keeps all in the layer;
    /// a value above the largest liquid-air distance replaces all, as in [SB12].
    Real airKeepFraction = Real(0.8);
    AirWeights airWeights = AirWeights::Complete; ///< how the air's weights are set

    // Basic SPH ([SB12] Sec. 3) -------------------------------------------------------------------
    Real basicXsphEpsilon = Real(0.5);       ///< XSPH on positions [Monaghan 1989]
    Real basicViscosityAlpha = Real(0.0005); ///< Becker and Teschner 2007 alpha
    /// Lennard-Jones strength D (m^2/s^2) of Monaghan 1994; 0 picks 5 |g| H at initialisation,
    /// H the height of the liquid (Monaghan's choice), or (0.1 c)^2 without gravity.
    Real lennardJonesStrength = Real(0);

    // Time stepping -------------------------------------------------------------------------------
    Real frameRate = Real(30);  ///< frames per second
    int substeps = 20;          ///< fixed steps per frame ([SB12]: 20); 0 = CFL-adaptive
    Real cflNumber = Real(0.4); ///< dt <= cfl h / (c + |v|max) and forces limit, when adaptive
    /// Blow-up bound: a particle faster than this (m/s) stops the run with a NumericalError.
    /// 0 picks 20 x the speed of sound.
    Real maxSpeed = Real(0);

    /// Domain: liquid and air leaving this box are removed (a kill box). Empty: no limit.
    sph::Aabb killBox;

    std::uint64_t seed = 0; ///< random seed of all sampling
    /// Sample the interior of liquid bodies and solids deeper than 2r from a relaxed periodic
    /// tile (PoissonSettings::tiledInterior): about twice as fast a set-up, with an interior
    /// packing up to about 1 % off the layer near the surface. Off: [SB12]'s pipeline throughout.
    bool tiledSampling = false;
    /// Volume relaxation of sampled liquid bodies, emitters and solids
    /// (PoissonSettings::volumeRelaxation): SPH packing (the default), about a
    /// third of the sampling time of [SB12]'s Algorithm 2 with half its interior density noise,
    /// or Algorithm 2 itself (Relaxation::Sb12, the paper's pipeline;
    /// bench/history/diary-2026-11.md, "Sampler: SPH packing" and "Tests that hold over sample
    /// realisations").
    sph::PoissonSettings::Relaxation samplingRelaxation = sph::PoissonSettings::Relaxation::Packing;

    /// Kernel support radius (m).
    Real supportRadius() const { return supportFactor * spacing; }
    /// Speed of sound of the Tait equation at rest, sqrt(7 k / rho0) (m/s).
    Real soundSpeed() const;
    /// The blow-up speed bound actually used (m/s).
    Real speedLimit() const;
    /// The shifting coefficient in use: shiftingCoefficient, or when automatic 2 above
    /// k = 2e4 Pa and 0 below (where the collapse of issue 18 does not need it, and it costs
    /// 24 % of a step: bench/RESULTS.md, "Stiff liquid").
    Real shifting() const;
    /// XSPH weight among liquid particles per step. Fixed steps: xsphEpsilon, as [SB12]
    /// defines it. CFL steps: xsphEpsilon at CFL 0.4 and in proportion to the CFL number
    /// (the steps' length), so a smaller CFL number does not add damping.
    Real xsphEpsilonPerStep() const;
    /// The relaxation passes in use: initialRelaxation, or when automatic 20 with DFSPH, above
    /// k = 2e4 Pa (where a 13 % density error is a 2 x k pressure kick) and in a scene with
    /// dynamic solids (`bodies`: the sampled liquid's error beside a light body kicks it, and a
    /// 500 kg/m^3 box on a Tait column started at 0.28 m/s unrelaxed, 0.14 relaxed), else 0.
    int relaxationPasses(bool bodies = false) const;
    /// How many of [SB12]'s steps a step of dt spans for the air's resampling and fading,
    /// with the fastest liquid at vmax: 1 with the Tait step ([SB12]: the layer resampled
    /// every airResampleSteps steps) and with DfsphSettings::AirResampling::Step. With Time,
    /// dt / solidDragReferenceStep(vmax), at most airResampleSteps: a DFSPH step is 2 to 5 of
    /// [SB12]'s at the defaults, and resamples and fades the air as far as [SB12] would in
    /// the same time, so the liquid moves as far between two resamplings of a region.
    Real airResampleSpan(Real dt, Real vmax) const;
    /// The step at which solidEpsilon is the per-step wall drag: the acoustic step of [SB12]'s
    /// k = 2000 Pa at CFL 0.4 (the defaults), 0.4 h / (c(2000 Pa) + vmax) (s).
    Real solidDragReferenceStep(Real vmax) const;
    /// XSPH weight towards ghost solids for a step of dt: solidEpsilon at the reference step,
    /// proportional to dt, at most 1.
    Real solidEpsilonForStep(Real dt, Real vmax) const;

    /// Throws ValueError for a field outside its declared range, and for the pairs of fields
    /// that do not go together (DFSPH with method basic; dfsph.maxTimeStep < minTimeStep).
    void validate() const;
};

/// The settings of scene object `settings` that GhostSettings holds, one row each.
const sph::SettingTable<GhostSettings>& liquidSettingTable();
/// The settings of scene object `settings.dfsph`.
const sph::SettingTable<DfsphSettings>& dfsphSettingTable();

/// Throws ValueError "<what>: viscosity = <nu>: expected <settings.viscosity's range>" for a
/// liquid's own kinematic viscosity `nu` (m^2/s) outside settings.viscosity's range.
void checkOwnViscosity(Real nu, const std::string& what);

} // namespace ghost
} // namespace ghostfx
