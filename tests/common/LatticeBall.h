/// @file   LatticeBall.h
/// @brief  Test helper: a ball of particle positions on a cubic lattice, as the frame-piece
///         tests (one process and several ranks) put one on their liquid.
#pragma once

#include <ghostfx/sph/Types.h>

#include <vector>

namespace ghostfx {
namespace testing {

/// Append to `x` every lattice point centre + (i, j, k) h with |i|, |j|, |k| <= `reach` that
/// lies closer than `radius` (m) to `centre`: a ball on a lattice of spacing `h` (m).
inline void addLatticeBall(std::vector<sph::Vec3>& x, const sph::Vec3& centre, sph::Real h,
                           int reach, double radius)
{
    for (int i = -reach; i <= reach; ++i)
        for (int j = -reach; j <= reach; ++j)
            for (int k = -reach; k <= reach; ++k) {
                const sph::Vec3 p =
                    centre + sph::Vec3(sph::Real(i), sph::Real(j), sph::Real(k)) * h;
                if ((p - centre).length() < radius) x.push_back(p);
            }
}

} // namespace testing
} // namespace ghostfx
