/// @file   SamplePacking.cc
/// @brief  SPH packing under the Poisson-disk bound: the sampler's alternative volume
///         relaxation (PoissonSettings::Relaxation::Packing).
/// @details [SB12] Sec. 4.5.3 relaxes the samples "to reduce noise in the SPH density by
///          optimizing sample locations"; its Algorithm 2 does so indirectly, moving each
///          sample in turn to the best of 50 random nearby points by the distance to its
///          nearest neighbour. Packing pursues the stated goal itself: the gradient of a
///          sample's SPH number density, sum_j grad W(x_i - x_j), vanishes where the samples
///          around it are evenly spread, and points away from where they crowd, so every sample
///          steps down it,
///
///              x_i <- x_i - a R^2 h^3 sum_j grad W(x_i - x_j),
///
///          with the cubic spline of support R = 2h (the first shell of neighbours, about 25),
///          all samples at once (Jacobi: each step reads the positions of the one before, so the
///          result does not depend on the thread count), the step cut to r / 5. This is the
///          particle shifting of incompressible SPH (Xu et al. 2009, Lind et al. 2012) and the
///          idea of SPH-based blue-noise sampling (Jiang et al. 2015), kept here under [SB12]'s
///          constraints:
///            - no move brings two samples closer than r (or closer than they were, where they
///              already are): a move is kept only if it stays that far from every other
///              sample's old and new position, which bounds every pair whichever of the two
///              moves;
///            - surface samples move along the surface (the normal part of the step removed,
///              then projected back onto phi = 0); interior samples stay inside the shape and,
///              for solids, within the band.
///          The surface is not compensated for its missing neighbours: the surface samples
///          (about 0.87 per h^2) stand in for them, and the profile of density against depth
///          then matches Algorithm 2's (bench/history/diary-2026-11.md, "Sampler: SPH packing as
///          the volume relaxation").
#include "ghostfx/sph/Kernels.h"
#include "ghostfx/sph/NeighborGrid.h"
#include "ghostfx/sph/NeighborLists.h"
#include "ghostfx/sph/Parallel.h"
#include "ghostfx/sph/PoissonSampler.h"

#include "SamplerGrids.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

namespace ghostfx {
namespace sph {

namespace {

/// Support of the packing kernel in particle spacings h: the first shell of neighbours, which
/// is what evens the spacing, at a third of the pairs of the solver's 3h.
constexpr Real SUPPORT_SPACINGS = Real(2);
/// Step gain a of x -= a R^2 h^3 sum_j grad W (unitless). With it the bench sphere's interior
/// density spread falls from 6.3 % to 1.8 % in 5 steps and 1.6 % in 8
/// (bench/history/diary-2026-11.md).
constexpr Real STEP_GAIN = Real(0.25);
/// Largest move per step, in Poisson radii (a surface sample's projection may add as much
/// again): a sample that may come within r of another's new position is within r + 4 r / 5
/// < R of it at the step's start, so it is on the list the guard reads.
constexpr Real MAX_MOVE_RADII = Real(0.2);
/// Lipschitz bound of the interpolated distance (as in Algorithm 2): phi(x + d) <= phi(x) +
/// LIPSCHITZ |d|, so a sample deeper than that cannot leave the shape and is not looked up.
constexpr Real LIPSCHITZ = Real(2);

/// What a sample carries between steps: its level-set value (interior samples) or outward
/// normal (surface samples), valid until it moves, and the surface sample that last showed it
/// within the band.
struct SampleCache
{
    Real phi = 0;
    Vec3 normal{0};
    Vec3 bandHint{std::numeric_limits<Real>::max()};
    bool valid = false;
};

/// The packing steps over one sample set. It works on a copy in the grid's cell order, so
/// that neighbours are near in memory; moves of r / 5 per step keep it nearly sorted. The
/// samples go back to their places in writeBack().
class Packing
{
public:
    /// Pack the samples with movable[i] (all when empty); the rest hold still.
    Packing(const SampleSet& samples, const LevelSet& shape, const PoissonSettings& settings,
            const std::vector<std::uint8_t>& movable)
        : mShape(shape)
        , mR(settings.radius)
        , mH(mR / PoissonSettings::SB12_RADIUS_FACTOR)
        , mKernel(SUPPORT_SPACINGS * mH)
        , mSupport(mKernel.supportRadius())
        , mGain(STEP_GAIN * mSupport * mSupport * mH * mH * mH)
        , mMaxMove(MAX_MOVE_RADII * mR)
        , mBand(samples, shape, settings.bandDepth, mR)
        , mGrid(mSupport)
    {
        const std::size_t n = samples.size();
        mGrid.build(samples.positions);
        mOrder = mGrid.order();
        if (mOrder.empty()) {
            mOrder.resize(n);
            for (std::size_t k = 0; k < n; ++k) mOrder[k] = Index(k);
        }
        mX.resize(n);
        mNext.resize(n);
        mSurface.resize(n);
        mMoves.resize(n);
        mKeep.resize(n);
        for (std::size_t k = 0; k < n; ++k) {
            mX[k] = samples.positions[mOrder[k]];
            mSurface[k] = samples.onSurface[mOrder[k]];
            mMoves[k] = movable.empty() || movable[mOrder[k]];
        }
        mCache.resize(n);
        mLimit2.resize(n);
    }

