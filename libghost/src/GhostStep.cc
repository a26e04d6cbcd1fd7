/// @file   GhostStep.cc
/// @brief  [SB12] Algorithm 3, one step, as the solver's parts the pressure model calls
///         (LiquidStep): one neighbour search and the density (lines 1-7, with DensityPass.cc),
///         then, after the model's pressure and forces (lines 8-14), ghost solid velocity (Eq.
///         3, lines 15-18), XSPH (Eq. 2, lines 19-21), air velocity (lines 22-25) and positions
///         (lines 26-28); then what follows every step: collisions, the kill box and the
///         blow-up check.
/// @details Every pass reads the neighbour lists of the step (searchNeighbors): liquid to liquid
///          and air, and liquid to the particles of each solid block. The nearest liquid particle
///          of a solid particle, which lines 5-7 and 15-18 need, is found in the density pass
///          from the same lists.
#include "ghostfx/ghost/GhostSolver.h"

#include "DfsphPressure.h"
#include "GhostInternal.h"

#include <ghostfx/sph/Exceptions.h>
#include <ghostfx/sph/PairBatch.h>
#include <ghostfx/sph/Parallel.h>
#include <ghostfx/sph/ParticleAge.h>

#include <algorithm>
#include <atomic>
#include <limits>
#include <mutex>
#include <sstream>

