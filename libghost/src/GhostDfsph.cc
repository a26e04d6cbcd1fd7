/// @file   GhostDfsph.cc
/// @brief  Ghost SPH with an implicit pressure: the divergence-free SPH solves of Bender and
///         Koschier ([BK15] "Divergence-Free Smoothed Particle Hydrodynamics", SCA 2015;
///         [BK17] the TVCG 2017 version) over [SB12]'s ghost air and ghost solids.
/// @details One step, with one neighbour search (the lists of GhostStep.cc):
///           1. density (Eq. 1, every kind of neighbour) and the factor alpha_i of each liquid
///              particle, keeping each liquid pair's m_j grad W_ij for the solves' passes
///              (DfsphSettings::keepGradients; the positions do not move until step 4), all
///              in one pass over the pairs (GhostSolver::computeDensity);
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
#include "ghostfx/ghost/GhostSolver.h"

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
/// once (see solvePressure). Measured on the column tank at CFL 0.1, 30 frames: 0.8, 0.9 and
/// 0.95 all keep its fastest particles at 1.3 to 2.3 m/s; 0.5 let one reach 83 m/s by frame 16;
/// at 0.9 the still tank's solves never fall below it (the hydrostatic pressure fits whole).
constexpr Real WARM_SHARE_RENEWED = Real(0.9);

} // namespace

void GhostSolver::prepareDfsphFactors()
{
    const std::size_t n = mParticles.size();
    const auto& kind = mParticles.kinds();
    const Real M = mMass;
    assignStepArray(mAlpha, n, Real(0));
    assignStepArray(mSolidGradient, n, Vec3(0));
    resizeStepArray(mLiquidMass, n);
    parallel::forEach(
        0, n,
        [&](std::size_t j) { mLiquidMass[j] = kind[j] == ParticleKind::Liquid ? M : Real(0); },
        4096);
    // Where each liquid particle's pairs start in mPairGradient (a halo copy's too: the
    // gradient pass gives it G k), if they fit in the limit.
    const DfsphSettings& opt = mSettings.dfsph;
    std::size_t pairs = 0;
    if (opt.keepGradients) {
        resizeStepArray(mPairStart, n + 1);
        for (std::size_t i = 0; i < n; ++i) {
            mPairStart[i] = pairs;
            if (kind[i] == ParticleKind::Liquid) pairs += mFluidLists[i].size();
        }
        mPairStart[n] = pairs;
    }
    const double bytes = double(pairs) * (3 * sizeof(Real)) + double(n + 1) * sizeof(std::size_t);
    const bool keep = opt.keepGradients && bytes <= opt.keptGradientLimit;
    mGradientsKept = keep;
    mSolveStats.lastGradientBytes = opt.keepGradients ? bytes : 0;
    if (opt.keepGradients && !keep) ++mSolveStats.recomputedSteps;
    if (!keep) {
        pairs = 0;
        std::vector<std::size_t>().swap(mPairStart);
    }
    for (auto& c : mPairGradient) {
        if (keep) resizeStepArray(c, pairs);
        else std::vector<Real>().swap(c);
    }
    if (opt.wallPressure == DfsphSettings::WallPressure::Mirror) {
        assignStepArray(mWallHydrostatic, n, Vec3(0));
    } else {
        std::vector<Vec3>().swap(mWallHydrostatic);
    }
}

