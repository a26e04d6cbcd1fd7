/// @file   PressureSolver.h
/// @brief  The pressure part of a liquid step behind one interface, as SPlisHSPlasH's TimeStep
///         subclasses: Tait's equation of state, DFSPH's implicit solves and Basic SPH's
///         baseline are its three models, and a caller may give the solver its own.
/// @details A GhostSolver owns one PressureSolver. Every step it hands the model a LiquidStep,
///          the step's state and parts, and the model runs [SB12] Algorithm 3 through it:
///          @code
///          void step(LiquidStep& s, Real dt) override
///          {
///              s.searchAndDensity();            // lines 1-7: air, neighbours, density
///              ...                              // lines 8-14: pressure and forces -> v*
///              s.finish(dt);                    // lines 15-28: XSPH, air, positions
///          }
///          @endcode
///          What follows the model's step (collisions, the kill box, the blow-up check, the
///          clock) is the solver's. A model keeps its own state between steps; the particle
///          channels it keeps on the liquid and air (warm starts) are named by channels() and
///          travel with the particles into checkpoints.
#pragma once

#include <ghostfx/ghost/GhostSettings.h>

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

namespace ghostfx {
namespace ghost {

class LiquidStep;

/// Work of the implicit pressure solves (settings.pressure = dfsph), accumulated since the last
/// resetTimings(), with the last step's figures.
struct PressureSolveStats
{
    std::uint64_t steps = 0;                ///< steps solved
    std::uint64_t densityIterations = 0;    ///< constant-density iterations, all steps
    std::uint64_t divergenceIterations = 0; ///< divergence iterations, all steps
    std::uint64_t unconverged = 0;          ///< solves that stopped short of either limit
                                            ///< (DfsphSettings::maxIterations)
    /// Steps that recomputed their kernel gradients because keeping them would have taken
    /// more than DfsphSettings::keptGradientLimit, and the bytes the last step's would have
    /// taken (DfsphSettings::keepGradients on; 0 when off).
    std::uint64_t recomputedSteps = 0;
    double lastGradientBytes = 0;
    int lastDensityIterations = 0, lastDivergenceIterations = 0;
    double lastDensityError = 0; ///< mean |rho* / rho0 - 1| the last density solve reached
    double lastDivergenceError =
        0; ///< mean |D rho / Dt| dt / rho0 the last divergence solve reached
    /// The largest error of one particle a density (divergence) solve left, over the steps:
    /// a solve stops when its mean error is within the limit and no particle's exceeds
    /// DfsphSettings::PEAK_FACTOR times the limit.
    double largestDensityError = 0, largestDivergenceError = 0;
    double lastLargestDensityError = 0, lastLargestDivergenceError = 0; ///< the last step's
};

/// How a step's pressure force acted between a liquid particle i and a solid particle s: the
/// pair pushed i by -m_i M (share k_i + k_s) grad W_is, and the solid by the reverse (what a
/// dynamic body feels). k is a pressure term p / rho^2 (m^5 / (kg s^2)).
struct SolidPairPressure
{
    /// k_i of each particle of the step's particles; 0 where the pressure pushed nothing.
    std::vector<Real> liquid;
    /// The share of k_i in the pair (DFSPH's wall share c; 1 for the Tait step).
    Real share = 1;
    /// What k_s is: the solid particle's own p / rho^2 (its nearest liquid particle's, [SB12]
    /// Algorithm 3 lines 5-7); the mirrored hydrostatic part (g_s . (x_s - x_i)) / rho0 with g_s
    /// the moving wall's gravity; or nothing.
    enum class SolidTerm { Own, Mirror, None } solid = SolidTerm::Own;
    /// With SolidTerm::Mirror: g_s of each moving solid particle, or null for the settings'
    /// gravity everywhere.
    const std::vector<Vec3>* wallGravity = nullptr;
};

class PressureSolver
{
public:
    virtual ~PressureSolver() = default;

    /// The model's name, for messages ("tait", "dfsph", "basic", or the caller's own).
    virtual std::string name() const = 0;
    /// Scalar channels the model keeps on the liquid and air from step to step; the solver adds
    /// them (0 everywhere) when it is made, and a restored state carries them.
    virtual std::vector<std::string> channels() const { return {}; }
    /// Ghost air fills a liquid particle's density up to rho0 and no further (the density of
    /// every pass, DfsphSettings::AirDensity::Fill); false: the air's full mass counts.
    virtual bool airFillsToRestDensity() const { return false; }

    /// The equation of state, for a model that has one: each particle's pressure from the
    /// density the density pass has just summed. The pass calls it before the halo copies and
    /// the solid particles take their values, so they take the pressure too. Returns whether
    /// it set the pressure channel (false: the model finds its pressure later in its step).
    virtual bool pressureFromDensity(LiquidStep& step)
    {
        (void)step;
        return false;
    }

    /// One step of length dt (s) through the parts of `step`, which end with v* (the VSTAR
    /// channel) integrated into velocities and positions (LiquidStep::finish), and the
    /// liquid's largest acceleration set (LiquidStep::setMaxAcceleration).
    virtual void step(LiquidStep& step, Real dt) = 0;

    /// The largest stable step (s) with `fastest` the liquid's largest speed (m/s, over every
    /// process) and `maxAcceleration` the last step's largest acceleration (m/s^2). The
    /// default is the weakly compressible limit: the acoustic CFL dt <= cfl h / (c + |v|max)
    /// and the force limit dt <= cfl sqrt(h / |a|max) (Monaghan 1992), a at least |g|.
    virtual Real stableTimeStep(const GhostSettings& settings, Real fastest,
                                Real maxAcceleration) const;

    /// The implicit solves' statistics, or null for a model without solves.
    virtual const PressureSolveStats* solveStats() const { return nullptr; }
    virtual void resetStats() {}
    /// How this step's pressure force acted on the solids (SolidPairPressure), asked after the
    /// model's forces and before LiquidStep::finish moves the particles. The default is the
    /// Tait step's symmetric force, k = p / rho^2 on both sides.
    virtual void solidPairPressure(LiquidStep& step, SolidPairPressure& out) const;
    /// The added-mass estimate of a dynamic solid's force filter, in rho0 V times the share of
    /// its ghosts the liquid reaches (GhostBodies.cc): how much liquid answers a body's
    /// acceleration within one step. The default, 0, is the weakly compressible step's: its
    /// liquid answers through pressure waves that the acoustic step resolves, and filtering
    /// that answer only delays a stiff spring's force (a 500 kg/m^3 box on a Tait column rang
    /// up to 0.25 m/s with 2, and faster with more).
    virtual double addedMassShare() const { return 0; }
    /// Bytes of the per-step arrays the model keeps between steps (their capacity).
    virtual std::size_t memoryBytes() const { return 0; }
};

/// The model settings.method and settings.pressure name: Basic SPH's for Method::Basic, else
/// Tait's or DFSPH's.
std::unique_ptr<PressureSolver> makePressureSolver(const GhostSettings& settings);

} // namespace ghost
} // namespace ghostfx