namespace ghostfx {
namespace ghost {

using namespace sph;
using namespace detail;

void GhostSolver::prepareSolidBlocks()
{
    // Forget the last step's extrapolation (only where it was made), then re-sort the blocks
    // whose particles changed or moved.
    for (SolidBlock* b : {&mStatic, &mMoving}) {
        restSolidValues(*b);
        if (b->block.stale()) b->block.rebuild();
    }
}

void GhostSolver::searchNeighbors()
{
    // Sort liquid and air by cell so every pass streams through memory, then search once:
    // each liquid particle's neighbours among liquid and air, and in each solid block.
    mGrid.sortParticles(mParticles);
    const std::size_t n = mParticles.size();
    // Air is searched too (liquid and air neighbours only): its nearest liquid particle, whose
    // velocity it takes (lines 22-25), is then the nearest liquid entry of its list.
    const auto& kind = mParticles.kinds();
    const Real R = mSettings.supportRadius();
    const Vec3* x = mParticles.positions().data();
    // Halo copies (other processes' particles) are neighbours, never queries: over several
    // processes a mask picks the queries. On one, every particle of the set is liquid or air
    // and each is a query, with no mask (1 byte per particle saved).
    const Real* halo = haloFlags();
    auto query = [&](std::size_t i) {
        return (!halo || halo[i] == Real(0))
               && (kind[i] == ParticleKind::Liquid || kind[i] == ParticleKind::GhostAir);
    };
    const bool everyOne =
        !halo && parallel::sum(0, n, [&](std::size_t i) { return query(i) ? 0.0 : 1.0; }) == 0;
    if (everyOne) {
        mQueryMask = std::vector<std::uint8_t>();
        mFluidLists.build(mGrid, x, n, R);
    } else {
        resizeStepArray(mQueryMask, n);
        parallel::forEach(0, n, [&](std::size_t i) { mQueryMask[i] = query(i); }, 4096);
        mFluidLists.build(mGrid, x, n, R, mQueryMask.data());
    }
    // Liquid, halo copies included, searches the solid blocks (chosen by the kind channel): a
    // ghost solid's nearest liquid particle (lines 5-7) may be across the cut. Then the
    // nearest-liquid keys get a page wherever those lists reach.
    static_assert(sizeof(ParticleKind) == 1, "the kind channel is a byte per particle");
    const auto* kindBytes = reinterpret_cast<const std::uint8_t*>(kind.data());
    for (SolidBlock* b : {&mStatic, &mMoving}) {
        b->lists.buildFor(b->block.grid(), x, n, R, kindBytes,
                          std::uint8_t(ParticleKind::Liquid));
        if (mSettings.method == Method::Ghost) b->nearest.prepare(b->lists, b->block.size());
        else b->nearest.clear(); // Basic SPH's boundary particles take no liquid values
    }
}

void GhostSolver::NearestKeys::prepare(const NeighborLists& lists, std::size_t particles)
{
    const std::size_t pages = (particles + PAGE_MASK) >> PAGE_BITS;
    std::vector<std::uint8_t> reached(pages, 0);
    parallel::forEach(
        0, lists.size(),
        [&](std::size_t q) {
        lists[q].forEach([&](Index s) {
            __atomic_store_n(&reached[s >> PAGE_BITS], std::uint8_t(1), __ATOMIC_RELAXED);
        });
        },
        1024);
    mPage.assign(pages, 0);
    std::size_t used = 0;
    for (std::size_t page = 0; page < pages; ++page) {
        mPage[page] = std::uint32_t(used);
        if (reached[page]) used += std::size_t(1) << PAGE_BITS;
    }
    if (used > std::size_t(std::numeric_limits<std::uint32_t>::max())) {
        throw ValueError(msg("nearest-liquid table: ", used, " keys exceed 2^32"));
    }
    // Pages not reached share offsets with their successor: never read (no list names them).
    // Capacity grows by a thirty-second and is given back when more than a sixteenth is idle.
    if (used > mKeys.capacity() || mKeys.capacity() > used + used / 16 + 4096) {
        std::vector<std::uint64_t> fitted;
        fitted.reserve(used + used / 32);
        mKeys.swap(fitted);
    }
    mKeys.resize(used);
    parallel::forEach(0, used, [&](std::size_t k) { mKeys[k] = NO_LIQUID; }, 1 << 14);
}

void GhostSolver::NearestKeys::clear()
{
    mPage = std::vector<std::uint32_t>();
    mKeys = std::vector<std::uint64_t>();
}

std::size_t GhostSolver::NearestKeys::memoryBytes() const
{
    return mPage.capacity() * sizeof(std::uint32_t) + mKeys.capacity() * sizeof(std::uint64_t);
}

namespace {

/// Mean and largest |rho / rho0 - 1| of the liquid in `set`.
void liquidDensityError(const ParticleSet& set, Real rho0, double& mean, double& worst)
{
    const auto& rho = set.densities();
    double sum = 0, count = 0;
    worst = 0;
    for (std::size_t i = 0; i < set.size(); ++i) {
        if (set.kinds()[i] != ParticleKind::Liquid) continue;
        const double e = std::abs(double(rho[i] / rho0) - 1);
        sum += e;
        worst = std::max(worst, e);
        ++count;
    }
    mean = count > 0 ? sum / count : 0;
}

} // namespace

void GhostSolver::relaxInitialLiquid()
{
    // Each pass: the neighbours with every ghost in place, then each liquid particle moves down
    // its density gradient (relaxationShift), a step of particle shifting with no flow; the air
    // layer is resampled around the moved liquid every 5 passes and at the end.
    const int passes = mSettings.relaxationPasses(hasBodies());
    if (passes <= 0) return;
    const Real rho0 = mSettings.restDensity;
    // Every other pass keeps the last pass's lists (Verlet lists without a skin). A pass moves
    // a particle by at most 0.05 h, so a pair's distance changes by at most 0.1 h while a list
    // is kept: a pair that leaves the support weighs nothing (the kernel's gradient is zero
    // beyond R), and one that enters is missed where it weighs under 1 % of the gradient's
    // peak (r > R - 0.1 h: 0.3 % at R = 3 h, 0.75 % at 2 h). Keeping lists for four passes
    // (to the next resampling) missed pairs up to 5 % of the peak, and left the stiff
    // collapse's relaxed error 15 % higher (bench/history/diary-2026-11.md); every other pass
    // leaves it as it was.
    std::vector<Vec3> shift;
    for (int pass = 0; pass <= passes; ++pass) {
        const bool resample = pass > 0 && (pass % 5 == 0 || pass == passes);
        if (pass % 2 == 0 || resample) {
            prepareSolidBlocks();
            searchNeighbors();
        }
        if (resample) {
            resampleAir(-1);
            searchNeighbors();
        }
        // The shift below reads the lists and masses only: the density is summed for the
        // errors reported before and after (and the end's sums are the first step's).
        if (pass == 0 || pass == passes) computeDensity();
        if (pass == 0) {
            liquidDensityError(mParticles, rho0, mInitialError.meanSampled,
                               mInitialError.maxSampled);
        }
        if (pass == passes) {
            liquidDensityError(mParticles, rho0, mInitialError.meanRelaxed,
                               mInitialError.maxRelaxed);
            break;
        }
        relaxationShift(shift);
        auto& xw = mParticles.positions();
        parallel::forEach(
            0, mParticles.size(), [&](std::size_t i) { xw[i] += shift[i]; }, 4096);
    }
}

void GhostSolver::relaxationShift(std::vector<Vec3>& shift) const
{
    // beta h^2 grad rho / rho0, at most 0.05 h. beta = 0.5: 20 passes take the column of issue
    // 18 at 10 mm from 3.2 % mean / 13.3 % largest error to 0.6 % / 4.1 % (60 passes: 0.6 % /
    // 3.1 %).
    const Real h = mSettings.spacing, rho0 = mSettings.restDensity;
    const Real beta = Real(0.5), cap = Real(0.05) * h, M = mMass;
    const std::size_t n = mParticles.size();
    const auto& x = mParticles.positions();
    const auto& m = mParticles.masses();
    const auto& kind = mParticles.kinds();
    shift.assign(n, Vec3(0));
    forRangeWithBatch(
        n, mKernel,
        [&](std::size_t lo, std::size_t hi, const CubicSplineKernel& kernel, PairBatch& batch) {
        for (std::size_t i = lo; i < hi; ++i) {
            if (kind[i] != ParticleKind::Liquid) continue;
            const Vec3 xi = x[i];
            Vec3 grad(0);
            batch.forEachBatch(xi, x.data(), mFluidLists[i], [&](PairBatch& b) {
                for (int k = 0; k < b.n; ++k) b.f[k] = m[b.j[k]] * kernel.gradFactor(b.r[k]);
                grad += b.sumScaledOffsets(b.f);
            });
            for (const SolidBlock* block : {&mStatic, &mMoving}) {
                batch.forEachBatch(xi, block->block.particles().positions().data(),
                                   block->lists[i], [&](PairBatch& b) {
                    for (int k = 0; k < b.n; ++k) b.f[k] = M * kernel.gradFactor(b.r[k]);
                    grad += b.sumScaledOffsets(b.f);
                });
            }
            Vec3 d = -(beta * h * h / rho0) * grad;
            const Real length = d.length();
            if (length > cap) d *= cap / length;
            shift[i] = d;
        }
        },
        512);
}

void GhostSolver::extrapolateSolidVelocity()
{
    // Lines 15-18: ghost solid velocity, Eq. 3: the solid's normal velocity and the nearest
    // liquid particle's tangential one (free slip), or the solid's velocity (no slip).
    const auto& vstar = mParticles.vectorChannel(VSTAR);
    const bool freeSlip = mSettings.solidSlip == SolidSlip::Free;
    for (SolidBlock* b : {&mStatic, &mMoving}) {
        ParticleSet& set = b->block.particles();
        if (b->touched.empty()) continue;
        const auto& normal = set.vectorChannel(SOLID_NORMAL);
        Vec3* vstarSolid = set.velocities().data();
        const std::vector<Vec3>* solidV =
            set.hasVectorChannel(SOLID_VELOCITY) ? &set.vectorChannel(SOLID_VELOCITY) : nullptr;
        forEachReachedSolid(*b, [&](Index s, Index j) {
            const Vec3 vs = solidV ? (*solidV)[s] : Vec3(0);
            if (!freeSlip) {
                vstarSolid[s] = vs;
                return;
            }
            const Vec3& nrm = normal[s];
            const Vec3& vl = vstar[j];
            vstarSolid[s] = vs.dot(nrm) * nrm + (vl - vl.dot(nrm) * nrm);
        });
    }
}

void GhostSolver::searchAndDensity(const DensityPass& pass)
{
    // Line 1: resample the air every airResampleSteps steps (the first step always has air),
    // then move every fading air particle's weight one step towards its target; a step that
    // spans more than [SB12]'s step does as much of both as it spans (pass.airSpan), its
    // fraction of a phase carried to the next step.
    // Fading runs first: it removes the air that has faded out, before the sort. New air is
    // sampled after the search (reusing it) with weight 0, so it has no part in this step's sums.
    // Basic SPH has no air to fade or resample.
    prepareSolidBlocks();
    const bool air = mSettings.method == Method::Ghost;
    if (air) fadeAir(pass.airSpan);
    if (mExchange) {
        const auto t = std::chrono::steady_clock::now();
        mExchange->exchange(mParticles, mSettings.supportRadius());
        mTimings.exchange += secondsSince(t);
    }

    auto t0 = std::chrono::steady_clock::now();
    searchNeighbors();
    const double search = secondsSince(t0);
    mTimings.sortAndSearch += search;
    if (air && mRun.step > 0) { // (the first step has fresh air)
        // With a span of 1 a step (the Tait step, DFSPH's default) step s resamples phase s.
        const auto N = std::uint64_t(mSettings.airResampleSteps);
        mAirPhaseCredit += double(pass.airSpan);
        const double phases = std::floor(mAirPhaseCredit);
        mAirPhaseCredit -= phases;
        if (phases > 0) {
            resampleAir(int(mAirPhase % N), int(phases));
            mAirPhase += std::uint64_t(phases);
        }
    }
    t0 = std::chrono::steady_clock::now();
    if (pass.beforeDensity) pass.beforeDensity();
    computeDensity(pass);
    mTimings.neighborsAndDensity += search + secondsSince(t0);
}

void GhostSolver::pressureToSolids()
{
    const Real* p = mParticles.pressures().data();
    for (SolidBlock* b : {&mStatic, &mMoving}) {
        Real* pSolid = b->block.particles().pressures().data();
        forEachReachedSolid(*b, [&](Index s, Index j) { pSolid[s] = p[j]; });
    }
}

void GhostSolver::finishGhostStep(Real dt, const std::vector<Vec3>& gradMass)
{
    const auto t0 = std::chrono::steady_clock::now();
    resizeStepArray(mScratch, mParticles.size());
    extrapolateSolidVelocity();
    if (hasBodies()) {
        gatherBodyForces(dt);
        measureWetShares(bodySlots());
    }
    applyXsph(dt);
    // Halo liquid's new velocities, for the air near the cut that takes one of them.
    if (mExchange) {
        const auto t = std::chrono::steady_clock::now();
        mExchange->refresh(mParticles, {"velocity"});
        mTimings.exchange += secondsSince(t);
    }

    airFollowsLiquid();
    // Lines 26-28: positions of liquid and air.
    auto& x = mParticles.positions();
    const auto& v = mParticles.velocities();
    parallel::forEach(
        0, mParticles.size(), [&](std::size_t i) { x[i] += dt * v[i]; }, 4096);
    if (!gradMass.empty()) shiftParticles(dt, gradMass);
    mTimings.xsphAndBoundary += secondsSince(t0);
}

Real GhostSolver::fastestOwnedLiquid() const
{
    const auto& kind = mParticles.kinds();
    const auto& v = mParticles.velocities();
    const Real* halo = haloFlags();
    Real vmax = 0;
    for (std::size_t i = 0; i < mParticles.size(); ++i) {
        if (kind[i] == ParticleKind::Liquid && (!halo || halo[i] == Real(0)))
            vmax = std::max(vmax, v[i].length());
    }
    return mExchange ? Real(mExchange->maxOf(double(vmax))) : vmax;
}

void GhostSolver::applyXsph(Real dt)
{
    const std::size_t n = mParticles.size();
    const auto& x = mParticles.positions();
    const auto& m = mParticles.masses();
    const auto& rho = mParticles.densities();
    const auto& kind = mParticles.kinds();
    auto& v = mParticles.velocities();
    const auto& vstar = mParticles.vectorChannel(VSTAR);
    const Real M = mMass;
    // Lines 19-21: XSPH artificial viscosity on the velocity (Eq. 2), liquid and solid
    // neighbours only: air would bias the outermost particles ([SB12] Sec. 4.3). The weight
    // eps m_j / rho_j of each neighbour is computed once (zero for air).
    // The wall drag is a rate (GhostSettings::solidEpsilonForStep), scaled by this step's dt
    // against the reference step at the liquid's largest speed.
    const Real* halo = haloFlags();
    auto owned = [halo](std::size_t i) { return !halo || halo[i] == Real(0); };
    const Real eps = mSettings.xsphEpsilonPerStep();
    const Real epsSolid = mSettings.solidEpsilonForStep(dt, fastestOwnedLiquid());
    parallel::forEach(
        0, n,
        [&](std::size_t j) {
        mScratch[j] = kind[j] == ParticleKind::GhostAir ? Real(0) : eps * m[j] / rho[j];
        },
        2048);
    forRangeWithBatch(
        n, mKernel,
        [&](std::size_t lo, std::size_t hi, const CubicSplineKernel& kernel, PairBatch& batch) {
        for (std::size_t i = lo; i < hi; ++i) {
            if (kind[i] != ParticleKind::Liquid || !owned(i)) continue;
            const Vec3 xi = x[i], vi = vstar[i];
            // The particle itself adds w W(0) (v_i - v_i) = 0.
            Vec3 dv(0);
            batch.forEachBatch(xi, x.data(), mFluidLists[i], [&](PairBatch& b) {
                for (int k = 0; k < b.n; ++k) b.f[k] = mScratch[b.j[k]];
                for (int k = 0; k < b.n; ++k) b.f[k] *= kernel.W(b.r[k]);
                dv += b.sumScaledDifferences(b.f, vstar.data(), vi);
            });
            for (const SolidBlock* block : {&mStatic, &mMoving}) {
                const Real* rhoSolid = block->block.particles().densities().data();
                const Vec3* vstarSolid = block->block.particles().velocities().data();
                batch.forEachBatch(xi, block->block.particles().positions().data(), block->lists[i],
                                   [&](PairBatch& b) {
                    for (int k = 0; k < b.n; ++k) b.f[k] = epsSolid * M / rhoSolid[b.j[k]];
                    for (int k = 0; k < b.n; ++k) b.f[k] *= kernel.W(b.r[k]);
                    dv += b.sumScaledDifferences(b.f, vstarSolid, vi);
                });
            }
            v[i] = vi + dv;
        }
        },
        512);
}

void GhostSolver::airFollowsLiquid()
{
    const std::size_t n = mParticles.size();
    const auto& x = mParticles.positions();
    const auto& kind = mParticles.kinds();
    auto& v = mParticles.velocities();
    const Real* halo = haloFlags();
    auto owned = [halo](std::size_t i) { return !halo || halo[i] == Real(0); };
    // Lines 22-25: air takes the new velocity of its nearest liquid particle (searched up to two
    // kernel radii: air advects between resamplings and may drift a little).
    // The nearest liquid entry of the air particle's list (within R), else a search to 2R.
    // Air added after the search (this step's resampling) already has its velocity.
    const Real R = mSettings.supportRadius();
    const std::size_t listed = mFluidLists.size();
    parallel::forEach(
        0, std::min(n, listed),
        [&](std::size_t i) {
        if (kind[i] != ParticleKind::GhostAir || !owned(i)) return;
        Index j = INVALID_INDEX;
        Real best2 = R * R;
        for (Index k : mFluidLists[i]) {
            if (kind[k] != ParticleKind::Liquid) continue;
            const Real r2 = (x[i] - x[k]).lengthSqr();
            if (r2 < best2 || (r2 == best2 && k < j)) {
                best2 = r2;
                j = k;
            }
        }
        if (j == INVALID_INDEX) j = nearestLiquid(x[i], Real(2) * R);
        if (j != INVALID_INDEX) v[i] = v[j];
        },
        256);
}

void GhostSolver::shiftParticles(Real dt, const std::vector<Vec3>& gradMass)
{
    const std::size_t n = mParticles.size();
    const auto& rho = mParticles.densities();
    const auto& kind = mParticles.kinds();
    const auto& v = mParticles.velocities();
    auto& xw = mParticles.positions();
    const auto& x = xw;
    const Real* halo = haloFlags();
    auto owned = [halo](std::size_t i) { return !halo || halo[i] == Real(0); };
    // Particle shifting (GhostSettings::shiftingCoefficient): down the concentration
    // gradient, by a diffusion coefficient A h |v| dt that grows with the distance moved,
    // so a liquid at rest is not shifted. grad C = grad(sum m W) / rho0.
    const Real h = mSettings.spacing;
    const Real scale = mSettings.shifting() * h * dt / mSettings.restDensity;
    const Real cap = Real(0.1) * h;
    const Real completeDensity = Real(0.9) * mSettings.restDensity;
    parallel::forEach(
        0, n,
        [&](std::size_t i) {
        // A particle whose neighbourhood is far from complete (a fresh emitter layer, a
        // drop outside the air layer) has no even spacing to move towards: not shifted.
        // Liquid inside an emitter keeps the emitter's packing: the volume rate is set by
        // how the emitter fills its shape.
        if (kind[i] != ParticleKind::Liquid || rho[i] < completeDensity || !owned(i)) return;
        for (const auto& em : mEmitters) {
            if (em->contains(x[i])) return;
        }
        Vec3 d = -(scale * v[i].length()) * gradMass[i];
        const Real length = d.length();
        if (length > cap) d *= cap / length;
        xw[i] += d;
        },
        4096);
}

// The step ----------------------------------------------------------------------------------------

void GhostSolver::step(Real dt, bool reportPressure)
{
    if (!(dt > Real(0)) || !std::isfinite(dt)) {
        throw ValueError(msg("liquid step: dt = ", dt, " s: expected a finite value > 0"));
    }
    checkRestoredInputs();
    // Whatever this step adds (emitters, resampled air) is born now.
    sph::stampBirthTimes(mParticles, mRun.time);
    mReportPressure = reportPressure;
    const bool fresh = !mRun.initialized;
    const auto start = std::chrono::steady_clock::now();
    if (!initialize()) {
        // Waiting for an emitter that starts later: only time and the solids move (its first
        // fill owes nothing).
        stepWithoutLiquid(dt, start, false);
        return;
    }
    // Algorithm 3 line 1: new liquid from the emitters (the first step's was added by
    // initialize(), before the mass scaling).
    if (!fresh && !mEmitters.empty()) {
        const auto t0 = std::chrono::steady_clock::now();
        emit();
        mTimings.emission += secondsSince(t0);
    }
    if (liquidIsGone()) {
        // Every liquid particle has left through the kill box: the air around it goes too,
        // and the solids and emitters go on until an emitter pours again.
        dropAir();
        stepWithoutLiquid(dt, start, true);
        return;
    }
    LiquidStep parts(*this);
    mPressure->step(parts, dt);

    const double t1 = mRun.time + double(dt);
    accrueEmission(mRun.time, t1);
    if (hasBodies()) advanceBodies(dt);
    moveSolids(t1);
    mRun.time = t1;
    ++mRun.step;
    projectOutOfSolids(dt);
    if (mExchange) mExchange->dropHalo(mParticles);
    applyKillBox();
    checkBlowUp();
    mTimings.total += secondsSince(start);
    ++mTimings.steps;
    if (mObserver) mObserver(*this, dt);
}

bool GhostSolver::liquidIsGone() const
{
    const auto& kinds = mParticles.kinds();
    const double here =
        std::find(kinds.begin(), kinds.end(), ParticleKind::Liquid) != kinds.end() ? 1.0 : 0.0;
    // Over several processes all of them decide together (each takes part in every exchange).
    return (mExchange ? mExchange->maxOf(here) : here) == 0.0;
}

void GhostSolver::dropAir()
{
    if (mParticles.count(ParticleKind::GhostAir) == 0) return;
    std::vector<std::uint8_t> remove(mParticles.size(), 0);
    for (std::size_t i = 0; i < mParticles.size(); ++i)
        remove[i] = mParticles.kinds()[i] == ParticleKind::GhostAir;
    mParticles.removeIf(remove);
}

void GhostSolver::stepWithoutLiquid(Real dt, std::chrono::steady_clock::time_point start,
                                    bool accrue)
{
    const double t1 = mRun.time + double(dt);
    if (accrue) accrueEmission(mRun.time, t1);
    if (hasBodies()) advanceBodies(dt);
    moveSolids(t1);
    mRun.time = t1;
    ++mRun.step;
    mRun.maxAcceleration = 0;
    mTimings.total += secondsSince(start);
    ++mTimings.steps;
    if (mObserver) mObserver(*this, dt);
}

// Collisions and blow-up -------------------------------------------------------------------------

Index GhostSolver::nearestLiquid(const Vec3& x, Real maxRadius) const
{
    return mGrid.nearestOfKind(x, mParticles.kinds(), ParticleKind::Liquid, maxRadius);
}

void GhostSolver::projectOutOfSolids(Real dt)
{
    if (mSolids.empty()) return;
    const auto start = std::chrono::steady_clock::now();
    auto& x = mParticles.positions();
    auto& v = mParticles.velocities();
    const auto& kind = mParticles.kinds();
    const double time = mRun.time;
    const std::vector<RigidTransform> placement = sph::placementsAt(mSolids, time);
    // Only particles near a solid can have entered it. A liquid particle with no solid particle
    // within R at the start of the step is at least R - 2h from every solid surface (surface
    // samples lie about h apart); it cannot have crossed that this step unless it, or a moving
    // solid, went farther. After a solid changed shape every particle is tested.
    const Real h = mSettings.spacing;
    const Real margin = std::max(Real(0), mSettings.supportRadius() - Real(2) * h);
    const bool all = mProjectAll;
    const std::size_t listed = mFluidLists.size(); // particles added after the search are air
    const Real solidSpeed = mMaxSolidSpeed;
    // [SB12] Sec. 3 "Solid Collisions" (sph::collideWithSolid). The step moved each particle
    // by dt v, so it started at x - dt v.
    std::atomic<std::size_t> stuck{mParticles.size()};
    std::atomic<std::uint64_t> restored{0};
    const Real* halo = haloFlags();
    // The momentum each particle loses to a dynamic solid, given to it after the loop.
    const bool bodies = hasBodies();
    std::vector<Vec3> impulse(bodies ? mParticles.size() : 0, Vec3(0));
    std::vector<std::uint32_t> hit(bodies ? mParticles.size() : 0, NO_BODY_HIT);
    const auto& m = mParticles.masses();
    parallel::forEach(0, mParticles.size(), [&](std::size_t i) {
        if (kind[i] != ParticleKind::Liquid || (halo && halo[i] != Real(0))) return;
        const bool near = all || i >= listed || !mStatic.lists[i].empty()
                          || !mMoving.lists[i].empty()
                          || dt * (v[i].length() + solidSpeed) >= margin;
        if (!near) return;
        const Vec3 previous = x[i] - dt * v[i];
        for (std::size_t b = 0; b < mSolids.size(); ++b) {
            const Vec3 before = v[i];
            const Collision c =
                collideWithSolid(*mSolids[b], placement[b], time, previous, x[i], v[i]);
            if (bodies && mSolids[b]->body && (c == Collision::Projected || c == Collision::Restored)) {
                impulse[i] += m[i] * (v[i] - before);
                hit[i] = std::uint32_t(b);
            }
            if (c == Collision::Restored) ++restored;
            if (c == Collision::Stuck) {
                std::size_t expected = stuck.load();
                while (i < expected && !stuck.compare_exchange_weak(expected, i)) {}
            }
        }
    });
    mRestoredFromSolids += restored.load();
    if (bodies) giveCollisionImpulses(impulse, hit);
    if (const std::size_t i = stuck.load(); i < mParticles.size()) throwStuckInSolid(i);
    mProjectAll = false;
    mTimings.xsphAndBoundary += secondsSince(start);
}

void GhostSolver::throwStuckInSolid(std::size_t i) const
{
    const auto& x = mParticles.positions();
    const double time = mRun.time;
    std::size_t b = 0;
    while (b + 1 < mSolids.size() && !(mSolids[b]->phi(x[i], time) < Real(0))) ++b;
    std::ostringstream where;
    where << "(" << x[i][0] << ", " << x[i][1] << ", " << x[i][2] << ")";
    const LevelSet& shape = mSolids[b]->shape;
    throw NumericalError(msg("liquid solver at frame ", mRun.frame, ", step ", mRun.step,
                             " (t = ", mRun.time, " s): liquid particle id ",
                             mParticles.ids()[i], " at ", where.str(), " is inside solid '",
                             shape.name(), "' deeper than its level set's band (",
                             shape.bandWidth(),
                             " m), and so was its position before the step: it cannot "
                             "be put back; reduce the time step (substeps / cflNumber)"));
}

void GhostSolver::checkBlowUp() const
{
    const Real limit = mSettings.speedLimit();
    const Real limit2 = limit * limit;
    const auto& x = mParticles.positions();
    const auto& v = mParticles.velocities();
    const std::size_t n = mParticles.size();
    std::atomic<std::size_t> bad{n};
    parallel::forEach(
        0, n,
        [&](std::size_t i) {
        if (isFinite(x[i]) && isFinite(v[i]) && v[i].lengthSqr() <= limit2) return;
        std::size_t expected = bad.load();
        while (i < expected && !bad.compare_exchange_weak(expected, i)) {}
        },
        4096);
    const std::size_t i = bad.load();
    // Over several processes every one must stop together (a process that throws alone would
    // leave the others waiting in the next exchange).
    if (mExchange && mExchange->maxOf(i == n ? 0.0 : 1.0) > 0 && i == n) {
        throw NumericalError(msg("liquid solver blew up at frame ", mRun.frame, ", step ",
                                 mRun.step, " (t = ", mRun.time,
                                 " s) on another process (its own message says where); reduce "
                                 "the time step (substeps / cflNumber) or the stiffness"));
    }
    if (i == n) return;
    const char* kind = kindName(mParticles.kinds()[i]);
    if (!isFinite(x[i]) || !isFinite(v[i])) {
        throw NumericalError(msg("liquid solver blew up at frame ", mRun.frame, ", step ",
                                 mRun.step, " (t = ", mRun.time, " s): ", kind, " particle id ",
                                 mParticles.ids()[i],
                                 " has a non-finite position or velocity; reduce the time step "
                                 "(substeps / cflNumber) or the stiffness"));
    }
    throw NumericalError(msg("liquid solver blew up at frame ", mRun.frame, ", step ", mRun.step,
                             " (t = ", mRun.time, " s): ", kind, " particle id ",
                             mParticles.ids()[i], " moves at ", v[i].length(),
                             " m/s, beyond maxSpeed = ", limit,
                             " m/s; reduce the time step (substeps / cflNumber) or the stiffness"));
}

} // namespace ghost
} // namespace ghostfx
