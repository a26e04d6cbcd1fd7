/// @file   DensityPass.cc
/// @brief  [SB12] Algorithm 3 lines 2-10: Eq. 1's density of every liquid particle over the
///         step's lists, the nearest liquid particle of every solid particle liquid reaches
///         (lines 5-7), the pressure model's equation of state, and, for DFSPH, the factors of
///         its solves found in the same pass over the pairs (DfsphPressure.cc, step 1).
/// @details The nearest liquid particle of a solid particle is the minimum of a packed
///          (distance, index) key (GhostInternal.h, nearestKey) lowered by every pair: the
///          answer does not depend on the threads' order, and the solid particles no liquid
///          reaches are never visited. Ghost SPH sums over every kind of neighbour, Basic SPH
///          over liquid only (it has no air, and its boundary particles act through
///          Lennard-Jones forces instead).
#include "ghostfx/ghost/GhostSolver.h"

#include "DfsphPressure.h"
#include "GhostInternal.h"

#include <ghostfx/sph/PairBatch.h>
#include <ghostfx/sph/Parallel.h>

#include <algorithm>
#include <mutex>

namespace ghostfx {
namespace ghost {

using namespace sph;
using namespace detail;

namespace {

/// *target = min(*target, key); true for the one caller that replaced NO_LIQUID.
inline bool atomicMin(std::uint64_t* target, std::uint64_t key)
{
    std::uint64_t old = __atomic_load_n(target, __ATOMIC_RELAXED);
    while (key < old) {
        if (__atomic_compare_exchange_n(target, &old, key, true, __ATOMIC_RELAXED,
                                        __ATOMIC_RELAXED)) {
            return old == NO_LIQUID;
        }
    }
    return false;
}

/// One liquid particle's sums over its neighbours.
struct ParticleSums
{
    Real density = 0, air = 0; ///< Eq. 1's sum, and the air's part of it
    std::size_t neighbours = 0;
    // The factor's sums: sum_liquid j m_j grad W_ij, over every neighbour (particle shifting),
    // sum_liquid j |m_j grad W_ij|^2 and the liquid neighbours.
    Vec3 liquid = Vec3(0), all = Vec3(0);
    Real squares = 0;
    int liquidNeighbours = 0;
    // The factor's solid sum_s M grad W_is and, for mirrored walls, the ghosts' known
    // hydrostatic part (DfsphPressure.cc's file comment).
    Vec3 solid = Vec3(0), hydrostatic = Vec3(0);
};

} // namespace

/// The pass over the pairs of computeDensity, instantiated once with and once without DFSPH's
/// factors (as DFSPH's solve passes are).
class DensitySummation
{
public:
    DensitySummation(GhostSolver& solver, const DensityPass& pass)
        : s(solver)
        , x(solver.mParticles.positions())
        , m(solver.mParticles.masses())
        , kind(solver.mParticles.kinds())
        , rho(solver.mParticles.densities())
        , rho0(solver.mSettings.restDensity)
        , ghost(pass.solids)
        , fill(ghost && solver.mPressure->airFillsToRestDensity())
        , f(pass.factors)
        , keep(f && f->gradientsKept)
        , halo(solver.haloFlags())
        , blocks{&solver.mStatic, &solver.mMoving}
        , neighbours(solver.mParticles.size(), 0)
    {}

    /// Sum every particle's density (and with FACTORS, its factors).
    template <bool FACTORS>
    void run();
    /// Mean neighbours of the liquid this process owns and the pairs, for the solver's counters.
    void count(double& meanNeighbors, std::size_t& pairCount) const;

private:
    using Block = GhostSolver::SolidBlock;
    using Touched = std::vector<Index>[2];

