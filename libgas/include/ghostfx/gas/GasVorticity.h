/// @file   GasVorticity.h
/// @brief  Artificial vorticity of the gas [RYY15] Sec. 5, Eqs. 25 - 26.
/// @details Each gas particle carries a vorticity omega_i (channel "vorticity", 1/s), which
///          the boundary generates and the flow stretches (Eq. 25),
///              d omega_i / dt = (omega_i . grad) v + beta n_i x g,
///          and which turns into a vortex velocity (Eq. 26) added to Eq. 24 as an acceleration,
///              a_i += S sum_j V_j (omega_j x x_ij) W_ij,
///          with S = GasSettings::vorticityStrength. Boundary particles carry no vorticity.
///          g is the gravity, or standard gravity against the buoyancy direction when the gas
///          has no weight (the default), so the boundary still generates vorticity.
///          State: d omega_i / dt of the last force pass, applied by advance().
#pragma once

#include <ghostfx/gas/GasSettings.h>
#include <ghostfx/sph/Kernels.h>
#include <ghostfx/sph/ParticleSet.h>

#include <vector>

namespace ghostfx {
namespace gas {

class GasVorticity
{
public:
    /// Pair sums of one gas particle.
    struct Sums
    {
        sph::Vec3d stretch{0.0}; ///< (omega_i . grad) v of Eq. 25 (1/s^2)
        sph::Vec3d vortex{0.0};  ///< the vortex velocity of Eq. 26 (m/s)
    };

    explicit GasVorticity(const GasSettings& settings);

    /// True when the settings turn artificial vorticity on.
    bool enabled() const { return mEnabled; }

    /// Add the "vorticity" channel to `particles` if enabled.
    void addChannel(sph::ParticleSet& particles) const;

    /// Start a force pass over `n` particles (every rate 0).
    void begin(std::size_t n) { mRate.assign(n, Vec3(0)); }

    /// Add gas neighbour j's terms to particle i's sums: omega the vorticity channel, vji =
    /// v_j - v_i (m/s), Vj = m_j / rho_j (m^3), gradW (1/m^4) at xij = x_i - x_j (m), r (m) and
    /// the pair support R (m).
    void addPair(Sums& sums, const std::vector<Vec3>& omega, std::size_t i, std::size_t j,
                 const Vec3& vji, Real Vj, const Vec3& gradW, const Vec3& xij, Real r, Real R) const
    {
        // Eq. 25: (omega_i . grad) v ~ sum_j V_j (v_j - v_i) (omega_i . grad W_ij).
        const Vec3 s = vji * (Vj * omega[i].dot(gradW));
        sums.stretch += sph::Vec3d(s);
        // Eq. 26, weighted by the neighbour volume V_j (resolution independent).
        const Vec3 u = omega[j].cross(xij) * (Vj * sph::poly6W(r, R));
        sums.vortex += sph::Vec3d(u);
    }

    /// Eq. 26's acceleration added to a (m/s^2), and Eq. 25's rate of particle i stored, from
    /// its sums and its normal nI (1/m).
    void finish(std::size_t i, const Sums& sums, const Vec3& nI, Vec3& a)
    {
        a += mStrength * sph::toVec3(sums.vortex);
        mRate[i] = sph::toVec3(sums.stretch) + mGeneration * nI.cross(mGravity);
    }

    /// Explicit Euler on particle i's vorticity omega[i] (1/s) over dt (s) with the stored
    /// rate.
    void advance(std::vector<Vec3>& omega, std::size_t i, Real dt) const
    {
        omega[i] += dt * mRate[i];
    }

private:
    bool mEnabled;
    Real mGeneration;        ///< beta of Eq. 25 (m)
    Real mStrength;          ///< S (1/s): Eq. 26's velocity to an acceleration
    Vec3 mGravity;           ///< g of Eq. 25 (m/s^2)
    std::vector<Vec3> mRate; ///< d omega_i / dt (1/s^2) of the last force pass
};

} // namespace gas
} // namespace ghostfx
