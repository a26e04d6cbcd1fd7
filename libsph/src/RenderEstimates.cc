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

/// |grad c| R at and above which a particle is on the surface: c falls from 1 inside to about
/// 1/2 at the outermost particles over one support radius R, a drop of about 0.5 over R; deep
/// inside, the sampling's irregularity leaves |grad c| R of a few hundredths.
constexpr double SURFACE_COLOUR_DROP = 0.2;

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

/// The Jacobian J_ab = df_a / dx_b at particle i of a field given at the neighbours by
/// `f(j)` (Vec3d), over the neighbours j with `counted(j)`: G_i L_i^-1 where L_i can be
/// inverted, else G_i (see the file's header).
template <typename Field, typename Counted>
Mat3d fieldJacobian(const ParticleSet& p, Index i, const KindNeighbours& near,
                    const CubicSplineKernel& kernel, double rho0, Field&& f, Counted&& counted)
{
    Mat3d L = Mat3d::zero(), G = Mat3d::zero();
    const Vec3d fi = f(i);
    near.grid.forEachInRadius(p.positions()[i], kernel.supportRadius(),
                              [&](Index k, const Vec3& xij, Real rij) {
        const Index j = near.members[k];
        if (!counted(j)) return;
        const Vec3d gradW(kernel.gradW(xij, rij));
        const double Vj = double(p.masses()[j]) / rho0;
        L += outer(Vec3d(-xij) * Vj, gradW);
        G += outer((f(j) - fi) * Vj, gradW);
    });
    if (L.det() < MIN_CORRECTION_DETERMINANT) return G;
    return G * L.inverse();
}

Mat3d velocityGradient(const ParticleSet& p, Index i, const KindNeighbours& near,
                       const CubicSplineKernel& kernel, double rho0)
{
    return fieldJacobian(
        p, i, near, kernel, rho0, [&](Index j) { return Vec3d(p.velocities()[j]); },
        [](Index) { return true; });
}

/// The outward unit normal -grad c / |grad c| of the colour field c = sum_j V_j W_ij at the
/// particles of the neighbours' kind where |grad c| R >= SURFACE_COLOUR_DROP (the surface
/// layer), else 0; indexed like the set.
std::vector<Vec3d> surfaceNormals(const ParticleSet& p, const KindNeighbours& near,
                                  const CubicSplineKernel& kernel, double rho0)
{
    const std::size_t n = near.members.size();
    std::vector<double> colour(p.size(), 0.0);
    parallel::forEach(
        0, n,
        [&](std::size_t k) {
        const Index i = near.members[k];
        double c = 0;
        near.grid.forEachInRadius(p.positions()[i], kernel.supportRadius(),
                                  [&](Index m, const Vec3&, Real rij) {
            c += double(p.masses()[near.members[m]]) / rho0 * double(kernel.W(rij));
        });
        colour[i] = c;
        },
        256);
    std::vector<Vec3d> normal(p.size(), Vec3d(0.0));
    const double R = double(kernel.supportRadius());
    parallel::forEach(
        0, n,
        [&](std::size_t k) {
        const Index i = near.members[k];
        const Mat3d J = fieldJacobian(
            p, i, near, kernel, rho0, [&](Index j) { return Vec3d(colour[j], 0.0, 0.0); },
            [](Index) { return true; });
        const Vec3d gradC(J(0, 0), J(0, 1), J(0, 2));
        if (gradC.length() * R >= SURFACE_COLOUR_DROP) normal[i] = -gradC / gradC.length();
        },
        256);
    return normal;
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

std::vector<Real> meanCurvature(const ParticleSet& particles, const std::vector<Index>& selection,
                                const EstimateSettings& settings)
{
    checkSettings(settings, "curvature estimate");
    const KindNeighbours near(particles, settings.kind, settings.supportRadius);
    const CubicSplineKernel kernel(settings.supportRadius);
    const double rho0 = double(settings.restDensity);
    const std::vector<Vec3d> normal = surfaceNormals(particles, near, kernel, rho0);
    auto isSurface = [&](Index j) { return normal[j].lengthSqr() > 0.0; };
    std::vector<Real> out(selection.size(), Real(0));
    parallel::forEach(
        0, selection.size(),
        [&](std::size_t k) {
        const Index i = selection[k];
        if (particles.kinds()[i] != settings.kind || !isSurface(i)) return;
        const Mat3d J = fieldJacobian(
            particles, i, near, kernel, rho0, [&](Index j) { return normal[j]; }, isSurface);
        // H = (kappa_1 + kappa_2) / 2 = div(n) / 2 for the outward unit normal n.
        out[k] = Real(0.5 * (J(0, 0) + J(1, 1) + J(2, 2)));
        },
        256);
    return out;
}

} // namespace sph
} // namespace ghostfx