    template <bool FACTORS>
    void particle(std::size_t i, const CubicSplineKernel& kernel, PairBatch& batch,
                  Touched& firstTouch);
    void offerNearest(std::size_t i, Touched& firstTouch);
    void keepHaloGradients(std::size_t i, const CubicSplineKernel& kernel, PairBatch& batch);
    template <bool FACTORS>
    void fluidSums(std::size_t i, const CubicSplineKernel& kernel, PairBatch& batch,
                   ParticleSums& sums);
    template <bool FACTORS>
    void solidSums(std::size_t i, int k, const CubicSplineKernel& kernel, PairBatch& batch,
                   ParticleSums& sums, Touched& firstTouch);
    template <bool FACTORS>
    void store(std::size_t i, ParticleSums& sums, std::size_t fluid);
    /// Where particle i's m_j grad W_ij go (DfsphSettings::keepGradients).
    void gradientsOf(std::size_t i, Real* g[3]) const
    {
        for (int c = 0; c < 3; ++c) g[c] = f->pairGradient[c].data() + f->pairStart[i];
    }
    /// Keep the batch's m_j grad W_ij (b.f the gradient factors times the masses) at g.
    static void keepGradients(const PairBatch& b, Real* g[3])
    {
        for (int k = 0; k < b.n; ++k) {
            g[0][k] = b.f[k] * b.dx[k];
            g[1][k] = b.f[k] * b.dy[k];
            g[2][k] = b.f[k] * b.dz[k];
        }
        for (int c = 0; c < 3; ++c) g[c] += b.n;
    }

