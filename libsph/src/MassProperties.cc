/// @file   MassProperties.cc
/// @brief  massProperties: the voxel sums MassProperties.h describes.
#include <ghostfx/sph/MassProperties.h>

#include <ghostfx/sph/Exceptions.h>
#include <ghostfx/sph/LevelSetGrid.h>

#include <openvdb/openvdb.h>

#include <algorithm>
#include <cmath>

namespace ghostfx {
namespace sph {
namespace {

/// Raw moments of the inside: volume, first moments and second moments (sum of v x x^T, each
/// cell's own second moment side^2 / 12 per axis included).
struct Moments
{
    double volume = 0;
    openvdb::math::Vec3d first{0.0};
    openvdb::math::Mat3d second = openvdb::math::Mat3d::zero();

    /// A cube of `side` at `x`, the `fraction` of it inside.
    void add(const openvdb::math::Vec3d& x, double side, double fraction = 1)
    {
        const double v = fraction * side * side * side;
        volume += v;
        first += v * x;
        for (int r = 0; r < 3; ++r) {
            for (int c = 0; c < 3; ++c) second(r, c) += v * x[r] * x[c];
            second(r, r) += v * side * side / 12;
        }
    }
};

/// Sub-cells per axis of a voxel the surface may cross.
constexpr int SUB = 4;

Moments insideMoments(const LevelSet& shape, const openvdb::FloatGrid& grid)
{
    const double dx = grid.voxelSize()[0];
    openvdb::CoordBBox box = grid.evalActiveVoxelBoundingBox();
    box.expand(1);
    auto acc = grid.getConstAccessor();
    Moments m;
    for (auto ijk = box.begin(); ijk; ++ijk) {
        const double phi = acc.getValue(*ijk);
        const openvdb::math::Vec3d x = grid.indexToWorld(*ijk);
        if (phi <= -dx) {
            m.add(x, dx); // the whole voxel is inside (phi is a distance)
            continue;
        }
        if (phi >= dx) continue;
        const double sub = dx / SUB;
        for (int i = 0; i < SUB; ++i) {
            for (int j = 0; j < SUB; ++j) {
                for (int k = 0; k < SUB; ++k) {
                    const openvdb::math::Vec3d y =
                        x + sub * openvdb::math::Vec3d(i + 0.5, j + 0.5, k + 0.5) - 0.5 * dx;
                    const double f = 0.5 - double(shape.phi(Vec3(y))) / sub;
                    if (f > 0) m.add(y, sub, std::min(f, 1.0));
                }
            }
        }
    }
    return m;
}

} // namespace

MassProperties massProperties(const LevelSet& shape, double density)
{
    if (!(density > 0) || !std::isfinite(density)) {
        throw ValueError(msg("level set '", shape.name(), "': density = ", density,
                             ": expected a number > 0 (kg/m^3)"));
    }
    const openvdb::FloatGrid& grid = *gridOf(shape);
    const Moments m = insideMoments(shape, grid);
    if (!(m.volume > 0)) {
        throw ValueError(msg("level set '", shape.name(), "': has no inside to give a mass"));
    }
    MassProperties p;
    p.volume = m.volume;
    p.mass = density * m.volume;
    p.centre = m.first / m.volume;
    // Second moments about the centre, S = sum v x x^T - V c c^T; I = rho (trace(S) E - S).
    openvdb::math::Mat3d s = m.second;
    for (int r = 0; r < 3; ++r) {
        for (int c = 0; c < 3; ++c) s(r, c) -= m.volume * p.centre[r] * p.centre[c];
    }
    const double trace = s(0, 0) + s(1, 1) + s(2, 2);
    for (int r = 0; r < 3; ++r) {
        for (int c = 0; c < 3; ++c) p.inertia(r, c) = density * ((r == c ? trace : 0) - s(r, c));
    }
    return p;
}

} // namespace sph
} // namespace ghostfx
