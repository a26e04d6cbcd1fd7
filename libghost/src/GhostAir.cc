/// @file   GhostAir.cc
/// @brief  The ghost air layer of [SB12] Sec. 4.3: sampled around the liquid body, kept where it
///         still belongs, faded in and out between resamplings.
/// @details A resampling (AirResampler, AirResampling.h) renews the layer in the region of some
///          phases; between resamplings each air particle's weight moves towards its target, so
///          the layer changes gradually instead of all at once.
#include "ghostfx/ghost/GhostSolver.h"

#include "AirResampling.h"
#include "GhostInternal.h"

#include <algorithm>

namespace ghostfx {
namespace ghost {

using namespace sph;
using namespace detail;

void GhostSolver::resampleAir(int phase, int count)
{
    // Needs the grid and lists of searchNeighbors() for the current positions.
    const auto start = std::chrono::steady_clock::now();
    std::vector<const MovingLevelSet*> solids;
    solids.reserve(mSolids.size());
    for (const auto& solid : mSolids) solids.push_back(solid.get());
    AirResampler(AirResamplingInputs{mSettings, mKernel, mParticles, mGrid, mFluidLists,
                                     AirSolidBlock{mStatic.block, mStatic.lists},
                                     AirSolidBlock{mMoving.block, mMoving.lists}, std::move(solids),
                                     mRun, mMass, mExchange},
                 phase, count)
        .run();
    mTimings.airResampling += secondsSince(start);
}

void GhostSolver::liquidMoved()
{
    if (!mRun.initialized || mSettings.method != Method::Ghost) return;
    dropAir();
    searchNeighbors();
    // The whole layer at full weight, as the first one (resampleAir fades in new air only
    // once the solver is initialised).
    mRun.initialized = false;
    resampleAir(-1);
    mRun.initialized = true;
}

void GhostSolver::fadeAir(Real span)
{
    auto& weight = mParticles.scalarChannel(AIR_WEIGHT);
    const auto& target = mParticles.scalarChannel(AIR_TARGET);
    // Faded in or out over one round of the phases.
    const Real rate = span / Real(mSettings.airResampleSteps);
    if (mParticles.hasScalarChannel(AIR_FADE)) {
        // The fade's progress, apart from the weight: towards 1 while the air has a weight to
        // reach, towards 0 once it is replaced.
        auto& fade = mParticles.scalarChannel(AIR_FADE);
        for (std::size_t i = 0; i < mParticles.size(); ++i) {
            if (mParticles.kinds()[i] != ParticleKind::GhostAir) continue;
            fade[i] = target[i] > Real(0) ? std::min(Real(1), fade[i] + rate)
                                          : std::max(Real(0), fade[i] - rate);
        }
    }
    std::vector<std::uint8_t> remove(mParticles.size(), 0);
    bool anyRemoved = false;
    for (std::size_t i = 0; i < mParticles.size(); ++i) {
        if (mParticles.kinds()[i] != ParticleKind::GhostAir) continue;
        weight[i] = target[i] > weight[i] ? std::min(target[i], weight[i] + rate)
                                          : std::max(target[i], weight[i] - rate);
        mParticles.masses()[i] = weight[i] * mMass;
        if (weight[i] == Real(0) && target[i] == Real(0)) remove[i] = anyRemoved = true;
    }
    if (anyRemoved) mParticles.removeIf(remove);
}

} // namespace ghost
} // namespace ghostfx
