/// @file   RenderEstimates.cc
#include "ghostfx/sph/RenderEstimates.h"

#include "ghostfx/sph/Exceptions.h"
#include "ghostfx/sph/Kernels.h"
#include "ghostfx/sph/NeighborGrid.h"
#include "ghostfx/sph/Parallel.h"

#include <openvdb/math/Mat3.h>

#include <cmath>

namespace ghostfx {
namespace sph {

namespace {

using Mat3d = openvdb::math::Mat3d;

/// det(L_i) below which L_i is not inverted. L_i is the identity for a full neighbourhood and
/// keeps about half of it in the normal direction at a free surface (det about 1/2); 0.01 is
/// an eigenvalue product of about 0.2^3, a neighbourhood that is little more than a plane.
constexpr double MIN_CORRECTION_DETERMINANT = 0.01;

/// Neighbours of one kind, in a grid of their own (indices into `members`).
struct KindNeighbours
{
    std::vector<Index> members; ///< particle index of grid entry j
    NeighborGrid grid;

    KindNeighbours(const ParticleSet& p, ParticleKind kind, Real supportRadius)
        : grid(supportRadius)
    {
        std::vector<Vec3> x;
        for (std::size_t i = 0; i < p.size(); ++i) {
            if (p.kinds()[i] != kind) continue;
            members.push_back(Index(i));
            x.push_back(p.positions()[i]);
        }
        grid.build(x);
    }
};

void checkSettings(const EstimateSettings& s, const char* what)
{
    if (!(s.supportRadius > Real(0)) || !std::isfinite(s.supportRadius)
        || !(s.restDensity > Real(0)) || !std::isfinite(s.restDensity)) {
        throw ValueError(msg(what, ": support radius ", s.supportRadius, " m, rest density ",
                             s.restDensity, " kg/m^3: expected both finite and > 0"));
    }
}

Mat3d outer(const Vec3d& a, const Vec3d& b)
{
    Mat3d m;
    for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 3; ++c) m(r, c) = a[r] * b[c];
    return m;
}

/// The velocity gradient J_ab = dv_a / dx_b at x_i (1/s), corrected where L_i allows.
Mat3d velocityGradient(const ParticleSet& p, Index i, const KindNeighbours& near,
                       const CubicSplineKernel& kernel, double rho0)
{
    Mat3d L = Mat3d::zero(), G = Mat3d::zero();
    const Vec3d vi(p.velocities()[i]);
    near.grid.forEachInRadius(p.positions()[i], kernel.supportRadius(),
                              [&](Index k, const Vec3& xij, Real rij) {
        const Index j = near.members[k];
        const Vec3d gradW(kernel.gradW(xij, rij));
        const double Vj = double(p.masses()[j]) / rho0;
        L += outer(Vec3d(-xij) * Vj, gradW);
        G += outer((Vec3d(p.velocities()[j]) - vi) * Vj, gradW);
    });
    if (L.det() < MIN_CORRECTION_DETERMINANT) return G;
    return G * L.inverse();
}

} // namespace

std::vector<Real> vorticityMagnitude(const ParticleSet& particles,
                                     const std::vector<Index>& selection,
                                     const EstimateSettings& settings)
{
    checkSettings(settings, "vorticity estimate");
    const KindNeighbours near(particles, settings.kind, settings.supportRadius);
    const CubicSplineKernel kernel(settings.supportRadius);
    std::vector<Real> out(selection.size(), Real(0));
    parallel::forEach(
        0, selection.size(),
        [&](std::size_t k) {
        const Index i = selection[k];
        if (particles.kinds()[i] != settings.kind) return;
        const Mat3d J = velocityGradient(particles, i, near, kernel, double(settings.restDensity));
        // curl v = (dv_z/dy - dv_y/dz, dv_x/dz - dv_z/dx, dv_y/dx - dv_x/dy)
        const Vec3d curl(J(2, 1) - J(1, 2), J(0, 2) - J(2, 0), J(1, 0) - J(0, 1));
        out[k] = Real(curl.length());
        },
        256);
    return out;
}

} // namespace sph
} // namespace ghostfx