    /// One Jacobi step: every movable sample proposes a move, then keeps it if allowed.
    void step()
    {
        const std::size_t n = mX.size();
        mGrid.build(mX);
        mLists.build(mGrid, mX.data(), n, mSupport, mMoves.data());
        parallel::forEach(
            0, n, [&](std::size_t k) { mNext[k] = mMoves[k] ? propose(k) : mX[k]; }, 256);
        parallel::forEach(
            0, n, [&](std::size_t k) { mKeep[k] = mNext[k] != mX[k] && allowed(k); }, 256);
        for (std::size_t k = 0; k < n; ++k) {
            if (!mKeep[k]) continue;
            mX[k] = mNext[k];
            mCache[k].valid = false;
        }
    }

    /// The packed positions back into the set, in its order.
    void writeBack(SampleSet& samples) const
    {
        for (std::size_t k = 0; k < mX.size(); ++k) samples.positions[mOrder[k]] = mX[k];
    }

private:
    /// Where sample k would go: down the density gradient, within its constraints; x[k] itself
    /// when it stays. Also sets mLimit2[k], the squared distance it must keep from the others.
    Vec3 propose(std::size_t k)
    {
        const Vec3 xk = mX[k];
        Vec3 step = densityStep(k);
        if (mSurface[k]) {
            const Vec3& normal = surfaceNormal(k);
            step -= normal * step.dot(normal);
        }
        const Real length = step.length();
        if (!(length > Real(0))) return xk;
        if (length > mMaxMove) step *= mMaxMove / length;
        const Vec3 to = xk + step;
        return mSurface[k] ? ontoSurface(xk, to) : insideShape(k, xk, to);
    }

    /// -a R^2 h^3 sum_j grad W(x_k - x_j) over k's list; sets mLimit2[k] to the lesser of r^2
    /// and the squared distance to its nearest neighbour.
    Vec3 densityStep(std::size_t k)
    {
        const Vec3 xk = mX[k];
        Vec3 gradient(0);
        Real nearest2 = std::numeric_limits<Real>::max();
        mLists[k].forEach([&](Index j) {
            if (j == Index(k)) return;
            const Vec3 xkj = xk - mX[j];
            const Real r2 = xkj.lengthSqr();
            gradient += mKernel.gradW(xkj, std::sqrt(r2));
            nearest2 = std::min(nearest2, r2);
        });
        mLimit2[k] = std::min(mR * mR, nearest2);
        return gradient * (-mGain);
    }