int GhostSolver::solvePressure(Real dt, bool density, std::vector<Real>& total, double& error,
                               double& largest)
{
    const std::size_t n = mParticles.size();
    const auto& x = mParticles.positions();
    const auto& rho = mParticles.densities();
    auto& w = mParticles.vectorChannel(VSTAR);
    const Real M = mMass, rho0 = mSettings.restDensity;
    const DfsphSettings& opt = mSettings.dfsph;
    const double limit = double(density ? opt.densityError : opt.divergenceError);
    // The relaxation is a share per step of the length CFL 0.4 would take; a shorter step takes
    // a share in proportion (DfsphSettings::densityRelaxation).
    Real scale = 1;
    if (density) {
        const auto& v = mParticles.velocities();
        const auto& kinds = mParticles.kinds();
        const Real* copies = haloFlags();
        double fastest = parallel::maximum(0, n, [&](std::size_t i) {
            return kinds[i] == ParticleKind::Liquid && (!copies || copies[i] == Real(0))
                       ? double(v[i].length())
                       : 0.0;
        });
        if (mExchange) fastest = mExchange->maxOf(fastest);
        const Real reference =
            dfsphTimeStep(mSettings, Real(fastest), DfsphSettings::RELAXATION_CFL);
        scale = std::min(Real(1), dt / reference);
    }
    const Real beta = density ? opt.densityRelaxation * scale : Real(0);
    // The particles in the solve: liquid that is not spray.
    auto solved = [&](std::size_t i) { return mAlpha[i] > Real(0); };
    const std::vector<Real>& lm = mLiquidMass;
    // Over several processes: sums over every process, and the owners' values for the halo
    // copies (a solve's vectors are this process's; DFSPH_SYNC carries them).
    const Real* halo = haloFlags();
    auto everywhere = [&](double value) { return mExchange ? mExchange->sumOf(value) : value; };
    auto fromOwners = [&](std::vector<Real>& values) {
        if (!mExchange) return;
        auto& channel = mParticles.scalarChannel(DFSPH_SYNC);
        std::copy(values.begin(), values.end(), channel.begin());
        mExchange->refresh(mParticles, {DFSPH_SYNC});
        for (std::size_t i = 0; i < n; ++i) {
            if (halo[i] != Real(0)) values[i] = channel[i];
        }
    };
    auto velocitiesFromOwners = [&] {
        if (mExchange) mExchange->refresh(mParticles, {VSTAR});
    };

    // G k (see the file comment), zero for air and spray.
    std::vector<Vec3> u(n, Vec3(0));
    // m_j grad W_ij of the liquid's pairs, when kept (the factor pass, computeDensity); else
    // each pass evaluates the kernel at the gathered positions.
    const bool kept = mGradientsKept;
    const Real* gx = mPairGradient[0].data();
    const Real* gy = mPairGradient[1].data();
    const Real* gz = mPairGradient[2].data();
    // Each pass is instantiated once for kept and once for recomputed gradients (a task body
    // holding both lost the recomputing loops' inlining: 7-13 % slower column tank).
    auto either = [&](auto&& pass) {
        if (kept) pass(std::true_type());
        else pass(std::false_type());
    };
    auto gradient = [&](const std::vector<Real>& k) {
        either([&](auto keep) {
            forRangeWithBatch(
                n, mKernel,
                [&](std::size_t lo, std::size_t hi, const CubicSplineKernel& kernel,
                    PairBatch& batch) {
                for (std::size_t i = lo; i < hi; ++i) {
                    if (lm[i] == Real(0)) continue;
                    const Real ki = k[i];
                    Vec3 sum(0);
                    if constexpr (decltype(keep)::value) {
                        const std::size_t at = mPairStart[i];
                        batch.forEachIndexBatch(mFluidLists[i],
                                                [&](PairBatch& b, std::size_t first) {
                            for (int c = 0; c < b.n; ++c) b.f[c] = ki + k[b.j[c]];
                            sum +=
                                b.sumScaled(b.f, gx + at + first, gy + at + first, gz + at + first);
                        });
                    } else {
                        batch.forEachBatch(x[i], x.data(), mFluidLists[i], [&](PairBatch& b) {
                            for (int c = 0; c < b.n; ++c) b.f[c] = lm[b.j[c]] * (ki + k[b.j[c]]);
                            for (int c = 0; c < b.n; ++c) b.f[c] *= kernel.gradFactor(b.r[c]);
                            sum += b.sumScaledOffsets(b.f);
                        });
                    }
                    // The solids' part, k_i sum_s M grad W_is, from the step's sum.
                    u[i] = sum + ki * mSolidGradient[i];
                }
                },
                512);
        });
    };
    // D v for the solved particles: liquid velocities `vel`, solids at their own velocity
    // (`solidMoves`) or still.
    std::vector<Real> rate(n, Real(0));
    // c sum_s M (v_i - v_s) . grad W_is = v_i . (the step's solid gradient sum, c included) -
    // c times the moving block's sum_s M v_s . grad W_is (static solids have v_s = 0).
    const bool movingSolids = !mMoving.block.empty();
    const Real wall = wallShare(opt);
    const Vec3* movingV =
        movingSolids ? mMoving.block.particles().vectorChannel(SOLID_VELOCITY).data() : nullptr;
    auto divergence = [&](const std::vector<Vec3>& vel, bool solidMoves) {
        either([&](auto keep) {
            forRangeWithBatch(
                n, mKernel,
                [&](std::size_t lo, std::size_t hi, const CubicSplineKernel& kernel,
                    PairBatch& batch) {
                for (std::size_t i = lo; i < hi; ++i) {
                    if (!solved(i)) continue;
                    const Vec3 vi = vel[i];
                    Real sum = vi.dot(mSolidGradient[i]);
                    if constexpr (decltype(keep)::value) {
                        const std::size_t at = mPairStart[i];
                        batch.forEachIndexBatch(mFluidLists[i],
                                                [&](PairBatch& b, std::size_t first) {
                            sum += b.sumApproach(vel.data(), vi, gx + at + first, gy + at + first,
                                                 gz + at + first);
                        });
                    } else {
                        batch.forEachBatch(x[i], x.data(), mFluidLists[i], [&](PairBatch& b) {
                            for (int c = 0; c < b.n; ++c)
                                b.f[c] = lm[b.j[c]] * kernel.gradFactor(b.r[c]);
                            sum += b.sumScaledApproach(b.f, vel.data(), vi);
                        });
                    }
                    if (solidMoves && movingSolids) {
                        const ParticleSet& set = mMoving.block.particles();
                        batch.forEachBatch(x[i], set.positions().data(), mMoving.lists[i],
                                           [&](PairBatch& b) {
                            for (int c = 0; c < b.n; ++c) b.f[c] = M * kernel.gradFactor(b.r[c]);
                            sum += wall * b.sumScaledApproach(b.f, movingV, Vec3(0));
                        });
                    }
                    rate[i] = sum;
                }
                },
                512);
        });
    };
    // (Over the solved particles: a halo copy's entries are its owner's, not summed here.)
    auto dot = [&](const std::vector<Real>& a, const std::vector<Real>& b) {
        return everywhere(parallel::sum(
            0, n, [&](std::size_t i) { return solved(i) ? double(a[i]) * double(b[i]) : 0.0; }));
    };
    const double count =
        everywhere(parallel::sum(0, n, [&](std::size_t i) { return solved(i) ? 1.0 : 0.0; }));
    const Real dt2 = dt * dt;
    // Mean |e| / rho0 over the solved particles of residuals r = e / dt^2.
    auto meanError = [&](const std::vector<Real>& r) {
        const double sum = everywhere(parallel::sum(
            0, n, [&](std::size_t i) { return solved(i) ? double(std::abs(r[i])) : 0.0; }));
        return count > 0 ? sum * double(dt2) / count / double(rho0) : 0.0;
    };
    // Largest |e| / rho0 of one particle. The mean alone does not see a few particles in a
    // hundred thousand: in SPlisHSPlasH's dam break at 100k, a handful beside the floor were
    // squeezed from 1.3 to 2.7 rho0 over ten steps in which the mean stayed under its limit
    // and no iteration ran (bench/history/diary-2026-11.md, "DFSPH: a peak limit";
    // DfsphSettings::PEAK_FACTOR).
    auto largestError = [&](const std::vector<Real>& r) {
        const double m = parallel::maximum(
            0, n, [&](std::size_t i) { return solved(i) ? double(std::abs(r[i])) : 0.0; });
        return (mExchange ? mExchange->maxOf(m) : m) * double(dt2) / double(rho0);
    };
    const double peakLimit = DfsphSettings::PEAK_FACTOR * limit;
    auto converged = [&](double mean, const std::vector<Real>& r) {
        largest = largestError(r);
        return mean <= limit && largest <= peakLimit;
    };

    std::vector<Real> k(n, Real(0)), r(n, Real(0)), z(n, Real(0)), p(n, Real(0)), q(n, Real(0));
    std::vector<Vec3> change(n, Vec3(0)); // G k
    // u = G values, with the halo copies' from their owners.
    auto gradientEverywhere = [&](std::vector<Real>& values) {
        fromOwners(values);
        gradient(values);
        if (!mExchange) return;
        auto& channel = mParticles.vectorChannel(DFSPH_SYNC_VECTOR);
        std::copy(u.begin(), u.end(), channel.begin());
        mExchange->refresh(mParticles, {DFSPH_SYNC_VECTOR});
        for (std::size_t i = 0; i < n; ++i) {
            if (halo[i] != Real(0)) u[i] = channel[i];
        }
    };
    // q = D u for the solved particles (solids held still).
    auto divergenceOfChange = [&] {
        divergence(u, false);
        parallel::forEach(
            0, n, [&](std::size_t i) { q[i] = solved(i) ? rate[i] : Real(0); }, 4096);
    };
    // r: the error the velocities w leave, beta (rho - rho0) + dt D rho / Dt for the density
    // solve, dt D rho / Dt for the divergence solve (over dt^2).
    auto residual = [&] {
        velocitiesFromOwners();
        divergence(w, true);
        parallel::forEach(
            0, n,
            [&](std::size_t i) {
            if (solved(i)) r[i] = (beta * (rho[i] - rho0) + dt * rate[i]) / dt2;
            },
            4096);
    };

    // Warm start: the last step's pressure terms first ([BK15] Sec. 4.3). Nothing to apply on
    // the first step, or after a restart from rest.
    const bool startWarm = opt.warmStart && (density || opt.divergenceWarmStart);
    const bool warm = startWarm && everywhere(parallel::sum(0, n, [&](std::size_t i) {
                                       return solved(i) && total[i] != Real(0) ? 1.0 : 0.0;
                                   })) > 0;
    // The density solve applies the share s of the last pressure that best fits this step,
    // the s in [0, 1] minimising the error left in the norm of D G:
    //     s = (k . r) / (k . D G k),
    // a line search along the last pressure before the conjugate gradients start. The solve's
    // limit is on one step's density change, which shrinks with the step while a pressure's
    // force does not: applied whole, a last pressure that no longer fits (after an impact) is
    // a force that small steps find "converged" and apply again, step after step, with no
    // iteration to renew it, until the liquid runs away (CFL 0.1: 22 m/s within 0.06 s in
    // Dfsph.SmallCflStepsStayBounded). The divergence solve's last terms are applied whole: a
    // share fitted to each step's divergence there shook a still tank (interior speed 0.17 ->
    // 0.35 m/s), and whole they do not run away. Where less than WARM_SHARE_RENEWED of the
    // last pressure fits, the solve iterates at least once whatever its limit says: the share
    // alone bounds the run-away but leaves local misfits (a global s is set by the bulk) that
    // at CFL 0.1 kept the column tank's fastest particles at 2 to 9 m/s against 1.3 to 2.3
    // with the iteration. Measured: bench/history/diary-2026-11.md, "DFSPH at small steps".
    Real share = 1;
    bool residualKnown = false;
    if (warm) {
        parallel::forEach(
            0, n, [&](std::size_t i) { k[i] = solved(i) ? total[i] : Real(0); }, 4096);
        // (The halo copies' G k only where D G k is summed below.)
        if (density && movingSolids) gradientEverywhere(k);
        else {
            fromOwners(k);
            gradient(k);
        }
        if (density && movingSolids) {
            // D counts the moving solids' velocities: the sums below do not, so r and D G k
            // are found as they are, with one more pass.
            residual();
            divergenceOfChange();
            const double kq = dot(k, q);
            share = kq > 0 ? Real(std::clamp(dot(k, r) / kq, 0.0, 1.0)) : Real(0);
            parallel::forEach(
                0, n, [&](std::size_t i) { r[i] -= share * q[i]; }, 4096);
            residualKnown = true;
        } else if (density) {
            // With the solids still, k . D u = u . G k over the liquid (D G symmetric, see the
            // file comment): k . D G k = |G k|^2 and k . r = k . beta (rho - rho0) / dt^2 +
            // w . G k / dt, so no pass beyond the gradient's.
            auto owned = [&](std::size_t i) {
                return lm[i] != Real(0) && (!halo || halo[i] == Real(0));
            };
            const double uu = everywhere(parallel::sum(
                0, n, [&](std::size_t i) { return owned(i) ? double(u[i].lengthSqr()) : 0.0; }));
            const double kr = everywhere(parallel::sum(0, n, [&](std::size_t i) {
                double term = owned(i) ? double(w[i].dot(u[i])) / double(dt) : 0.0;
                if (solved(i)) term += double(k[i]) * double(beta * (rho[i] - rho0)) / double(dt2);
                return term;
            }));
            share = uu > 0 ? Real(std::clamp(kr / uu, 0.0, 1.0)) : Real(0);
        }
        parallel::forEach(
            0, n, [&](std::size_t i) { w[i] -= dt * share * u[i]; }, 4096);
    }
    parallel::forEach(
        0, n,
        [&](std::size_t i) { total[i] = solved(i) && startWarm ? share * total[i] : Real(0); },
        4096);
    if (!residualKnown) residual();
    error = meanError(r);

    // Preconditioned conjugate gradients on D G k = r.
    std::fill(k.begin(), k.end(), Real(0));
    int iteration = 0;
    const int least = warm && share < WARM_SHARE_RENEWED ? 1 : 0;
    bool done = converged(error, r) && least == 0;
    if (!done) {
        parallel::forEach(
            0, n,
            [&](std::size_t i) {
            z[i] = mAlpha[i] * r[i];
            p[i] = z[i];
            },
            4096);
        double rz = dot(r, z);
        while (iteration < opt.maxIterations) {
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
            error = meanError(r);
            if (!std::isfinite(error)) {
                throw NumericalError(msg("liquid solver at frame ", mRun.frame, ", step ",
                                         mRun.step, " (t = ", mRun.time, " s): the DFSPH ",
                                         density ? "density" : "divergence",
                                         " solve gave a non-finite error at iteration ", iteration,
                                         "; reduce the time step (dfsph.max_dt, cfl)"));
            }
            done = converged(error, r) && iteration >= least;
            if (done) break;
            parallel::forEach(
                0, n, [&](std::size_t i) { z[i] = mAlpha[i] * r[i]; }, 4096);
            const double rzNext = dot(r, z);
            const Real direction = Real(rzNext / rz);
            rz = rzNext;
            parallel::forEach(
                0, n, [&](std::size_t i) { p[i] = z[i] + direction * p[i]; }, 4096);
        }
        parallel::forEach(
            0, n,
            [&](std::size_t i) {
            w[i] -= dt * change[i];
            total[i] += k[i];
            },
            4096);
    }
    if (!done) ++mSolveStats.unconverged;
    return iteration;
}

