/// @file   Shapes.h
/// @brief  Test helper: level sets the solver tests share.
#pragma once

#include <ghostfx/sph/LevelSetGrid.h>

#include <algorithm>

namespace ghostfx {
namespace testing {

/// Open-top box container: walls `wall` (m) thick around the inside [-a, a] x [0, top] x [-a, a],
/// at voxels of `voxel` (m).
inline openvdb::FloatGrid::Ptr openTankGrid(sph::Real a, sph::Real top, double wall,
                                            sph::Real voxel)
{
    const openvdb::Vec3d outerLo(-a - wall, -wall, -a - wall), outerHi(a + wall, top, a + wall);
    const openvdb::Vec3d innerLo(-a, 0, -a), innerHi(a, top + 1, a);
    auto sdf = [&](const openvdb::Vec3d& x) {
        return std::max(sph::boxSignedDistance(x, outerLo, outerHi),
                        -sph::boxSignedDistance(x, innerLo, innerHi));
    };
    const sph::Aabb bounds{sph::Vec3(outerLo), sph::Vec3(outerHi)};
    return sph::levelSetFromSdf(sdf, bounds, voxel);
}

/// Closed box container: walls `wall` (m) thick around the inside [lo, hi], at voxels of
/// `voxel` (m).
inline openvdb::FloatGrid::Ptr closedTankGrid(const sph::Vec3& lo, const sph::Vec3& hi, double wall,
                                              sph::Real voxel)
{
    const openvdb::Vec3d innerLo(lo), innerHi(hi);
    const openvdb::Vec3d outerLo = innerLo - openvdb::Vec3d(wall),
                         outerHi = innerHi + openvdb::Vec3d(wall);
    auto sdf = [&](const openvdb::Vec3d& x) {
        return std::max(sph::boxSignedDistance(x, outerLo, outerHi),
                        -sph::boxSignedDistance(x, innerLo, innerHi));
    };
    const sph::Aabb bounds{sph::Vec3(outerLo), sph::Vec3(outerHi)};
    return sph::levelSetFromSdf(sdf, bounds, voxel);
}

/// An upside-down cup: a ceiling at y = 0 with side walls 4 cm thick around
/// [-0.06, 0.06]^2 reaching down to y = -0.1, open at the bottom, at voxels of spacing / 2.
inline openvdb::FloatGrid::Ptr invertedCupGrid(sph::Real spacing)
{
    using sph::Real;
    const double a = 0.06, wall = 0.04;
    auto sdf = [&](const openvdb::Vec3d& x) {
        const double outside =
            sph::boxSignedDistance(x, {-a - wall, -0.1, -a - wall}, {a + wall, wall, a + wall});
        return std::max(outside, -sph::boxSignedDistance(x, {-a, -1.0, -a}, {a, 0.0, a}));
    };
    return sph::levelSetFromSdf(sdf,
                                sph::Aabb{sph::Vec3(Real(-a - wall), Real(-0.1), Real(-a - wall)),
                                          sph::Vec3(Real(a + wall), Real(wall), Real(a + wall))},
                                spacing / 2);
}

/// The liquid of the cohesion tests: a 4 cm slab filling the top of invertedCupGrid (its
/// ceiling at y = 0, its walls at |x|, |z| = 6 cm), at voxels of half the spacing.
inline openvdb::FloatGrid::Ptr ceilingSlabGrid(sph::Real spacing)
{
    // (float literals, as the tests had them: the same slab in the double build)
    return sph::makeBoxLevelSet(sph::Vec3(-0.06f, -0.04f, -0.06f), sph::Vec3(0.06f, 0, 0.06f),
                                spacing / 2);
}

} // namespace testing
} // namespace ghostfx
