/// @file   LiquidStep.cc
/// @brief  The step's state and parts as a pressure model sees them: views of GhostSolver's
///         members and calls of its step functions (GhostStep.cc).
#include "ghostfx/ghost/LiquidStep.h"

#include "GhostInternal.h"
#include "ImplicitViscosity.h"
#include "SurfaceTension.h"

namespace ghostfx {
namespace ghost {

using namespace sph;
using namespace detail;

ParticleSet& LiquidStep::particles() { return mSolver.mParticles; }
const NeighborLists& LiquidStep::lists() const { return mSolver.mFluidLists; }

const ParticleSet& LiquidStep::solids(Block block) const
{
    return (block == STATIC ? mSolver.mStatic : mSolver.mMoving).block.particles();
}

const NeighborLists& LiquidStep::solidLists(Block block) const
{
    return (block == STATIC ? mSolver.mStatic : mSolver.mMoving).lists;
}

const CubicSplineKernel& LiquidStep::kernel() const { return mSolver.mKernel; }
const GhostSettings& LiquidStep::settings() const { return mSolver.mSettings; }
Real LiquidStep::particleMass() const { return mSolver.mMass; }
Real LiquidStep::lennardJones() const { return mSolver.mLennardJones; }
const Real* LiquidStep::haloFlags() const { return mSolver.haloFlags(); }
ParticleExchange* LiquidStep::exchange() const { return mSolver.mExchange; }
PhaseTimings& LiquidStep::timings() { return mSolver.mTimings; }
double LiquidStep::time() const { return mSolver.mRun.time; }
int LiquidStep::frame() const { return mSolver.mRun.frame; }
std::uint64_t LiquidStep::stepIndex() const { return mSolver.mRun.step; }
bool LiquidStep::reportsPressure() const { return mSolver.mReportPressure; }

void LiquidStep::searchAndDensity(const DensityPass& pass)
{
    mSolver.searchAndDensity(pass);
}

void LiquidStep::pressureToSolids() { mSolver.pressureToSolids(); }
void LiquidStep::setMaxAcceleration(Real a) { mSolver.mRun.maxAcceleration = a; }
Real LiquidStep::maxAcceleration() const { return mSolver.mRun.maxAcceleration; }

void LiquidStep::applySurfaceTension(Real dt)
{
    if (mSolver.mSurfaceTension) mSolver.mSurfaceTension->apply(*this, dt);
}

void LiquidStep::applyViscosity(Real dt)
{
    if (mSolver.mViscosity) mSolver.mViscosity->apply(*this, dt);
}

void LiquidStep::finish(Real dt, const std::vector<Vec3>& gradMass)
{
    mSolver.finishGhostStep(dt, gradMass);
}

void LiquidStep::movingSolidVelocityChanges(double t0, double t1, std::vector<Vec3>& change) const
{
    // From the motions' rates where they give them, else MovingLevelSet::velocity's difference.
    const ParticleSet& set = mSolver.mMoving.block.particles();
    const auto& solids = mSolver.mSolids;
    const std::vector<RigidTransform> now = sph::placementsAt(solids, t0);
    const std::vector<RigidTransform> next = sph::placementsAt(solids, t1);
    const auto& local = set.vectorChannel(SOLID_LOCAL);
    const auto& index = set.scalarChannel(SOLID_INDEX);
    resizeStepArray(change, set.size());
    parallel::forEach(
        0, set.size(),
        [&](std::size_t s) {
        const std::size_t b = std::size_t(index[s]);
        const Vec3& q = local[s];
        change[s] = now[b].hasRates && next[b].hasRates
                        ? next[b].translationRate - now[b].translationRate
                              + (next[b].rotationRate - now[b].rotationRate) * q
                        : solids[b]->velocity(q, t1) - solids[b]->velocity(q, t0);
        },
        1024);
}

} // namespace ghost
} // namespace ghostfx
