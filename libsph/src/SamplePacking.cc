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

} // namespace

void PoissonDiskSampler::pack(SampleSet& samples, const LevelSet& shape, int iterations) const
{
    packSome(samples, shape, iterations, {});
}

void PoissonDiskSampler::packSome(SampleSet& samples, const LevelSet& shape, int iterations,
                                  const std::vector<std::uint8_t>& movable) const
{
    const std::size_t n = samples.size();
    if (iterations <= 0 || n < 2) return;
    const Real r = mSettings.radius;
    const Real h = r / PoissonSettings::SB12_RADIUS_FACTOR;
    const CubicSplineKernel kernel(SUPPORT_SPACINGS * h);
    const Real support = kernel.supportRadius();
    const Real gain = STEP_GAIN * support * support * h * h * h;
    const Real maxMove = MAX_MOVE_RADII * r;
    const detail::DepthLimit band(samples, shape, mSettings.bandDepth, r);

    // Work on a copy in the grid's cell order, so that neighbours are near in memory; moves of
    // r / 5 per step keep it nearly sorted. The samples go back to their places at the end.
    NeighborGrid grid(support);
    grid.build(samples.positions);
    std::vector<Index> order = grid.order();
    if (order.empty()) {
        order.resize(n);
        for (std::size_t k = 0; k < n; ++k) order[k] = Index(k);
    }
    std::vector<Vec3> x(n), next(n);
    std::vector<std::uint8_t> surface(n), moves(n), keep(n);
    for (std::size_t k = 0; k < n; ++k) {
        x[k] = samples.positions[order[k]];
        surface[k] = samples.onSurface[order[k]];
        moves[k] = movable.empty() || movable[order[k]];
    }
    std::vector<SampleCache> cache(n);
    std::vector<Real> limit2(n);
    NeighborLists lists;

    // Where sample k would go: down the density gradient, within its constraints; x[k] itself
    // when it stays. Also sets limit2[k], the squared distance it must keep from the others.
    auto propose = [&](std::size_t k) {
        const Vec3 xk = x[k];
        Vec3 gradient(0);
        Real nearest2 = std::numeric_limits<Real>::max();
        lists[k].forEach([&](Index j) {
            if (j == Index(k)) return;
            const Vec3 xkj = xk - x[j];
            const Real r2 = xkj.lengthSqr();
            gradient += kernel.gradW(xkj, std::sqrt(r2));
            nearest2 = std::min(nearest2, r2);
        });
        limit2[k] = std::min(r * r, nearest2);
        Vec3 step = gradient * (-gain);
        SampleCache& c = cache[k];
        if (surface[k]) {
            if (!c.valid) {
                Vec3 g;
                shape.phiAndGradient(xk, g);
                const Real len = g.length();
                c.normal = len > Real(0) ? g / len : Vec3(0);
                c.valid = true;
            }
            step -= c.normal * step.dot(c.normal);
        }
        const Real length = step.length();
        if (!(length > Real(0))) return xk;
        if (length > maxMove) step *= maxMove / length;
        const Vec3 to = xk + step;
        if (surface[k]) {
            Vec3 g;
            const Real phi = shape.phiAndGradient(to, g);
            const SurfaceProjection proj = shape.projectToSurface(to, phi, g);
            if (!proj.converged || (proj.point - xk).lengthSqr() > Real(4) * maxMove * maxMove)
                return xk;
            return proj.point;
        }
        if (!c.valid) {
            c.phi = shape.phi(xk);
            c.valid = true;
        }
        // phi(to) where needed, looked up once.
        Real phiTo = 0;
        bool known = false;
        auto phiOfTo = [&] {
            if (!known) {
                phiTo = shape.phi(to);
                known = true;
            }
            return phiTo;
        };
        if (c.phi + LIPSCHITZ * maxMove >= Real(0) && !(phiOfTo() < Real(0))) return xk;
        if (band.limited() && !band.accepts(to, phiOfTo, c.bandHint)) return xk;
        return to;
    };

    // Whether k may move to next[k]: no closer than sqrt(limit2[k]) to any other sample, at its
    // old position or its new one. Any sample that could come that close is on k's list (see
    // MAX_MOVE_RADII).
    auto allowed = [&](std::size_t k) {
        const Vec3 to = next[k];
        bool ok = true;
        lists[k].forEach([&](Index j) {
            if (j != Index(k)
                && ((to - x[j]).lengthSqr() < limit2[k] || (to - next[j]).lengthSqr() < limit2[k]))
                ok = false;
        });
        return ok;
    };

    for (int step = 0; step < iterations; ++step) {
        grid.build(x);
        lists.build(grid, x.data(), n, support, moves.data());
        parallel::forEach(
            0, n, [&](std::size_t k) { next[k] = moves[k] ? propose(k) : x[k]; }, 256);
        parallel::forEach(
            0, n, [&](std::size_t k) { keep[k] = next[k] != x[k] && allowed(k); }, 256);
        for (std::size_t k = 0; k < n; ++k) {
            if (!keep[k]) continue;
            x[k] = next[k];
            cache[k].valid = false;
        }
    }
    for (std::size_t k = 0; k < n; ++k) samples.positions[order[k]] = x[k];
}

} // namespace sph
} // namespace ghostfx
