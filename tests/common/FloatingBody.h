/// @file   FloatingBody.h
/// @brief  Test helper: a still tank of water with a box body in it, for the dynamic-solid
///         tests (tests/ghost/test_rigid_bodies.cc).
#pragma once

#include "Shapes.h"

#include <ghostfx/ghost/GhostSolver.h>
#include <ghostfx/sph/LevelSetGrid.h>

#include <algorithm>
#include <memory>

namespace ghostfx {
namespace testing {

/// An open tank of inside [-a, a] x [0, top] x [-a, a] filled to `depth` with water, and a
/// box body of half-extents `half` (m) centred at `centre`, turned by `tilt` (rad) about z;
/// the water's level set leaves the body out.
struct FloatingBodyScene
{
    sph::Real a = sph::Real(0.2), top = sph::Real(0.4), depth = sph::Real(0.2);
    sph::Vec3 half{sph::Real(0.1), sph::Real(0.05), sph::Real(0.1)};
    sph::Vec3 centre{0, sph::Real(0.2), 0};
    double tilt = 0;

    /// The body's level set (at voxels of spacing / 2).
    sph::LevelSet body(sph::Real spacing) const
    {
        return sph::makeLevelSet(sph::levelSetFromSdf([this](const openvdb::Vec3d& x) {
            return boxDistance(x);
        }, bodyBounds(), spacing / 2), "box");
    }
    sph::LevelSet water(sph::Real spacing) const
    {
        const openvdb::Vec3d lo(-a, 0, -a), hi(a, depth, a);
        auto sdf = [&](const openvdb::Vec3d& x) {
            return std::max(sph::boxSignedDistance(x, lo, hi), -boxDistance(x));
        };
        return sph::makeLevelSet(
            sph::levelSetFromSdf(sdf, sph::Aabb{sph::Vec3(lo), sph::Vec3(hi)}, spacing / 2),
            "water");
    }
    sph::LevelSet tank(sph::Real spacing) const
    {
        return sph::makeLevelSet(openTankGrid(a, top, 4 * double(spacing), spacing / 2), "tank");
    }
    /// A solver with the tank, the body (dynamic with `spec`) and the water, in that order.
    std::unique_ptr<ghost::GhostSolver> solver(const ghost::GhostSettings& s,
                                               const ghost::DynamicSolid& spec) const
    {
        auto solver = std::make_unique<ghost::GhostSolver>(s);
        solver->addSolid(tank(s.spacing));
        solver->addDynamicSolid(body(s.spacing), spec);
        solver->addLiquid(water(s.spacing));
        return solver;
    }

private:
    double boxDistance(const openvdb::Vec3d& x) const
    {
        const double c = std::cos(tilt), sn = std::sin(tilt);
        const openvdb::Vec3d d = x - openvdb::Vec3d(centre);
        const openvdb::Vec3d local(c * d[0] + sn * d[1], -sn * d[0] + c * d[1], d[2]);
        return sph::boxSignedDistance(local, -openvdb::Vec3d(half), openvdb::Vec3d(half));
    }
    sph::Aabb bodyBounds() const
    {
        const sph::Real r = half.length() + sph::Real(0.02);
        return sph::Aabb{centre - sph::Vec3(r), centre + sph::Vec3(r)};
    }
};

} // namespace testing
} // namespace ghostfx