/// The pressure reported, p = k rho^2 with k = k_density + k_divergence, is their Shepard
/// average over the liquid and the air (at zero pressure): a pressure solve on SPH gradients
/// determines k only up to the particle-scale patterns that G cannot see, which change no
/// velocity but scatter single particles' k by tens of percent of the hydrostatic pressure
/// (measured: +98 % on a tank's slope at 2 cm, 0.5 % after averaging). Each ghost solid takes
/// the pressure of its nearest liquid particle, as in the Tait step.
void GhostSolver::reportDfsphPressure()
{
    const std::size_t n = mParticles.size();
    const auto& kind = mParticles.kinds();
    const auto& rho = mParticles.densities();
    const auto& x = mParticles.positions();
    const auto& m = mParticles.masses();
    const auto& kappaDensity = mParticles.scalarChannel(DENSITY_KAPPA);
    const auto& kappaDivergence = mParticles.scalarChannel(DIVERGENCE_KAPPA);
    auto& p = mParticles.pressures();
    resizeStepArray(mScratch, n);
    parallel::forEach(
        0, n,
        [&](std::size_t i) {
        mScratch[i] =
            kind[i] == ParticleKind::Liquid ? kappaDensity[i] + kappaDivergence[i] : Real(0);
        },
        4096);
    forRangeWithBatch(
        n, mKernel,
        [&](std::size_t lo, std::size_t hi, const CubicSplineKernel& kernel, PairBatch& batch) {
        for (std::size_t i = lo; i < hi; ++i) {
            if (kind[i] != ParticleKind::Liquid) {
                p[i] = 0;
                continue;
            }
            Real weight = 0, sum = 0;
            batch.forEachBatch(x[i], x.data(), mFluidLists[i], [&](PairBatch& b) {
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
    if (mExchange) mExchange->refresh(mParticles, {"pressure"});
    for (SolidBlock* b : {&mStatic, &mMoving}) {
        Real* pSolid = b->block.particles().pressures().data();
        forEachReachedSolid(*b, [&](Index s, Index j) { pSolid[s] = p[j]; });
    }
}

void GhostSolver::applyWallHydrostatics(Real dt)
{
    // The known part of the mirrored ghosts' pressure force (file comment), summed by the
    // factor pass (computeDensity) over the solids of both blocks, on each solved particle. A
    // halo copy has alpha 0: its owner applies it.
    auto& w = mParticles.vectorChannel(VSTAR);
    parallel::forEach(
        0, mParticles.size(),
        [&](std::size_t i) {
        if (mAlpha[i] > Real(0)) w[i] -= dt * mWallHydrostatic[i];
        },
        4096);
}

void GhostSolver::computeMovingWallGravity(Real dt)
{
    ParticleSet& set = mMoving.block.particles();
    if (set.empty() || mSettings.dfsph.wallPressure != DfsphSettings::WallPressure::Mirror) {
        std::vector<Vec3>().swap(mMovingWallGravity);
        return;
    }
    // Each particle's acceleration over the step, from its velocity now and at the step's end:
    // from the motions' rates where they give them, else MovingLevelSet::velocity's difference.
    const double t0 = mRun.time, t1 = t0 + double(dt);
    const std::vector<RigidTransform> now = sph::placementsAt(mSolids, t0);
    const std::vector<RigidTransform> next = sph::placementsAt(mSolids, t1);
    const auto& local = set.vectorChannel(SOLID_LOCAL);
    const auto& index = set.scalarChannel(SOLID_INDEX);
    const Vec3 g = mSettings.gravity;
    resizeStepArray(mMovingWallGravity, set.size());
    parallel::forEach(
        0, set.size(),
        [&](std::size_t s) {
        const std::size_t b = std::size_t(index[s]);
        const Vec3& q = local[s];
        const Vec3 change = now[b].hasRates && next[b].hasRates
                                ? next[b].translationRate - now[b].translationRate
                                      + (next[b].rotationRate - now[b].rotationRate) * q
                                : mSolids[b]->velocity(q, t1) - mSolids[b]->velocity(q, t0);
        mMovingWallGravity[s] = g - change / dt;
        },
        1024);
}

void GhostSolver::stepDfsph(Real dt)
{
    // Line 1 and the density of lines 2-7, as in the Tait step (GhostStep.cc), with step 1's
    // factors found in the density's pass.
    const bool shifting = mSettings.shifting() > Real(0);
    std::vector<Vec3> gradMass(shifting ? mParticles.size() : 0, Vec3(0));
    searchAndDensity(dt, true, shifting ? &gradMass : nullptr);

    const auto t0 = std::chrono::steady_clock::now();
    const std::size_t n = mParticles.size();
    if (mExchange) {
        // What the solves hand to the halo copies (removed again at the end of the step).
        mParticles.addScalarChannel(DFSPH_SYNC, Real(0));
        mParticles.addVectorChannel(DFSPH_SYNC_VECTOR, Vec3(0));
    }
    const auto& v = mParticles.velocities();
    auto& w = mParticles.vectorChannel(VSTAR);
    auto& kappaDensity = mParticles.scalarChannel(DENSITY_KAPPA);
    auto& kappaDivergence = mParticles.scalarChannel(DIVERGENCE_KAPPA);

    // The divergence solve: the velocities the last step left, made divergence-free at the
    // positions they led to.
    parallel::forEach(
        0, n, [&](std::size_t i) { w[i] = v[i]; }, 4096);
    double divergenceError = 0;
    double divergencePeak = 0;
    const int divergenceIterations =
        solvePressure(dt, false, kappaDivergence, divergenceError, divergencePeak);

    // Lines 11-14 with the implicit pressure: v* = v + dt g for liquid and air (air falls with
    // the liquid it surrounds), then the constant-density solve on v*.
    const Vec3 g = mSettings.gravity;
    parallel::forEach(
        0, n, [&](std::size_t i) { w[i] += dt * g; }, 4096);
    if (mSettings.dfsph.wallPressure == DfsphSettings::WallPressure::Mirror)
        applyWallHydrostatics(dt);
    double densityError = 0;
    double densityPeak = 0;
    const int densityIterations = solvePressure(dt, true, kappaDensity, densityError, densityPeak);

    // The pressure terms of both solves act on the velocities (dt G (k_density +
    // k_divergence) a step). The pressure's acceleration does not bound the next step
    // (dfsphTimeStep): gravity alone counts.
    mRun.maxAcceleration = 0;
    if (mExchange) {
        // The halo copies' v* (XSPH reads it) and pressure terms (the reported pressure).
        mExchange->refresh(mParticles, {VSTAR, DENSITY_KAPPA, DIVERGENCE_KAPPA});
        mParticles.removeChannel(DFSPH_SYNC);
        mParticles.removeChannel(DFSPH_SYNC_VECTOR);
    }
    // Only output and checkpoints read the pressure (the solves and forces use k): a frame's
    // inner steps skip its pass (advanceFrame, mReportPressure).
    if (mReportPressure) reportDfsphPressure();
    ++mSolveStats.steps;
    mSolveStats.densityIterations += std::uint64_t(densityIterations);
    mSolveStats.divergenceIterations += std::uint64_t(divergenceIterations);
    mSolveStats.lastDensityIterations = densityIterations;
    mSolveStats.lastDivergenceIterations = divergenceIterations;
    mSolveStats.lastDensityError = densityError;
    mSolveStats.lastDivergenceError = divergenceError;
    mSolveStats.lastLargestDensityError = densityPeak;
    mSolveStats.lastLargestDivergenceError = divergencePeak;
    mSolveStats.largestDensityError = std::max(mSolveStats.largestDensityError, densityPeak);
    mSolveStats.largestDivergenceError =
        std::max(mSolveStats.largestDivergenceError, divergencePeak);
    mTimings.pressureForce += secondsSince(t0);

    finishGhostStep(dt, gradMass);
}

} // namespace ghost
} // namespace ghostfx
