/// @file   ImplicitViscosity.h
/// @brief  The liquid's viscosity, solved implicitly: Weiler, Koschier, Brand and Bender 2018,
///         "A Physically Consistent Implicit Viscosity Solver for SPH Fluids" (Computer
///         Graphics Forum 37(2)), over [SB12]'s ghost solids and ghost air.
/// @details The viscous acceleration of liquid particle i is the SPH Laplacian of the velocity
///          ([WKBB18] Eq. 7, with d = 3 dimensions):
///              a_i = 2 (d + 2) nu sum_j (m_j / rho_j) (v_ij . x_ij) / (|x_ij|^2 + 0.01 h^2)
///                    grad W_ij,
///          nu the kinematic viscosity (m^2/s). One step of backward Euler, v = w + dt a(v),
///          with w the velocities the step has so far, is the linear system
///              m v_i - dt sum_j c_ij x_ij (x_ij . (v_i - v_j)) = m w_i,
///              c_ij = 10 nu rho0 m_i m_j / (rho_i rho_j) W'(r) / r / (r^2 + 0.01 h^2) <= 0,
///          written in momenta (each row times m_i, and nu rho0 = mu as the dynamic
///          viscosity), so that its matrix is symmetric, and positive definite: m I plus dt
///          times a graph Laplacian of the pairs. It is solved by conjugate gradients with the
///          inverse of each particle's 3 x 3 diagonal block as the preconditioner ([WKBB18]
///          Sec. 4), started from w plus the last step's viscous change (a channel of the
///          particles, kept in checkpoints). Any nu is stable at the flow's step: backward
///          Euler damps every mode.
///
///          Neighbours: the liquid's own (air is left out: a free surface feels no viscous
///          drag from the air, [SB12] Sec. 4.3's ghost air only completes its density), and with
///          GhostSettings::solidSlip no_slip the ghost solids at their solid's velocity, a known
///          part on the right-hand side (free-slip walls take no viscous traction).
#pragma once

#include <ghostfx/ghost/GhostSolver.h>
#include <ghostfx/ghost/LiquidStep.h>

#include <cstdint>
#include <vector>

namespace ghostfx {
namespace ghost {

class ImplicitViscosity
{
public:
    /// The particle channel of each liquid particle's last viscous velocity change (m/s).
    static constexpr const char* CHANNEL = "viscosity_dv";
    /// Each liquid particle's own kinematic viscosity nu (m^2/s), where a liquid or an
    /// emitter has its own (GhostSolver::addLiquid); without it every particle has
    /// settings.viscosity. A pair of liquid particles couples with the mean of their dynamic
    /// viscosities (which keeps the system symmetric), a particle and a no-slip solid with the
    /// particle's.
    static constexpr const char* NU_CHANNEL = GhostSolver::VISCOSITY_CHANNEL;

    /// Replace the liquid's v* (LiquidStep::VELOCITY_STAR) by the velocities one backward
    /// Euler step of length dt (s) of the viscous force gives from it. Throws NumericalError
    /// on a non-finite result.
    void apply(LiquidStep& step, Real dt);
    const ViscositySolveStats& stats() const { return mStats; }

private:
    /// A symmetric 3 x 3 block: xx, yy, zz, xy, xz, yz.
    struct Block
    {
        double a[6] = {0, 0, 0, 0, 0, 0};
    };
    void prepare(LiquidStep& step, Real dt);
    /// mLiquid, mOverRho and mMu of every particle.
    void gatherParticles(LiquidStep& step);
    /// Add liquid particle i's no-slip solid pairs to its diagonal block `d`; returns their
    /// known part of its right-hand side, dt sum_s c_is x_is (x_is . v_s).
    sph::Vec3d addWalls(LiquidStep& step, std::size_t i, double* d) const;
    /// The liquid pairs (mStart, mCount, mNeighbour, mCoefficient: V_i V_j W' / r / (r^2 +
    /// 0.01 h^2)) and mScale, each particle's Laplacian made whole where neighbours are left out.
    void gatherPairs(LiquidStep& step);
    /// The largest such scale: a particle with a quarter of its neighbourhood (a lone drop).
    static constexpr double MAX_SCALE = 4;
    /// y = A v over the liquid (A the system matrix of the file comment).
    void multiply(LiquidStep& step, const std::vector<sph::Vec3d>& v, std::vector<sph::Vec3d>& y);
    void precondition(const std::vector<sph::Vec3d>& r, std::vector<sph::Vec3d>& z) const;
    double dot(const std::vector<sph::Vec3d>& a, const std::vector<sph::Vec3d>& b) const;
    int solve(LiquidStep& step, std::vector<sph::Vec3d>& v, double& residual);

    Real mDt = 0;
    double mEps2 = 0;             ///< 0.01 h^2 (m^2)
    std::vector<double> mMu;      ///< nu rho0 of each particle (Pa s)
    std::vector<char> mLiquid;    ///< per particle: a liquid particle this process solves for
    std::vector<double> mOverRho; ///< m / rho of each particle (m^3)
    std::vector<double> mScale;   ///< gamma_i (scaleForMissingNeighbours)
    /// Each liquid particle's liquid neighbours (mNeighbour) and, once prepared, their dt c_ij
    /// (mCoefficient, s kg), from mStart[i], mCount[i] of them: 8 bytes a liquid pair.
    std::vector<std::size_t> mStart;
    std::vector<std::uint32_t> mCount, mNeighbour;
    std::vector<float> mCoefficient;
    std::vector<Block> mDiagonal, mInverse;
    std::vector<sph::Vec3d> mRhs;
    std::vector<sph::Vec3d> mR, mZ, mP, mAp;
    ViscositySolveStats mStats;
};

} // namespace ghost
} // namespace ghostfx
