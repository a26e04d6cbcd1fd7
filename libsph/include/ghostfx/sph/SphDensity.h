/// @file   SphDensity.h
/// @brief  SPH density summation ([SB12] Eq. 1) and the initial mass scaling of [SB12] Sec. 4.6.
#pragma once

#include "ghostfx/sph/Kernels.h"
#include "ghostfx/sph/NeighborGrid.h"
#include "ghostfx/sph/Parallel.h"
#include "ghostfx/sph/Types.h"

#include <cstdint>
#include <vector>

namespace ghostfx {
namespace sph {

/// rho_i = sum_j m_j W(x_i - x_j) over all particles ([SB12] Eq. 1). `grid` must be built on
/// `positions` with a cell size >= the kernel's support radius.
template <typename Kernel>
std::vector<Real> densitySum(const std::vector<Vec3>& positions, const std::vector<Real>& masses,
                             const NeighborGrid& grid, const Kernel& kernel)
{
    std::vector<Real> rho(positions.size(), Real(0));
    parallel::forEach(0, positions.size(), [&](std::size_t i) {
        Real sum = 0;
        grid.forEachNeighbor(Index(i),
                             [&](Index j, const Vec3&, Real r) { sum += masses[j] * kernel.W(r); });
        rho[i] = sum;
    });
    return rho;
}

/// [SB12] Sec. 4.6: the particle mass that makes the mean SPH density of the particles selected
/// by `measure` (all when empty) equal `restDensity` (kg/m^3): m = rho0 / mean_i(sum_j W_ij).
/// Throws ValueError when no particle is selected or the density sum is zero.
template <typename Kernel>
Real massForRestDensity(const std::vector<Vec3>& positions, const Kernel& kernel, Real restDensity,
                        const std::vector<std::uint8_t>& measure = {})
{
    NeighborGrid grid(kernel.supportRadius());
    grid.build(positions);
    const bool all = measure.empty();
    // Sums for the measured particles only: a liquid's solver measures its liquid among all the
    // ghosts, and a tank's ghost solids can outnumber the liquid several times.
    std::vector<Real> rho(positions.size(), Real(0));
    parallel::forEach(0, positions.size(), [&](std::size_t i) {
        if (!all && !measure[i]) return;
        Real sum = 0;
        grid.forEachNeighbor(Index(i), [&](Index, const Vec3&, Real r) { sum += kernel.W(r); });
        rho[i] = sum;
    });
    const double total = parallel::sum(
        0, rho.size(), [&](std::size_t i) { return all || measure[i] ? double(rho[i]) : 0.0; });
    const double count =
        parallel::sum(0, rho.size(), [&](std::size_t i) { return all || measure[i] ? 1.0 : 0.0; });
    if (!(count > 0.0) || !(total > 0.0)) {
        throw ValueError(msg("mass for rest density: no particle to measure (", count,
                             " selected of ", positions.size(), ")"));
    }
    return Real(double(restDensity) * count / total);
}

} // namespace sph
} // namespace ghostfx
