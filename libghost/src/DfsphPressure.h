/// @file   DfsphPressure.h
/// @brief  The implicit pressure model: DFSPH's divergence and constant-density solves over
///         [SB12]'s ghosts (DfsphPressure.cc's file comment), and the factors the density pass
///         finds for it.
#pragma once

#include "ghostfx/ghost/LiquidStep.h"
#include "ghostfx/ghost/PressureSolver.h"

#include <cstddef>
#include <vector>

namespace ghostfx {
namespace ghost {
namespace detail {

/// DFSPH's per-step arrays that the density pass fills in its pass over the pairs
/// (GhostSolver::computeDensity): for each liquid particle the factor 1 / (|sum_j m_j grad
/// W_ij|^2 + sum_liquid j |m_j grad W_ij|^2) (liquid and solid neighbours; 0 for spray and
/// halo copies), its solid sum, the kept pair gradients and the walls' hydrostatic part.
struct DfsphFactors
{
    std::vector<sph::Real> alpha;
    /// Each particle's mass if liquid, else 0.
    std::vector<sph::Real> liquidMass;
    std::vector<sph::Vec3> solidGradient; ///< sum_solid M grad W_is of each liquid particle
    /// Mirrored walls: sum_solid M (k_s - k_i) grad W_is, the walls' known hydrostatic push on
    /// each liquid particle (DfsphPressure.cc's file comment).
    std::vector<sph::Vec3> wallHydrostatic;
    /// Mirrored walls, this step: g - a_s of each moving solid particle, a_s its acceleration
    /// over the step (the gravity its mirrored pressure is extrapolated with).
    std::vector<sph::Vec3> movingWallGravity;
    /// m_j grad W_ij of each liquid particle i's fluid neighbours j, in its list's order from
    /// pairStart[i] on, one array a component: the solves' passes read them instead of
    /// gathering positions and evaluating the kernel again.
    std::vector<std::size_t> pairStart;
    std::vector<sph::Real> pairGradient[3];
    /// Whether this step keeps pairGradient (DfsphSettings::keepGradients and
    /// keptGradientLimit) or the solves recompute the gradients.
    bool gradientsKept = false;
    bool mirror = true;    ///< DfsphSettings::WallPressure::Mirror
    sph::Real wall = 2;    ///< the wall's share c (wallShare)
    int minNeighbours = 0; ///< below this a liquid particle is spray (minimumNeighbours)
    /// With particle shifting: where the pass puts sum_j m_j grad W_ij of each particle.
    std::vector<sph::Vec3>* gradMass = nullptr;

    std::size_t memoryBytes() const;
};

} // namespace detail

class DfsphPressure final : public PressureSolver
{
public:
    explicit DfsphPressure(const GhostSettings& settings);

    std::string name() const override { return "dfsph"; }
    std::vector<std::string> channels() const override;
    bool airFillsToRestDensity() const override;
    void step(LiquidStep& step, Real dt) override;
    /// dt <= cfl h / |v|max ([BK15] Sec. 4.4), gravity's force limit, and [minTimeStep,
    /// maxTimeStep]: the implicit pressure has no sound speed to resolve.
    Real stableTimeStep(const GhostSettings& settings, Real fastest,
                        Real maxAcceleration) const override;
    const PressureSolveStats* solveStats() const override { return &mStats; }
    void resetStats() override { mStats = PressureSolveStats(); }
    std::size_t memoryBytes() const override;
    /// The solves' pressure terms k_density + k_divergence of the solved particles, with the
    /// wall's share and the mirrored ghosts' hydrostatic part (DfsphPressure.cc).
    void solidPairPressure(LiquidStep& step, SolidPairPressure& out) const override;
    /// The incompressible liquid answers a body's acceleration within the step. Measured: a
    /// box of 100 kg/m^3 under water answers with m_a = 3.75 rho0 V in its first steps (the
    /// mirrored ghosts' wall share doubles it); the filter is stable while m_a < 2 m + 4 m~,
    /// and at a share of 1 it rang up to 6.8 m/s before settling, at 2 it rises at most at
    /// 0.85 m/s.
    double addedMassShare() const override { return 2; }

private:
    /// The share of [SB12]'s air resampling period the step spans (DfsphSettings::
    /// airResampling).
    Real airSpan(LiquidStep& step, Real dt) const;
    /// Size the factor arrays for this step's particles and lists.
    void prepareFactors(LiquidStep& step);
    void computeMovingWallGravity(LiquidStep& step, Real dt);
    void applyWallHydrostatics(LiquidStep& step, Real dt);
    /// One solve on v* (DfsphSolve); returns its iterations.
    int solve(LiquidStep& step, Real dt, bool density, std::vector<Real>& total, double& error,
              double& largest);
    void reportPressure(LiquidStep& step);
    /// After the density pass: the divergence solve, gravity and the density solve on v*,
    /// the pressure reported when the step asks for it, and the statistics.
    void solveStep(LiquidStep& step, Real dt);
    void recordSolves(int densityIterations, int divergenceIterations, double densityError,
                      double divergenceError, double densityPeak, double divergencePeak);

    DfsphSettings mOptions;
    detail::DfsphFactors mFactors;
    PressureSolveStats mStats;
    std::vector<Real> mScratch;
};

} // namespace ghost
} // namespace ghostfx
