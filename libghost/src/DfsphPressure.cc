/// @file   DfsphPressure.cc
/// @brief  Ghost SPH with an implicit pressure: the divergence-free SPH solves of Bender and
///         Koschier ([BK15] "Divergence-Free Smoothed Particle Hydrodynamics", SCA 2015;
///         [BK17] the TVCG 2017 version) over [SB12]'s ghost air and ghost solids.
/// @details One step, with one neighbour search (the lists of GhostStep.cc):
///           1. density (Eq. 1, every kind of neighbour) and the factor alpha_i of each liquid
///              particle, keeping each liquid pair's m_j grad W_ij for the solves' passes
///              (DfsphSettings::keepGradients; the positions do not move until step 4), all
///              in one pass over the pairs (the density pass, GhostSolver::computeDensity);
///           2. the divergence solve on the velocities the last step left ([BK15] Algorithm 2,
///              moved from the end of the last step to the start of this one, where the new
///              neighbourhood is known: the same sequence with one search);
///           3. v* = v + dt g, then the constant-density solve ([BK15] Algorithm 3) on v*;
///           4. [SB12] Algorithm 3 from line 15 on, unchanged: Eq. 3 ghost solid velocities,
///              XSPH, air velocities, positions.
///
///          Both solves find pressure terms k_i = p_i / rho_i^2 (m^5 / (kg s^2)) whose velocity
///          change is the symmetric pressure force of [SB12]'s Tait step,
///              v_i -= dt (G k)_i,   (G k)_i = sum_liquid j m_j (k_i + k_j) grad W_ij
///                                             + c sum_solid s M k_i grad W_is,
///          such that the rate of density change (D v)_i = sum_liquid j m_j (v_i - v_j) .
///          grad W_ij + c sum_solid s M (v_i - v_s) . grad W_is meets the solve's target (c: the
///          wall's share, below). D G is symmetric and positive semi-definite (for equal
///          masses sum_i k_i (D u)_i = sum_i u_i . (G k)_i when solids are held still), so the
///          solve is preconditioned conjugate gradients with [BK15]'s alpha_i as the inverse
///          diagonal. [BK15]'s Jacobi iteration (k_i = alpha_i e_i / dt^2) diverges at [SB12]'s
///          3 h support: with about 110 neighbours the off-diagonal coupling outweighs the
///          diagonal (measured: the error grew 4.4 x per iteration on a sampled ball).
///
///          How the ghosts take part (each choice measured: bench/history/diary-2026-11.md,
///          "DFSPH"):
///           - ghost air gives a surface particle its full density (its mass is in rho_i) at
///             zero pressure (k = 0), and moves with the liquid: it adds nothing to the rate of
///             density change or to the forces. So no density clamping and no surface special
///             case: a surface particle has the error of any other. Air held still in the solve
///             walls the liquid in (a falling ball's solve pressed it against its own air); air
///             following its nearest liquid particle makes an isolated particle's density
///             unchangeable (the system singular).
///           - a ghost solid adds its mass to rho_i and, as seen from liquid particle i, is
///             i's mirror image in the wall (DfsphSettings::WallPressure::Mirror, the default):
///             its pressure term is i's, extrapolated down the hydrostatic gradient,
///                 k_s = k_i + g . (x_s - x_i) / rho0      (Adami et al. 2012, p_s = p_i +
///                                                          rho0 g . (x_s - x_i), over rho0^2),
///             and its velocity relative to the wall is i's reflected, so i closes on it twice
///             as fast as on a fixed particle. The pair's symmetric force M (k_i + k_s) grad
///             W_is then splits into c = 2 times the unknown k_i, in G, and the known
///             hydrostatic part, applied with gravity before the density solve; and D's solid
///             term takes the same c = 2 (the mirror's approach rate), so D G stays symmetric.
///             For a linear pressure field the sum over liquid and ghosts then gives grad k
///             times the full moment of the kernel: without the mirror, the solid term leaves
///             a force proportional to k_i itself, which at depth outweighs the pressure
///             gradient. Measured (bench/history/diary-2026-11.md, "DFSPH: ghost solids as mirror
///             images"): with WallPressure::Own (c = 1, no extrapolation, the previous model) a
///             still tank's pressure rose 0.6 to 1.4 % too fast with depth and a slab under a
///             ceiling slid 1.2-1.8 cm in 0.1 s (the top layer packed against the layer below under
///             tension); mirrored, -0.1 to +0.4 % and within 1 mm. The factor alone (c = 2
///             without the extrapolation) compressed the tank by 2.6 %; c = 2 in G but not in
///             D (D the exact rate of the density sum) is not symmetric, and the conjugate
///             gradients blew up. A moving solid's ghost extrapolates with g - a_s, a_s its
///             own acceleration over the step (Adami's full form; computeMovingWallGravity): in
///             a tank accelerating upwards at g / 2, the slope is -0.9 to +0.5 % of rho0 1.5 g,
///             against +2.0 to +4.4 % with g alone.
///             The reflection is about the solid's own velocity (the wall's normal velocity is
///             what it imposes): taking [SB12]'s Eq. 3 velocity there (the tangential velocity
///             of the nearest liquid) fed the liquid's corrections back into the walls'
///             velocities and a still tank blew up at the corners.
///           - the density-invariance target is relaxed (Asai et al. 2012's stabilised
///             incompressible SPH): the density solve asks for rho + dt D rho / Dt = rho0 +
///             (1 - beta) (rho - rho0), beta = DfsphSettings::densityRelaxation per step, while
///             the divergence solve asks for D rho / Dt = 0 in full. The Poisson samples, the
///             resampled air and the emitters' new particles carry density errors of a few
///             percent; asking each step to remove them in full (beta = 1) turns them into
///             velocity kicks of error x h / dt that grew without bound in every violent test.
///           - a liquid particle with fewer than MIN_NEIGHBOURS liquid and solid neighbours (at
///             [SB12]'s 3 h support; in proportion to the support's volume at another) is
///             spray (a thin stream's edge, a drop): too little to push against; it takes no
///             part in the solve.
///
///          Over several processes (setExchange) each solves for the particles it owns: before
///          a pass reads its neighbours' values (the search direction, G k, v*), the halo
///          copies get their owners' (ParticleExchange::refresh), and every sum the iteration
///          decides on (dot products, the error, the count) is summed over the processes, so
///          all take the same iterations and stop together. The result equals the one-process
///          solve up to summation order.
#include "DfsphPressure.h"

