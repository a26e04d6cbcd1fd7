/// @file   RenderEstimates.h
/// @brief  SPH estimates written on exported points for rendering (not used by any solver):
///         the magnitude of the velocity's curl, and the mean curvature of the liquid surface.
/// @details Both are computed from a particle set as it is (positions, velocities, masses)
///          over the neighbours of one kind within the kernel support R, with the cubic spline
///          kernel of the solvers (Kernels.h). Gradients use the corrected SPH gradient of
///          Bonet and Lok (CMAME 180, 1999, Sec. 5): with V_j = m_j / rho0,
///              L_i = sum_j V_j (x_j - x_i) (x) gradW_ij,   G_i = sum_j V_j (f_j - f_i) (x) gradW_ij,
///              grad f_i = G_i L_i^-1,
///          which is exact for any linear field f, also where the neighbourhood is cut by the
///          free surface. Where L_i is near singular (fewer than a plane of neighbours: spray)
///          the plain estimate grad f_i = G_i is used.
#pragma once

#include "ghostfx/sph/ParticleSet.h"

#include <vector>

namespace ghostfx {
namespace sph {

/// The kernel and neighbours an estimate uses.
struct EstimateSettings
{
    Real supportRadius = 0; ///< kernel support R (m)
    Real restDensity = 0;   ///< rho0 (kg/m^3): neighbour volumes V_j = m_j / rho0
    ParticleKind kind = ParticleKind::Liquid; ///< neighbours counted, and particles estimated
};

/// |curl v| (1/s) at each particle `selection[k]`, from the velocities of its neighbours of
/// `settings.kind`; 0 for a selected particle of another kind. Throws ValueError on a
/// non-positive support radius or rest density.
std::vector<Real> vorticityMagnitude(const ParticleSet& particles,
                                     const std::vector<Index>& selection,
                                     const EstimateSettings& settings);

/// Mean curvature H = (kappa_1 + kappa_2) / 2 = div(n) / 2 (1/m) of the surface at each
/// particle `selection[k]` of `settings.kind` in the surface layer: positive where the liquid
/// is convex (1 / r on a ball of radius r), 0 inside and for other kinds. The layer and its
/// outward normals n come from the colour field c = sum_j V_j W_ij: the particles where
/// |grad c| R >= 0.2 (c falls by about 1/2 over R across a free surface), n = -grad c / |grad c|;
/// div(n) is the corrected estimate over the layer's particles. Throws like
/// vorticityMagnitude.
std::vector<Real> meanCurvature(const ParticleSet& particles, const std::vector<Index>& selection,
                                const EstimateSettings& settings);

} // namespace sph
} // namespace ghostfx
