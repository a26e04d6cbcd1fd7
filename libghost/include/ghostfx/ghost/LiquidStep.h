/// @file   LiquidStep.h
/// @brief  One liquid step as a pressure model sees it (PressureSolver.h): the state the step
///         works on and the parts of [SB12] Algorithm 3 the model calls in order.
/// @details The solver makes one for each step and hands it to its PressureSolver. The
///          particles are the liquid and ghost air (ParticleSet); the solid particles live in
///          two blocks, static and moving solids, each with the step's lists from every liquid
///          particle into it. Over several processes (GhostSolver::setExchange) the particle
///          set also holds halo copies of the neighbours' particles (haloFlags() nonzero): a
///          model computes only for the particles it owns and refreshes the copies through
///          exchange() before a pass reads a neighbour's new value.
#pragma once

#include <ghostfx/ghost/GhostSettings.h>
#include <ghostfx/sph/Kernels.h>
#include <ghostfx/sph/NeighborLists.h>
#include <ghostfx/sph/ParticleExchange.h>
#include <ghostfx/sph/ParticleSet.h>

#include <cstdint>
#include <functional>
#include <vector>

namespace ghostfx {
namespace ghost {

class GhostSolver;
struct PhaseTimings;
namespace detail {
struct DfsphFactors;
}

/// What the density pass (LiquidStep::searchAndDensity) does beside Eq. 1's density.
struct DensityPass
{
    /// Sum over the solid particles too (Ghost SPH's ghost solids); false: over liquid (and
    /// air) only, as Basic SPH, whose boundary particles push by their own force.
    bool solids = true;
    /// The share of [SB12]'s air resampling period this step spans (GhostSettings::
    /// airResampleSpan): 1 for a step of the Tait step's length.
    Real airSpan = 1;
    /// Called after the search and the air resampling, before the density: a model's
    /// preparation of per-step arrays that the pass fills (DFSPH's factors).
    std::function<void()> beforeDensity;
    /// DFSPH's factors, found in the density's pass over the pairs (libghost's own model).
    detail::DfsphFactors* factors = nullptr;
};

class LiquidStep
{
public:
    /// The two solid blocks.
    enum Block : int { STATIC = 0, MOVING = 1 };
    /// The vector channel of particles() holding v* = v + dt a (Algorithm 3 line 14), which
    /// a model fills for the liquid it owns (a halo copy's comes from its owner).
    static constexpr const char* VELOCITY_STAR = "vstar";

    // The step's state ----------------------------------------------------------------------
    /// Liquid and ghost air (and halo copies), sorted by the step's search.
    sph::ParticleSet& particles();
    /// Liquid particle -> its neighbours in particles(), the particle itself included.
    const sph::NeighborLists& lists() const;
    /// The solid particles of a block: density, pressure and velocity are those of their
    /// nearest liquid where liquid reaches them this step (Algorithm 3 lines 5-7, 15-18).
    const sph::ParticleSet& solids(Block block) const;
    /// Liquid particle -> its neighbours in solids(block).
    const sph::NeighborLists& solidLists(Block block) const;
    const sph::CubicSplineKernel& kernel() const;
    const GhostSettings& settings() const;
    Real particleMass() const;
    /// Basic SPH's Lennard-Jones strength D (m^2/s^2).
    Real lennardJones() const;
    /// Per particle of particles(): nonzero for a halo copy; null on one process.
    const Real* haloFlags() const;
    /// The other processes of the simulation, or null.
    sph::ParticleExchange* exchange() const;
    PhaseTimings& timings();
    double time() const;
    int frame() const;
    std::uint64_t stepIndex() const;
    /// Whether this step sets the pressure channel for output (the last step of a frame,
    /// GhostSolver::step's reportPressure); a model may skip a pass that only reports.
    bool reportsPressure() const;

    // The parts, in Algorithm 3's order ------------------------------------------------------
    /// Lines 1-7: air fading and resampling (Ghost SPH), the halo exchange, the neighbour
    /// search and Eq. 1's density of every liquid particle, each reached solid particle taking
    /// its nearest liquid particle's.
    void searchAndDensity(const DensityPass& pass = DensityPass());
    /// Lines 5-7 for the pressure: each solid particle liquid reaches takes its nearest liquid
    /// particle's pressure.
    void pressureToSolids();
    /// The liquid's largest acceleration this step (m/s^2): the next step's force limit.
    void setMaxAcceleration(Real a);
    Real maxAcceleration() const;
    /// The surface tension's acceleration (GhostSettings::surfaceTension) added to v* times
    /// dt. Nothing without surface tension.
    void applySurfaceTension(Real dt);
    /// The liquid's viscosity (GhostSettings::viscosity), implicitly: v* becomes the
    /// velocities one backward Euler step of the viscous force gives from it. Nothing without
    /// viscosity. A model calls it once its other non-pressure forces are in v*.
    void applyViscosity(Real dt);
    /// Lines 15-28 from v* (VSTAR): ghost solid velocities (Eq. 3), XSPH (Eq. 2), air
    /// velocities, positions, and, with `gradMass` (sum_j m_j grad W_ij of each particle),
    /// particle shifting (GhostSettings::shiftingCoefficient).
    void finish(Real dt, const std::vector<sph::Vec3>& gradMass = {});
    /// Each moving solid particle's velocity change from time t0 to t1 (s), in its block's
    /// order: the solid's acceleration there times t1 - t0.
    void movingSolidVelocityChanges(double t0, double t1, std::vector<sph::Vec3>& change) const;

private:
    friend class GhostSolver;
    explicit LiquidStep(GhostSolver& solver) : mSolver(solver) {}
    GhostSolver& mSolver;
};

} // namespace ghost
} // namespace ghostfx