#include "GhostInternal.h"

#include <ghostfx/sph/Exceptions.h>
#include <ghostfx/sph/PairBatch.h>
#include <ghostfx/sph/Parallel.h>

#include <algorithm>
#include <cmath>
#include <type_traits>

namespace ghostfx {
namespace ghost {

using namespace sph;
using namespace detail;

namespace {

/// A density solve whose warm start fits the step with a share below this iterates at least
/// once (see DfsphSolve::warmStart). Measured on the column tank at CFL 0.1, 30 frames: 0.8,
/// 0.9 and 0.95 all keep its fastest particles at 1.3 to 2.3 m/s; 0.5 let one reach 83 m/s by
/// frame 16; at 0.9 the still tank's solves never fall below it (the hydrostatic pressure fits
/// whole).
constexpr Real WARM_SHARE_RENEWED = Real(0.9);

/// The largest speed of the liquid a process owns, over every process.
double fastestLiquid(LiquidStep& step)
{
    const ParticleSet& set = step.particles();
    const auto& v = set.velocities();
    const auto& kinds = set.kinds();
    const Real* halo = step.haloFlags();
    const double vmax = parallel::maximum(0, set.size(), [&](std::size_t i) {
        return kinds[i] == ParticleKind::Liquid && (!halo || halo[i] == Real(0))
                   ? double(v[i].length())
                   : 0.0;
    });
    return step.exchange() ? step.exchange()->maxOf(vmax) : vmax;
}

/// One DFSPH solve on the v* velocities (preconditioned conjugate gradients, the file
/// comment): the density solve drives rho + dt D rho / Dt to its relaxed target, the
/// divergence solve D rho / Dt to 0. `total` is the per-particle channel of accumulated
/// pressure terms (warm start in, result out).
class DfsphSolve
{
public:
    DfsphSolve(LiquidStep& step, const DfsphFactors& factors, const DfsphSettings& options,
               Real dt, bool density)
        : mStep(step)
        , mSet(step.particles())
        , mFactors(factors)
        , mOptions(options)
        , n(mSet.size())
        , x(mSet.positions())
        , rho(mSet.densities())
        , w(mSet.vectorChannel(VSTAR))
        , M(step.particleMass())
        , rho0(step.settings().restDensity)
        , mDt(dt)
        , dt2(dt * dt)
        , mDensity(density)
        , limit(double(density ? options.densityError : options.divergenceError))
        , halo(step.haloFlags())
        , exchange(step.exchange())
        , movingSolids(!step.solids(LiquidStep::MOVING).empty())
        , movingV(movingSolids
                      ? step.solids(LiquidStep::MOVING).vectorChannel(SOLID_VELOCITY).data()
                      : nullptr)
    {
        beta = density ? options.densityRelaxation * relaxationScale() : Real(0);
        u.assign(n, Vec3(0));
        rate.assign(n, Real(0));
        for (auto* a : {&k, &r, &z, &p, &q}) a->assign(n, Real(0));
        change.assign(n, Vec3(0));
        count = everywhere(parallel::sum(0, n, [&](std::size_t i) { return solved(i) ? 1.0 : 0.0; }));
    }

