/// @file   GasPairs.h
/// @brief  Pair helpers shared by the gas solver's passes and parts (libgas internal).
/// @details Pair sums use the symmetric support (h_i + h_j) / 2 ([RYY15] with a variable
///          smoothing length, GasSolver.h), walk a particle's neighbour list in its fixed order
///          and accumulate in double, so a sum does not depend on the thread count.
#pragma once

#include <ghostfx/sph/NeighborLists.h>
#include <ghostfx/sph/Types.h>

#include <vector>

namespace ghostfx {
namespace gas {
namespace detail {

using sph::Index;
using sph::NeighborLists;
using sph::Real;
using sph::Vec3;
using sph::Vec3d;

/// Add a Real vector to a double-precision sum.
inline void accumulate(Vec3d& sum, const Vec3& v) { sum += Vec3d(v[0], v[1], v[2]); }

/// Pair support radius: symmetric in i and j, so every pair term is antisymmetric.
inline Real pairSupport(Real hi, Real hj) { return Real(0.5) * (hi + hj); }

/// Call fn(j, x_i - x_j, r) for each entry j of particle i's neighbour list (i itself included,
/// at r = 0), in the list's fixed order.
template <typename Fn>
inline void forEachListed(const NeighborLists& lists, const std::vector<Vec3>& x, std::size_t i,
                          Fn&& fn)
{
    const Vec3 xi = x[i];
    lists[i].forEach([&](Index j) {
        const Vec3 xij = xi - x[j];
        fn(j, xij, xij.length());
    });
}

} // namespace detail
} // namespace gas
} // namespace ghostfx
