/// @file   GasCompensation.h
/// @brief  Density correction and force compensation of the fast gas without ambient air
///         [RYY15] Secs. 3.1 - 3.2 and 5 (Method::Fast).
/// @details A gas particle at the boundary of a gas without air misses the air's neighbours.
///          One virtual particle k per gas particle, delta h_i away against n_bar_i (Sec. 3.1),
///          stands in for them:
///           - density (Eqs. 5, 7, 8): V_0 = |n_bar_i| / |grad W_ik| with
///             n_bar_i = sum_j m_j / rho_bar_j grad W_ij, and rho_i = rho_bar_i (1 + V_0 W_ik);
///           - force (Eq. 10): the virtual particle's pressure term, -p_i (rho_bar_i / rho_i)
///             n_bar_i;
///           - atmospheric pressure (Eq. 13): P_a n_i, scaled by beta inside the gas (Sec. 5);
///           - damping (Eq. 14): -C_d v_i on boundary particles, the drag of the missing air.
///          The baselines (ambient air, uncorrected) switch the part off: they use rho_bar as it
///          is (Eq. 21) and none of these forces. State: n_bar_i of the last density pass.
#pragma once

#include <ghostfx/gas/GasSettings.h>
#include <ghostfx/sph/NeighborLists.h>

#include <vector>

namespace ghostfx {
namespace gas {

class GasCompensation
{
public:
    explicit GasCompensation(const GasSettings& settings);

    /// True for Method::Fast; the baselines have no compensation.
    bool enabled() const { return mEnabled; }

    /// Start a density pass over `n` particles (n_bar_i = 0 for all).
    void beginDensity(std::size_t n) { mNbar.assign(n, Vec3(0)); }

    /// Eqs. 5 and 8 for gas particle i: stores n_bar_i (1/m) from the uncorrected densities
    /// rhoBar (kg/m^3) of i's listed neighbours and returns the corrected density rho_i
    /// (kg/m^3). x: positions (m), m: masses (kg), h: support radii (m).
    Real correctedDensity(const sph::NeighborLists& lists, const std::vector<Vec3>& x,
                          const std::vector<Real>& m, const std::vector<Real>& h,
                          const std::vector<Real>& rhoBar, std::size_t i);

    /// Eq. 5's n_bar_i alone (no correction), for a method without compensation whose
    /// entrainment still needs the gas's boundary (GasEntrainment.h); arguments as above.
    void storeNormal(const sph::NeighborLists& lists, const std::vector<Vec3>& x,
                     const std::vector<Real>& m, const std::vector<Real>& h,
                     const std::vector<Real>& rhoBar, std::size_t i);

    /// Eqs. 10 and 13 added to the force density F (N/m^3) of gas particle i: pressure pi (Pa),
    /// densities rhoBarI and rhoI (kg/m^3), normal nI (1/m), `surface` when |n_i| h_i > C_N.
    void addForces(Vec3& F, std::size_t i, Real pi, Real rhoBarI, Real rhoI, const Vec3& nI,
                   bool surface) const
    {
        // Eq. 10: the virtual particle k (mass m_k = V_0 rho_bar_i, Eq. 7; density and
        // pressure those of i) adds + (m_k / rho_k) (p_i + p_k) / 2 grad W_ik. By Eq. 5,
        // (m_k / rho_k) |grad W_ik| = (rho_bar_i / rho_i) |n_bar_i|, and grad W_ik points
        // from i to k, against n_bar_i (Eq. 4), so the term is -p_i (rho_bar_i / rho_i)
        // n_bar_i. We take the sign as printed. The other reading (the force a real particle
        // at k would exert, -(m_k / rho_k) ... grad W_ik) cancels -p_i n_i, the background
        // pressure that keeps particles evenly spaced, for every particle, and P_a n_i then
        // pushes the surface in unopposed: a block at rest clumped and flew apart (RMS radius
        // x3.6 in 2 s, tests/gas setting). As printed, the surface balances P_a n_i against
        // about 2 p_i n_i: stable, the block holds (x0.97).
        F -= mNbar[i] * (pi * rhoBarI / rhoI);
        // Eq. 13: atmospheric pressure P_a n_i, scaled by beta inside the gas (Sec. 5).
        const Real Pa = mAtmosphericPressure * (surface ? Real(1) : mInteriorPressureScale);
        F += Pa * nI;
    }

    /// n_bar_i of Eq. 5 (1/m) from the last density pass: the gradient of the gas's colour
    /// field, pointing into the gas; its length is the boundary's area per volume.
    const Vec3& normal(std::size_t i) const { return mNbar[i]; }

    /// Eq. 14 added to the acceleration a (m/s^2) of a particle at velocity vi (m/s).
    void damp(Vec3& a, const Vec3& vi, bool surface) const
    {
        if (surface) a -= mDamping * vi;
    }

private:
    bool mEnabled;
    Real mDelta;                 ///< delta of Sec. 3.1 (fraction of h_i)
    Real mAtmosphericPressure;   ///< P_a of Eq. 13 (Pa)
    Real mInteriorPressureScale; ///< beta of Sec. 5
    Real mDamping;               ///< C_d of Eq. 14 (1/s)
    std::vector<Vec3> mNbar;     ///< n_bar_i of Eq. 5 (1/m), from the last density pass
};

} // namespace gas
} // namespace ghostfx