    /// Solve; returns the iterations and sets the mean error reached and the largest one
    /// particle's error left. `converged` is false when the solve stopped at maxIterations.
    int run(std::vector<Real>& total, double& error, double& largest, bool& converged);

private:
    bool solved(std::size_t i) const { return mFactors.alpha[i] > Real(0); }
    double everywhere(double value) const { return exchange ? exchange->sumOf(value) : value; }
    /// The relaxation is a share per step of the length CFL 0.4 would take; a shorter step
    /// takes a share in proportion (DfsphSettings::densityRelaxation).
    Real relaxationScale() const
    {
        const Real reference = dfsphTimeStep(mStep.settings(), Real(fastestLiquid(mStep)),
                                             DfsphSettings::RELAXATION_CFL);
        return std::min(Real(1), mDt / reference);
    }
    template <typename T>
    void takeOwners(std::vector<T>& values, std::vector<T>& channel, const char* name);
    /// The halo copies' entries of `values` from their owners (DFSPH_SYNC carries them).
    void fromOwners(std::vector<Real>& values);
    template <bool KEPT> void gradientPass(const std::vector<Real>& k);
    /// u = G k (see the file comment), zero for air and spray.
    void gradient(const std::vector<Real>& k)
    {
        // Each pass is instantiated once for kept and once for recomputed gradients (a task
        // body holding both lost the recomputing loops' inlining: 7-13 % slower column tank).
        if (mFactors.gradientsKept) gradientPass<true>(k);
        else gradientPass<false>(k);
    }
    template <bool KEPT> void divergencePass(const std::vector<Vec3>& vel, bool solidMoves);
    /// rate = D vel for the solved particles: liquid velocities `vel`, solids at their own
    /// velocity (`solidMoves`) or still.
    void divergence(const std::vector<Vec3>& vel, bool solidMoves)
    {
        if (mFactors.gradientsKept) divergencePass<true>(vel, solidMoves);
        else divergencePass<false>(vel, solidMoves);
    }
    /// a . b over the solved particles (a halo copy's entries are its owner's, not summed).
    double dot(const std::vector<Real>& a, const std::vector<Real>& b) const
    {
        return everywhere(parallel::sum(
            0, n, [&](std::size_t i) { return solved(i) ? double(a[i]) * double(b[i]) : 0.0; }));
    }
    double meanError() const;
    double largestError() const;
    bool converged(double mean, double& largest) const
    {
        largest = largestError();
        return mean <= limit && largest <= DfsphSettings::PEAK_FACTOR * limit;
    }
    void gradientEverywhere(std::vector<Real>& values);
    /// q = D u for the solved particles (solids held still).
    void divergenceOfChange()
    {
        divergence(u, false);
        parallel::forEach(
            0, n, [&](std::size_t i) { q[i] = solved(i) ? rate[i] : Real(0); }, 4096);
    }
    void residual();
    bool warmStart(const std::vector<Real>& total);
    Real warmShareWithMovingSolids();
    Real warmShareWithStillSolids();
    int iterate(double& error, double& largest, bool& done, int least);

