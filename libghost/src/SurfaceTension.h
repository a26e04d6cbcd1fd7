/// @file   SurfaceTension.h
/// @brief  Surface tension as a continuum surface force (Brackbill, Kothe and Zemach 1992,
///         J. Comput. Phys. 100; in SPH after Morris 2000, Int. J. Numer. Meth. Fluids 33),
///         with [SB12]'s ghost air as the second phase of the colour field.
/// @details The liquid has colour 1, the ghost air 0. Each liquid and air particle's colour
///          gradient is
///              n_i = sum_j V_j (c_j - c_i) grad W_ij      (over liquid and air, V = m / rho),
///          which points into the liquid and is about 1 / h across a layer at the surface; the
///          air completes the sum on the surface's outside, where a liquid-only gradient
///          would see half a neighbourhood. The curvature is the negative divergence of the
///          unit normal over the particles whose |n| > 0.01 / h (Morris' reliable normals),
///          renormalised by the first moment of the kernel over those same neighbours:
///              kappa_i = -(d / -sum_j V_j x_ij . grad W_ij) sum_j V_j (n^_j - n^_i) . grad W_ij,
///          and each liquid particle takes the force per unit mass 2 sigma kappa_i n_i / rho_i,
///          the pressure jump of Laplace spread over the layer: the colour gradient's
///          integral across the layer falls half on each phase, and the ghost air, which
///          carries no force, leaves its half to the liquid. The solids count as neither
///          phase (the liquid meets them at a right angle). With DFSPH the force enters v*
///          before the density solve, whose pressure then carries the jump; with the Tait step
///          it is added after the pressure force.
///
///          Why a continuum surface force and not Akinci et al. 2013's cohesion and curvature
///          forces: Akinci's cohesion kernel and its particle-count correction give a tension
///          whose size depends on the kernel and the spacing, so sigma in N/m would need a
///          calibration per spacing, and the tests measure sigma itself (Laplace's
///          jump, Rayleigh's period). The CSF force is sigma kappa n by construction, and the
///          ghost air gives it the whole neighbourhood that its curvature needs.
///
///          A capillary wave of the spacing's length is resolved when dt <= sqrt(rho0 h^3 /
///          (2 pi sigma)) (Brackbill et al. Eq. 61): GhostSolver::stableTimeStep takes it.
#pragma once

#include <ghostfx/ghost/LiquidStep.h>

#include <vector>

namespace ghostfx {
namespace ghost {

class SurfaceTension
{
public:
    /// Add dt times the surface tension's acceleration to the liquid's v*
    /// (LiquidStep::VELOCITY_STAR).
    void apply(LiquidStep& step, Real dt);
    /// The largest step (s) that resolves a capillary wave of one spacing.
    static Real capillaryTimeStep(const GhostSettings& settings);

private:
    void colourGradients(LiquidStep& step);
    std::vector<sph::Vec3> mNormal; ///< n_i of each particle (1/m)
    std::vector<char> mReliable;    ///< |n_i| > 0.01 / h
};

} // namespace ghost
} // namespace ghostfx