    /// The outward unit normal at surface sample k (cached until it moves).
    const Vec3& surfaceNormal(std::size_t k)
    {
        SampleCache& c = mCache[k];
        if (!c.valid) {
            Vec3 g;
            mShape.phiAndGradient(mX[k], g);
            const Real len = g.length();
            c.normal = len > Real(0) ? g / len : Vec3(0);
            c.valid = true;
        }
        return c.normal;
    }

    /// A surface sample's move from xk to `to` (along the surface), projected back onto it;
    /// xk when the projection fails or goes too far.
    Vec3 ontoSurface(const Vec3& xk, const Vec3& to) const
    {
        Vec3 g;
        const Real phi = mShape.phiAndGradient(to, g);
        const SurfaceProjection proj = mShape.projectToSurface(to, phi, g);
        if (!proj.converged || (proj.point - xk).lengthSqr() > Real(4) * mMaxMove * mMaxMove)
            return xk;
        return proj.point;
    }

    /// An interior sample k's move from xk to `to`, if `to` is inside the shape and within the
    /// band; else xk.
    Vec3 insideShape(std::size_t k, const Vec3& xk, const Vec3& to)
    {
        SampleCache& c = mCache[k];
        if (!c.valid) {
            c.phi = mShape.phi(xk);
            c.valid = true;
        }
        // phi(to) where needed, looked up once.
        Real phiTo = 0;
        bool known = false;
        auto phiOfTo = [&] {
            if (!known) {
                phiTo = mShape.phi(to);
                known = true;
            }
            return phiTo;
        };
        if (c.phi + LIPSCHITZ * mMaxMove >= Real(0) && !(phiOfTo() < Real(0))) return xk;
        if (mBand.limited() && !mBand.accepts(to, phiOfTo, c.bandHint)) return xk;
        return to;
    }

    /// Whether k may move to next[k]: no closer than sqrt(limit2[k]) to any other sample, at
    /// its old position or its new one. Any sample that could come that close is on k's list
    /// (see MAX_MOVE_RADII).
    bool allowed(std::size_t k) const
    {
        const Vec3 to = mNext[k];
        bool ok = true;
        mLists[k].forEach([&](Index j) {
            if (j != Index(k)
                && ((to - mX[j]).lengthSqr() < mLimit2[k]
                    || (to - mNext[j]).lengthSqr() < mLimit2[k]))
                ok = false;
        });
        return ok;
    }

    const LevelSet& mShape;
    const Real mR; ///< Poisson radius (m)
    const Real mH; ///< particle spacing (m)
    const CubicSplineKernel mKernel;
    const Real mSupport; ///< the kernel's support radius R (m)
    const Real mGain;    ///< a R^2 h^3 (m^5)
    const Real mMaxMove; ///< largest move per step (m)
    const detail::DepthLimit mBand;
    NeighborGrid mGrid;
    NeighborLists mLists;
    std::vector<Index> mOrder;   ///< sample index of each working slot
    std::vector<Vec3> mX, mNext; ///< positions (m) at the step's start and proposed
    std::vector<std::uint8_t> mSurface, mMoves, mKeep;
    std::vector<SampleCache> mCache;
    std::vector<Real> mLimit2; ///< per sample: the squared distance it must keep (m^2)
};

} // namespace

void PoissonDiskSampler::pack(SampleSet& samples, const LevelSet& shape, int iterations) const
{
    packSome(samples, shape, iterations, {});
}

void PoissonDiskSampler::packSome(SampleSet& samples, const LevelSet& shape, int iterations,
                                  const std::vector<std::uint8_t>& movable) const
{
    if (iterations <= 0 || samples.size() < 2) return;
    Packing packing(samples, shape, mSettings, movable);
    for (int step = 0; step < iterations; ++step) packing.step();
    packing.writeBack(samples);
}

} // namespace sph
} // namespace ghostfx