    LiquidStep& mStep;
    ParticleSet& mSet;
    const DfsphFactors& mFactors;
    const DfsphSettings& mOptions;
    const std::size_t n;
    const std::vector<Vec3>& x;
    const std::vector<Real>& rho;
    std::vector<Vec3>& w;
    const Real M, rho0, mDt, dt2;
    const bool mDensity;
    const double limit;
    const Real* halo;
    ParticleExchange* exchange;
    const bool movingSolids;
    const Vec3* movingV;
    Real beta = 0;
    Real share = 1;          ///< of the last pressure applied by the warm start
    bool residualKnown = false;
    double count = 0;        ///< solved particles, over every process
    std::vector<Vec3> u;     ///< G of the last gradient pass's values
    std::vector<Real> rate;  ///< the last divergence pass's D v
    std::vector<Real> k, r, z, p, q;
    std::vector<Vec3> change; ///< G k, accumulated with k
};

/// The halo copies' entries of `values` from their owners, carried by `channel` (DFSPH_SYNC
/// or DFSPH_SYNC_VECTOR).
template <typename T>
void DfsphSolve::takeOwners(std::vector<T>& values, std::vector<T>& channel, const char* name)
{
    std::copy(values.begin(), values.end(), channel.begin());
    exchange->refresh(mSet, {name});
    for (std::size_t i = 0; i < n; ++i) {
        if (halo[i] != Real(0)) values[i] = channel[i];
    }
}

void DfsphSolve::fromOwners(std::vector<Real>& values)
{
    if (exchange) takeOwners(values, mSet.scalarChannel(DFSPH_SYNC), DFSPH_SYNC);
}

template <bool KEPT> void DfsphSolve::gradientPass(const std::vector<Real>& k)
{
    const std::vector<Real>& lm = mFactors.liquidMass;
    const NeighborLists& lists = mStep.lists();
    const Real* gx = mFactors.pairGradient[0].data();
    const Real* gy = mFactors.pairGradient[1].data();
    const Real* gz = mFactors.pairGradient[2].data();
    forRangeWithBatch(
        n, mStep.kernel(),
        [&](std::size_t lo, std::size_t hi, const CubicSplineKernel& kernel, PairBatch& batch) {
        for (std::size_t i = lo; i < hi; ++i) {
            if (lm[i] == Real(0)) continue;
            const Real ki = k[i];
            Vec3 sum(0);
            if constexpr (KEPT) {
                const std::size_t at = mFactors.pairStart[i];
                batch.forEachIndexBatch(lists[i], [&](PairBatch& b, std::size_t first) {
                    for (int c = 0; c < b.n; ++c) b.f[c] = ki + k[b.j[c]];
                    sum += b.sumScaled(b.f, gx + at + first, gy + at + first, gz + at + first);
                });
            } else {
                batch.forEachBatch(x[i], x.data(), lists[i], [&](PairBatch& b) {
                    for (int c = 0; c < b.n; ++c) b.f[c] = lm[b.j[c]] * (ki + k[b.j[c]]);
                    for (int c = 0; c < b.n; ++c) b.f[c] *= kernel.gradFactor(b.r[c]);
                    sum += b.sumScaledOffsets(b.f);
                });
            }
            // The solids' part, k_i sum_s M grad W_is, from the step's sum.
            u[i] = sum + ki * mFactors.solidGradient[i];
        }
        },
        512);
}

template <bool KEPT>
void DfsphSolve::divergencePass(const std::vector<Vec3>& vel, bool solidMoves)
{
    // c sum_s M (v_i - v_s) . grad W_is = v_i . (the step's solid gradient sum, c included) -
    // c times the moving block's sum_s M v_s . grad W_is (static solids have v_s = 0).
    const std::vector<Real>& lm = mFactors.liquidMass;
    const NeighborLists& lists = mStep.lists();
    const Real* gx = mFactors.pairGradient[0].data();
    const Real* gy = mFactors.pairGradient[1].data();
    const Real* gz = mFactors.pairGradient[2].data();
    const ParticleSet& moving = mStep.solids(LiquidStep::MOVING);
    const NeighborLists& movingLists = mStep.solidLists(LiquidStep::MOVING);
    const Real wall = mFactors.wall;
    forRangeWithBatch(
        n, mStep.kernel(),
        [&](std::size_t lo, std::size_t hi, const CubicSplineKernel& kernel, PairBatch& batch) {
        for (std::size_t i = lo; i < hi; ++i) {
            if (!solved(i)) continue;
            const Vec3 vi = vel[i];
            Real sum = vi.dot(mFactors.solidGradient[i]);
            if constexpr (KEPT) {
                const std::size_t at = mFactors.pairStart[i];
                batch.forEachIndexBatch(lists[i], [&](PairBatch& b, std::size_t first) {
                    sum += b.sumApproach(vel.data(), vi, gx + at + first, gy + at + first,
                                         gz + at + first);
                });
            } else {
                batch.forEachBatch(x[i], x.data(), lists[i], [&](PairBatch& b) {
                    for (int c = 0; c < b.n; ++c) b.f[c] = lm[b.j[c]] * kernel.gradFactor(b.r[c]);
                    sum += b.sumScaledApproach(b.f, vel.data(), vi);
                });
            }
            if (solidMoves && movingSolids) {
                batch.forEachBatch(x[i], moving.positions().data(), movingLists[i],
                                   [&](PairBatch& b) {
                    for (int c = 0; c < b.n; ++c) b.f[c] = M * kernel.gradFactor(b.r[c]);
                    sum += wall * b.sumScaledApproach(b.f, movingV, Vec3(0));
                });
            }
            rate[i] = sum;
        }
        },
        512);
}

/// Mean |e| / rho0 over the solved particles of the residuals r = e / dt^2.
double DfsphSolve::meanError() const
{
    const double sum = everywhere(parallel::sum(
        0, n, [&](std::size_t i) { return solved(i) ? double(std::abs(r[i])) : 0.0; }));
    return count > 0 ? sum * double(dt2) / count / double(rho0) : 0.0;
}

/// Largest |e| / rho0 of one particle. The mean alone does not see a few particles in a
/// hundred thousand: in SPlisHSPlasH's dam break at 100k, a handful beside the floor were
/// squeezed from 1.3 to 2.7 rho0 over ten steps in which the mean stayed under its limit and
/// no iteration ran (bench/history/diary-2026-11.md, "DFSPH: a peak limit";
/// DfsphSettings::PEAK_FACTOR).
double DfsphSolve::largestError() const
{
    const double m = parallel::maximum(
        0, n, [&](std::size_t i) { return solved(i) ? double(std::abs(r[i])) : 0.0; });
    return (exchange ? exchange->maxOf(m) : m) * double(dt2) / double(rho0);
}

/// u = G values, with the halo copies' from their owners.
void DfsphSolve::gradientEverywhere(std::vector<Real>& values)
{
    fromOwners(values);
    gradient(values);
    if (exchange) takeOwners(u, mSet.vectorChannel(DFSPH_SYNC_VECTOR), DFSPH_SYNC_VECTOR);
}

/// r: the error the velocities w leave, beta (rho - rho0) + dt D rho / Dt for the density
/// solve, dt D rho / Dt for the divergence solve (over dt^2).
void DfsphSolve::residual()
{
    if (exchange) exchange->refresh(mSet, {VSTAR});
    divergence(w, true);
    parallel::forEach(
        0, n,
        [&](std::size_t i) {
        if (solved(i)) r[i] = (beta * (rho[i] - rho0) + mDt * rate[i]) / dt2;
        },
        4096);
}

/// D counts the moving solids' velocities, the sums of warmShareWithStillSolids do not: r and
/// D G k are found as they are, with one more pass.
Real DfsphSolve::warmShareWithMovingSolids()
{
    residual();
    divergenceOfChange();
    const double kq = dot(k, q);
    const Real s = kq > 0 ? Real(std::clamp(dot(k, r) / kq, 0.0, 1.0)) : Real(0);
    parallel::forEach(
        0, n, [&](std::size_t i) { r[i] -= s * q[i]; }, 4096);
    residualKnown = true;
    return s;
}

/// With the solids still, k . D u = u . G k over the liquid (D G symmetric, see the file
/// comment): k . D G k = |G k|^2 and k . r = k . beta (rho - rho0) / dt^2 + w . G k / dt, so
/// no pass beyond the gradient's.
Real DfsphSolve::warmShareWithStillSolids()
{
    const std::vector<Real>& lm = mFactors.liquidMass;
    auto owned = [&](std::size_t i) { return lm[i] != Real(0) && (!halo || halo[i] == Real(0)); };
    const double uu = everywhere(parallel::sum(
        0, n, [&](std::size_t i) { return owned(i) ? double(u[i].lengthSqr()) : 0.0; }));
    const double kr = everywhere(parallel::sum(0, n, [&](std::size_t i) {
        double term = owned(i) ? double(w[i].dot(u[i])) / double(mDt) : 0.0;
        if (solved(i)) term += double(k[i]) * double(beta * (rho[i] - rho0)) / double(dt2);
        return term;
    }));
    return uu > 0 ? Real(std::clamp(kr / uu, 0.0, 1.0)) : Real(0);
}

/// The warm start: the last step's pressure terms first ([BK15] Sec. 4.3); nothing to apply on
/// the first step, or after a restart from rest. Returns whether there was one.
/// The density solve applies the share s of the last pressure that best fits this step, the s
/// in [0, 1] minimising the error left in the norm of D G:
///     s = (k . r) / (k . D G k),
/// a line search along the last pressure before the conjugate gradients start. The solve's
/// limit is on one step's density change, which shrinks with the step while a pressure's force
/// does not: applied whole, a last pressure that no longer fits (after an impact) is a force
/// that small steps find "converged" and apply again, step after step, with no iteration to
/// renew it, until the liquid runs away (CFL 0.1: 22 m/s within 0.06 s in
/// Dfsph.SmallCflStepsStayBounded). The divergence solve's last terms are applied whole: a
/// share fitted to each step's divergence there shook a still tank (interior speed 0.17 ->
/// 0.35 m/s), and whole they do not run away. Measured: bench/history/diary-2026-11.md,
/// "DFSPH at small steps".
bool DfsphSolve::warmStart(const std::vector<Real>& total)
{
    const bool startWarm = mOptions.warmStart && (mDensity || mOptions.divergenceWarmStart);
    const bool warm = startWarm && everywhere(parallel::sum(0, n, [&](std::size_t i) {
                                       return solved(i) && total[i] != Real(0) ? 1.0 : 0.0;
                                   })) > 0;
    if (!warm) return false;
    parallel::forEach(
        0, n, [&](std::size_t i) { k[i] = solved(i) ? total[i] : Real(0); }, 4096);
    // (The halo copies' G k only where D G k is summed below.)
    if (mDensity && movingSolids) gradientEverywhere(k);
    else {
        fromOwners(k);
        gradient(k);
    }
    if (mDensity && movingSolids) share = warmShareWithMovingSolids();
    else if (mDensity) share = warmShareWithStillSolids();
    parallel::forEach(
        0, n, [&](std::size_t i) { w[i] -= mDt * share * u[i]; }, 4096);
    return true;
}

/// Preconditioned conjugate gradients on D G k = r, from k = 0, for at least `least`
/// iterations; then v* and `total` take the result. Returns the iterations.
int DfsphSolve::iterate(double& error, double& largest, bool& done, int least)
{
    std::fill(k.begin(), k.end(), Real(0));
    const std::vector<Real>& alpha = mFactors.alpha;
    parallel::forEach(
        0, n,
        [&](std::size_t i) {
        z[i] = alpha[i] * r[i];
        p[i] = z[i];
        },
        4096);
    double rz = dot(r, z);
    int iteration = 0;
    while (iteration < mOptions.maxIterations) {
        ++iteration;
        gradientEverywhere(p);
        divergenceOfChange();
        const double pq = dot(p, q);
        if (!(pq > 0)) break; // what is left lies where G has no effect
        const Real step = Real(rz / pq);
        // G k accumulates with k (G is linear): no gradient pass after the loop.
        parallel::forEach(
            0, n,
            [&](std::size_t i) {
            k[i] += step * p[i];
            r[i] -= step * q[i];
            change[i] += step * u[i];
            },
            4096);
        error = meanError();
        if (!std::isfinite(error)) {
            throw NumericalError(msg("liquid solver at frame ", mStep.frame(), ", step ",
                                     mStep.stepIndex(), " (t = ", mStep.time(), " s): the DFSPH ",
                                     mDensity ? "density" : "divergence",
                                     " solve gave a non-finite error at iteration ", iteration,
                                     "; reduce the time step (dfsph.max_dt, cfl)"));
        }
        done = converged(error, largest) && iteration >= least;
        if (done) break;
        parallel::forEach(
            0, n, [&](std::size_t i) { z[i] = alpha[i] * r[i]; }, 4096);
        const double rzNext = dot(r, z);
        const Real direction = Real(rzNext / rz);
        rz = rzNext;
        parallel::forEach(
            0, n, [&](std::size_t i) { p[i] = z[i] + direction * p[i]; }, 4096);
    }
    return iteration;
}

int DfsphSolve::run(std::vector<Real>& total, double& error, double& largest, bool& done)
{
    const bool warm = warmStart(total);
    const bool startWarm = mOptions.warmStart && (mDensity || mOptions.divergenceWarmStart);
    parallel::forEach(
        0, n,
        [&](std::size_t i) { total[i] = solved(i) && startWarm ? share * total[i] : Real(0); },
        4096);
    if (!residualKnown) residual();
    error = meanError();
    // Where less than WARM_SHARE_RENEWED of the last pressure fits, the solve iterates at
    // least once whatever its limit says: the share alone bounds the run-away but leaves local
    // misfits (a global s is set by the bulk) that at CFL 0.1 kept the column tank's fastest
    // particles at 2 to 9 m/s against 1.3 to 2.3 with the iteration.
    const int least = warm && share < WARM_SHARE_RENEWED ? 1 : 0;
    done = converged(error, largest) && least == 0;
    if (done) return 0;
    const int iterations = iterate(error, largest, done, least);
    parallel::forEach(
        0, n,
        [&](std::size_t i) {
        w[i] -= mDt * change[i];
        total[i] += k[i];
        },
        4096);
    return iterations;
}

} // namespace

std::size_t DfsphFactors::memoryBytes() const
{
    std::size_t bytes = (alpha.capacity() + liquidMass.capacity()) * sizeof(Real)
                        + (solidGradient.capacity() + wallHydrostatic.capacity()
                           + movingWallGravity.capacity())
                              * sizeof(Vec3)
                        + pairStart.capacity() * sizeof(std::size_t);
    for (const auto& c : pairGradient) bytes += c.capacity() * sizeof(Real);
    return bytes;
}

DfsphPressure::DfsphPressure(const GhostSettings& settings) : mOptions(settings.dfsph)
{
    mFactors.mirror = mOptions.wallPressure == DfsphSettings::WallPressure::Mirror;
    mFactors.wall = wallShare(mOptions);
    mFactors.minNeighbours = minimumNeighbours(settings.supportFactor);
}

std::vector<std::string> DfsphPressure::channels() const
{
    return {DENSITY_KAPPA, DIVERGENCE_KAPPA};
}

bool DfsphPressure::airFillsToRestDensity() const
{
    return mOptions.airDensity == DfsphSettings::AirDensity::Fill;
}

Real DfsphPressure::stableTimeStep(const GhostSettings& settings, Real fastest, Real) const
{
    return dfsphTimeStep(settings, fastest, settings.cflNumber);
}

std::size_t DfsphPressure::memoryBytes() const
{
    return mFactors.memoryBytes() + mScratch.capacity() * sizeof(Real);
}

Real DfsphPressure::airSpan(LiquidStep& step, Real dt) const
{
    if (mOptions.airResampling != DfsphSettings::AirResampling::Time) return 1;
    return step.settings().airResampleSpan(dt, Real(fastestLiquid(step)));
}

void DfsphPressure::prepareFactors(LiquidStep& step)
{
    const ParticleSet& set = step.particles();
    const std::size_t n = set.size();
    const auto& kind = set.kinds();
    const Real M = step.particleMass();
    DfsphFactors& f = mFactors;
    assignStepArray(f.alpha, n, Real(0));
    assignStepArray(f.solidGradient, n, Vec3(0));
    resizeStepArray(f.liquidMass, n);
    parallel::forEach(
        0, n,
        [&](std::size_t j) { f.liquidMass[j] = kind[j] == ParticleKind::Liquid ? M : Real(0); },
        4096);
    // Where each liquid particle's pairs start in pairGradient (a halo copy's too: the
    // gradient pass gives it G k), if they fit in the limit.
    std::size_t pairs = 0;
    if (mOptions.keepGradients) {
        resizeStepArray(f.pairStart, n + 1);
        for (std::size_t i = 0; i < n; ++i) {
            f.pairStart[i] = pairs;
            if (kind[i] == ParticleKind::Liquid) pairs += step.lists()[i].size();
        }
        f.pairStart[n] = pairs;
    }
    const double bytes = double(pairs) * (3 * sizeof(Real)) + double(n + 1) * sizeof(std::size_t);
    const bool keep = mOptions.keepGradients && bytes <= mOptions.keptGradientLimit;
    f.gradientsKept = keep;
    mStats.lastGradientBytes = mOptions.keepGradients ? bytes : 0;
    if (mOptions.keepGradients && !keep) ++mStats.recomputedSteps;
    if (!keep) {
        pairs = 0;
        std::vector<std::size_t>().swap(f.pairStart);
    }
    for (auto& c : f.pairGradient) {
        if (keep) resizeStepArray(c, pairs);
        else std::vector<Real>().swap(c);
    }
    if (f.mirror) assignStepArray(f.wallHydrostatic, n, Vec3(0));
    else std::vector<Vec3>().swap(f.wallHydrostatic);
}

void DfsphPressure::solidPairPressure(LiquidStep& step, SolidPairPressure& out) const
{
    // The step moved solved particle i by -dt G (k_density + k_divergence) and the walls'
    // known part: per solid pair, m_i M (c k_i + [mirror] g_s . (x_s - x_i) / rho0) grad W_is.
    const ParticleSet& set = step.particles();
    const auto& density = set.scalarChannel(DENSITY_KAPPA);
    const auto& divergence = set.scalarChannel(DIVERGENCE_KAPPA);
    out.liquid.resize(set.size());
    parallel::forEach(
        0, set.size(),
        [&](std::size_t i) {
        out.liquid[i] = mFactors.alpha[i] > Real(0) ? density[i] + divergence[i] : Real(0);
        },
        4096);
    out.share = mFactors.wall;
    out.solid = mFactors.mirror ? SolidPairPressure::SolidTerm::Mirror
                                : SolidPairPressure::SolidTerm::None;
    out.wallGravity = mFactors.movingWallGravity.empty() ? nullptr : &mFactors.movingWallGravity;
}

void DfsphPressure::computeMovingWallGravity(LiquidStep& step, Real dt)
{
    std::vector<Vec3>& gravity = mFactors.movingWallGravity;
    if (step.solids(LiquidStep::MOVING).empty() || !mFactors.mirror) {
        std::vector<Vec3>().swap(gravity);
        return;
    }
    // Each particle's acceleration over the step, from its velocity now and at the step's end.
    const double t0 = step.time();
    step.movingSolidVelocityChanges(t0, t0 + double(dt), gravity);
    const Vec3 g = step.settings().gravity;
    parallel::forEach(
        0, gravity.size(), [&](std::size_t s) { gravity[s] = g - gravity[s] / dt; }, 1024);
}

void DfsphPressure::applyWallHydrostatics(LiquidStep& step, Real dt)
{
    // The known part of the mirrored ghosts' pressure force (file comment), summed by the
    // factor pass over the solids of both blocks, on each solved particle. A halo copy has
    // alpha 0: its owner applies it.
    auto& w = step.particles().vectorChannel(VSTAR);
    parallel::forEach(
        0, step.particles().size(),
        [&](std::size_t i) {
        if (mFactors.alpha[i] > Real(0)) w[i] -= dt * mFactors.wallHydrostatic[i];
        },
        4096);
}

int DfsphPressure::solve(LiquidStep& step, Real dt, bool density, std::vector<Real>& total,
                         double& error, double& largest)
{
    DfsphSolve solve(step, mFactors, mOptions, dt, density);
    bool converged = false;
    const int iterations = solve.run(total, error, largest, converged);
    if (!converged) ++mStats.unconverged;
    return iterations;
}

/// The pressure reported, p = k rho^2 with k = k_density + k_divergence, is their Shepard
/// average over the liquid and the air (at zero pressure): a pressure solve on SPH gradients
/// determines k only up to the particle-scale patterns that G cannot see, which change no
/// velocity but scatter single particles' k by tens of percent of the hydrostatic pressure
/// (measured: +98 % on a tank's slope at 2 cm, 0.5 % after averaging). Each ghost solid takes
/// the pressure of its nearest liquid particle, as in the Tait step.
void DfsphPressure::reportPressure(LiquidStep& step)
{
    ParticleSet& set = step.particles();
    const std::size_t n = set.size();
    const auto& kind = set.kinds();
    const auto& rho = set.densities();
    const auto& x = set.positions();
    const auto& m = set.masses();
    const auto& kappaDensity = set.scalarChannel(DENSITY_KAPPA);
    const auto& kappaDivergence = set.scalarChannel(DIVERGENCE_KAPPA);
    const NeighborLists& lists = step.lists();
    auto& p = set.pressures();
    resizeStepArray(mScratch, n);
    parallel::forEach(
        0, n,
        [&](std::size_t i) {
        mScratch[i] =
            kind[i] == ParticleKind::Liquid ? kappaDensity[i] + kappaDivergence[i] : Real(0);
        },
        4096);
    forRangeWithBatch(
        n, step.kernel(),
        [&](std::size_t lo, std::size_t hi, const CubicSplineKernel& kernel, PairBatch& batch) {
        for (std::size_t i = lo; i < hi; ++i) {
            if (kind[i] != ParticleKind::Liquid) {
                p[i] = 0;
                continue;
            }
            Real weight = 0, sum = 0;
            batch.forEachBatch(x[i], x.data(), lists[i], [&](PairBatch& b) {
                for (int c = 0; c < b.n; ++c) b.f[c] = m[b.j[c]] / rho[b.j[c]] * kernel.W(b.r[c]);
                weight += b.sum(b.f);
                for (int c = 0; c < b.n; ++c) b.f[c] *= mScratch[b.j[c]];
                sum += b.sum(b.f);
            });
            p[i] = (weight > Real(0) ? sum / weight : mScratch[i]) * sqr(rho[i]);
        }
        },
        512);
    // The solids near the cut take the pressure of a halo copy as their nearest liquid.
    if (step.exchange()) step.exchange()->refresh(set, {"pressure"});
    step.pressureToSolids();
}

void DfsphPressure::recordSolves(int densityIterations, int divergenceIterations,
                                 double densityError, double divergenceError, double densityPeak,
                                 double divergencePeak)
{
    ++mStats.steps;
    mStats.densityIterations += std::uint64_t(densityIterations);
    mStats.divergenceIterations += std::uint64_t(divergenceIterations);
    mStats.lastDensityIterations = densityIterations;
    mStats.lastDivergenceIterations = divergenceIterations;
    mStats.lastDensityError = densityError;
    mStats.lastDivergenceError = divergenceError;
    mStats.lastLargestDensityError = densityPeak;
    mStats.lastLargestDivergenceError = divergencePeak;
    mStats.largestDensityError = std::max(mStats.largestDensityError, densityPeak);
    mStats.largestDivergenceError = std::max(mStats.largestDivergenceError, divergencePeak);
}

void DfsphPressure::solveStep(LiquidStep& step, Real dt)
{
    ParticleSet& set = step.particles();
    const std::size_t n = set.size();
    if (step.exchange()) {
        // What the solves hand to the halo copies (removed again at the end of the step).
        set.addScalarChannel(DFSPH_SYNC, Real(0));
        set.addVectorChannel(DFSPH_SYNC_VECTOR, Vec3(0));
    }
    const auto& v = set.velocities();
    auto& w = set.vectorChannel(VSTAR);

    // The divergence solve: the velocities the last step left, made divergence-free at the
    // positions they led to.
    parallel::forEach(
        0, n, [&](std::size_t i) { w[i] = v[i]; }, 4096);
    double divergenceError = 0, divergencePeak = 0;
    const int divergenceIterations = solve(step, dt, false, set.scalarChannel(DIVERGENCE_KAPPA),
                                           divergenceError, divergencePeak);

    // Lines 11-14 with the implicit pressure: v* = v + dt g for liquid and air (air falls with
    // the liquid it surrounds), then the constant-density solve on v*.
    const Vec3 g = step.settings().gravity;
    parallel::forEach(
        0, n, [&](std::size_t i) { w[i] += dt * g; }, 4096);
    if (mFactors.mirror) applyWallHydrostatics(step, dt);
    // The other non-pressure forces, before the density solve ([BK15] Algorithm 1).
    step.applySurfaceTension(dt);
    step.applyViscosity(dt);
    double densityError = 0, densityPeak = 0;
    const int densityIterations = solve(step, dt, true, set.scalarChannel(DENSITY_KAPPA),
                                        densityError, densityPeak);

    // The pressure terms of both solves act on the velocities (dt G (k_density +
    // k_divergence) a step). The pressure's acceleration does not bound the next step
    // (dfsphTimeStep): gravity alone counts.
    step.setMaxAcceleration(0);
    if (step.exchange()) {
        // The halo copies' v* (XSPH reads it) and pressure terms (the reported pressure).
        step.exchange()->refresh(set, {VSTAR, DENSITY_KAPPA, DIVERGENCE_KAPPA});
        set.removeChannel(DFSPH_SYNC);
        set.removeChannel(DFSPH_SYNC_VECTOR);
    }
    // Only output and checkpoints read the pressure (the solves and forces use k): a frame's
    // inner steps skip its pass.
    if (step.reportsPressure()) reportPressure(step);
    recordSolves(densityIterations, divergenceIterations, densityError, divergenceError,
                 densityPeak, divergencePeak);
}

void DfsphPressure::step(LiquidStep& step, Real dt)
{
    // Line 1 and the density of lines 2-7, as in the Tait step, with step 1's factors found in
    // the density's pass.
    const bool shifting = step.settings().shifting() > Real(0);
    std::vector<Vec3> gradMass(shifting ? step.particles().size() : 0, Vec3(0));
    mFactors.gradMass = shifting ? &gradMass : nullptr;
    DensityPass pass;
    pass.airSpan = airSpan(step, dt);
    pass.factors = &mFactors;
    pass.beforeDensity = [&] {
        computeMovingWallGravity(step, dt);
        prepareFactors(step);
    };
    step.searchAndDensity(pass);
    const auto t0 = std::chrono::steady_clock::now();
    solveStep(step, dt);
    step.timings().pressureForce += secondsSince(t0);

    step.finish(dt, gradMass);
    mFactors.gradMass = nullptr;
}

} // namespace ghost
} // namespace ghostfx