    GhostSolver& s;
    const std::vector<Vec3>& x;
    const std::vector<Real>& m;
    const std::vector<ParticleKind>& kind;
    std::vector<Real>& rho;
    const Real rho0;
    const bool ghost, fill;
    DfsphFactors* const f;
    const bool keep;
    const Real* halo;
    Block* blocks[2];
    std::vector<std::uint32_t> neighbours;
    std::mutex touchedMutex;
};

template <bool FACTORS>
void DensitySummation::run()
{
    forRangeWithBatch(
        x.size(), s.mKernel,
        [&](std::size_t lo, std::size_t hi, const CubicSplineKernel& kernel, PairBatch& batch) {
        Touched firstTouch;
        for (std::size_t i = lo; i < hi; ++i) particle<FACTORS>(i, kernel, batch, firstTouch);
        if (firstTouch[0].empty() && firstTouch[1].empty()) return;
        std::lock_guard<std::mutex> lock(touchedMutex);
        for (int k = 0; k < 2; ++k) {
            blocks[k]->touched.insert(blocks[k]->touched.end(), firstTouch[k].begin(),
                                      firstTouch[k].end());
        }
        },
        512);
}

template <bool FACTORS>
void DensitySummation::particle(std::size_t i, const CubicSplineKernel& kernel, PairBatch& batch,
                                Touched& firstTouch)
{
    if (kind[i] != ParticleKind::Liquid) {
        rho[i] = rho0;
        return;
    }
    if (halo && halo[i] != Real(0)) {
        // A halo copy: its density comes from its owner (refresh, computeDensity); it only
        // offers itself as the nearest liquid particle of the solid particles it sees. With
        // DFSPH it is solved by its owner (alpha 0 here), but the gradient pass gives it G k
        // from its kept pairs.
        offerNearest(i, firstTouch);
        if (FACTORS && keep) keepHaloGradients(i, kernel, batch);
        return;
    }
    ParticleSums sums;
    fluidSums<FACTORS>(i, kernel, batch, sums);
    sums.neighbours = s.mFluidLists[i].size();
    for (int k = 0; ghost && k < 2; ++k) solidSums<FACTORS>(i, k, kernel, batch, sums, firstTouch);
    store<FACTORS>(i, sums, s.mFluidLists[i].size());
}

void DensitySummation::offerNearest(std::size_t i, Touched& firstTouch)
{
    for (int k = 0; k < 2; ++k) {
        Block& block = *blocks[k];
        const Vec3* xs = block.block.particles().positions().data();
        for (Index j : block.lists[i]) {
            const Real r = (x[i] - xs[j]).length();
            if (atomicMin(&block.nearest[j], nearestKey(r, Index(i)))) firstTouch[k].push_back(j);
        }
    }
}

void DensitySummation::keepHaloGradients(std::size_t i, const CubicSplineKernel& kernel,
                                         PairBatch& batch)
{
    Real* g[3];
    gradientsOf(i, g);
    batch.forEachBatch(x[i], x.data(), s.mFluidLists[i], [&](PairBatch& b) {
        for (int k = 0; k < b.n; ++k) b.f[k] = f->liquidMass[b.j[k]] * kernel.gradFactor(b.r[k]);
        keepGradients(b, g);
    });
}

template <bool FACTORS>
void DensitySummation::fluidSums(std::size_t i, const CubicSplineKernel& kernel, PairBatch& batch,
                                 ParticleSums& sums)
{
    Real* g[3] = {nullptr, nullptr, nullptr};
    if (FACTORS && keep) gradientsOf(i, g);
    std::vector<Vec3>* const gradMass = FACTORS ? f->gradMass : nullptr;
    batch.forEachBatch(x[i], x.data(), s.mFluidLists[i], [&](PairBatch& b) {
        if constexpr (FACTORS) {
            for (int k = 0; k < b.n; ++k) b.g[k] = kernel.gradFactor(b.r[k]);
            for (int k = 0; k < b.n; ++k) b.f[k] = f->liquidMass[b.j[k]] * b.g[k];
            if (keep) keepGradients(b, g);
            sums.liquid += b.sumScaledOffsets(b.f);
            for (int k = 0; k < b.n; ++k) {
                sums.liquidNeighbours += f->liquidMass[b.j[k]] > Real(0);
                b.f[k] = sqr(b.f[k] * b.r[k]);
            }
            sums.squares += b.sum(b.f);
            if (gradMass) {
                for (int k = 0; k < b.n; ++k) b.f[k] = m[b.j[k]] * b.g[k];
                sums.all += b.sumScaledOffsets(b.f);
            }
        }
        for (int k = 0; k < b.n; ++k) b.f[k] = m[b.j[k]];
        for (int k = 0; k < b.n; ++k) b.f[k] *= kernel.W(b.r[k]);
        sums.density += b.sum(b.f);
        if (!fill) return;
        for (int k = 0; k < b.n; ++k)
            b.g[k] = kind[b.j[k]] == ParticleKind::GhostAir ? b.f[k] : Real(0);
        sums.air += b.sum(b.g);
    });
}

template <bool FACTORS>
void DensitySummation::solidSums(std::size_t i, int k, const CubicSplineKernel& kernel,
                                 PairBatch& batch, ParticleSums& sums, Touched& firstTouch)
{
    Block& block = *blocks[k];
    const bool moving = k == 1;
    const NeighborLists::List list = block.lists[i];
    const Real M = s.mMass;
    const Vec3 gravity = s.mSettings.gravity;
    Real w = 0;
    batch.forEachBatch(x[i], block.block.particles().positions().data(), list, [&](PairBatch& b) {
        if constexpr (FACTORS) {
            for (int c = 0; c < b.n; ++c) b.f[c] = M * kernel.gradFactor(b.r[c]);
            sums.solid += b.sumScaledOffsets(b.f);
            if (f->mirror) {
                // sum_s M (k_s - k_i) grad W_is with k_s - k_i = (g - a_s) . (x_s - x_i) /
                // rho0 (a_s = 0 for a static solid); (dx, dy, dz) = x_i - x_s.
                if (moving) {
                    for (int c = 0; c < b.n; ++c) {
                        const Vec3& e = f->movingWallGravity[b.j[c]];
                        b.f[c] *= -(e[0] * b.dx[c] + e[1] * b.dy[c] + e[2] * b.dz[c]) / rho0;
                    }
                } else {
                    const Vec3& e = gravity;
                    for (int c = 0; c < b.n; ++c)
                        b.f[c] *= -(e[0] * b.dx[c] + e[1] * b.dy[c] + e[2] * b.dz[c]) / rho0;
                }
                sums.hydrostatic += b.sumScaledOffsets(b.f);
            }
        }
        for (int c = 0; c < b.n; ++c) b.f[c] = kernel.W(b.r[c]);
        w += b.sum(b.f);
        for (int c = 0; c < b.n; ++c) {
            if (atomicMin(&block.nearest[b.j[c]], nearestKey(b.r[c], Index(i))))
                firstTouch[k].push_back(b.j[c]);
        }
    });
    sums.density += M * w;
    sums.neighbours += list.size();
}

template <bool FACTORS>
void DensitySummation::store(std::size_t i, ParticleSums& sums, std::size_t fluid)
{
    if (fill) {
        const Real own = sums.density - sums.air; // liquid and solids
        sums.density = own + std::min(sums.air, std::max(Real(0), rho0 - own));
    }
    rho[i] = sums.density;
    neighbours[i] = std::uint32_t(sums.neighbours);
    if constexpr (FACTORS) {
        if (f->mirror) f->wallHydrostatic[i] = sums.hydrostatic;
        if (f->gradMass) (*f->gradMass)[i] = sums.all + sums.solid;
        const Vec3 solid = sums.solid * f->wall; // the wall's share c
        const int solidNeighbours = int(sums.neighbours - fluid);
        // The particle's own pressure term moves it by its liquid and solid gradient sums and
        // each liquid neighbour by its own term.
        const Real a = (sums.liquid + solid).lengthSqr() + sums.squares;
        f->alpha[i] = a > Real(0) && sums.liquidNeighbours + solidNeighbours >= f->minNeighbours
                          ? Real(1) / a
                          : Real(0);
        f->solidGradient[i] = solid;
    }
}

void DensitySummation::count(double& meanNeighbors, std::size_t& pairCount) const
{
    const std::size_t n = x.size();
    const double liquidCount = parallel::sum(0, n, [&](std::size_t i) {
        return kind[i] == ParticleKind::Liquid && !(halo && halo[i] != Real(0)) ? 1.0 : 0.0;
    });
    const double pairs = parallel::sum(0, n, [&](std::size_t i) { return double(neighbours[i]); });
    meanNeighbors = pairs / std::max(1.0, liquidCount);
    pairCount = std::size_t(pairs);
}

void GhostSolver::computeDensity(const DensityPass& pass)
{
    DensitySummation summation(*this, pass);
    if (pass.factors) summation.run<true>();
    else summation.run<false>();
    summation.count(mRun.meanNeighbors, mPairCount);

    // Lines 8-10: pressure from the equation of state (ghost air: rho0, so p = 0), for a model
    // that has one; an implicit model finds its pressure by its solves.
    LiquidStep view(*this);
    const bool stateEquation = mPressure->pressureFromDensity(view);
    if (mExchange) {
        const auto t = std::chrono::steady_clock::now();
        if (stateEquation) mExchange->refresh(mParticles, {"density", "pressure"});
        else mExchange->refresh(mParticles, {"density"});
        mTimings.exchange += secondsSince(t);
    }

    // Lines 5-7: a ghost solid takes the density (and so the pressure) of its nearest liquid
    // particle; a dynamic solid's ghost takes no pressure (bodyGhostFlags).
    const auto& rho = mParticles.densities();
    const auto& p = mParticles.pressures();
    const std::vector<char> bodyGhost = stateEquation ? bodyGhostFlags() : std::vector<char>();
    for (SolidBlock* b : {&mStatic, &mMoving}) {
        Real* rhoSolid = b->block.particles().densities().data();
        Real* pSolid = b->block.particles().pressures().data();
        const bool bodies = b == &mMoving && !bodyGhost.empty();
        forEachReachedSolid(*b, [&](Index s, Index j) {
            rhoSolid[s] = rho[j];
            if (stateEquation) pSolid[s] = bodies && bodyGhost[s] ? Real(0) : p[j];
        });
    }
}

std::vector<char> GhostSolver::bodyGhostFlags() const
{
    // With its nearest liquid particle's pressure p_j, a dynamic solid's ghost s would push
    // liquid particle i with m_i M (p_i / rho_i^2 + p_j / rho_j^2) grad W_is, a force that is
    // not the gradient of the liquid's energy (p_j answers i's neighbour, not the pair), and
    // a light body fed energy into it: a 500 kg/m^3 box floating on a Tait column rang with the
    // column's acoustic mode at 0.2-0.3 m/s and growing. With no pressure of its own the pair
    // force is m_i M p_i / rho_i^2 grad W_is, the change of i's energy as the body moves, and
    // the ringing decays (0.14 to 0.04 m/s over 2 s; tests/ghost/test_rigid_bodies.cc).
    if (!hasBodies()) return {};
    const ParticleSet& set = mMoving.block.particles();
    const auto& index = set.scalarChannel(SOLID_INDEX);
    std::vector<char> flags(set.size(), 0);
    for (std::size_t s = 0; s < set.size(); ++s)
        flags[s] = mSolids[std::size_t(index[s])]->body ? 1 : 0;
    return flags;
}

} // namespace ghost
} // namespace ghostfx
