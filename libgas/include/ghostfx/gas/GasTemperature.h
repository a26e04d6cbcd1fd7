/// @file   GasTemperature.h
/// @brief  Temperature of the gas [RYY15] Sec. 3.3: diffusion (Eq. 15), radiation at the gas
///         boundary (Eq. 16) and thermal buoyancy (Eq. 17).
/// @details Diffusion is Cleary's SPH form (1998), antisymmetric in i and j, so diffusion alone
///          conserves sum_i m_i T_i; boundary particles are adiabatic (no exchange). Radiation
///          models the heat lost to the air that is not simulated, so the ambient-air baseline
///          has none. Buoyancy is Boussinesq: a_b = C_b (T_i - T_ambient) b. State: the rate
///          dT_i/dt of the last force pass, applied by advance().
#pragma once

#include <ghostfx/gas/GasSettings.h>
#include <ghostfx/sph/ParticleSet.h>

#include <vector>

namespace ghostfx {
namespace gas {

class GasTemperature
{
public:
    explicit GasTemperature(const GasSettings& settings);

    /// True when Eq. 15 is on (D_c > 0).
    bool diffuses() const { return mDiffusion > Real(0); }

    /// Start a force pass over `n` particles (every rate 0).
    void begin(std::size_t n) { mRate.assign(n, Real(0)); }

    /// Eq. 15 term of gas neighbour j for gas particle i (K/s): mass mj (kg), densities rhoI and
    /// rhoJ (kg/m^3), temperatures Ti and Tj (K), xij = x_i - x_j (m) at distance r (m), the
    /// kernel gradient gradW (1/m^4) for the pair support R (m).
    double pairRate(Real mj, Real rhoI, Real rhoJ, Real Ti, Real Tj, const Vec3& xij,
                    const Vec3& gradW, Real r, Real R) const
    {
        return double(mj) / (double(rhoI) * double(rhoJ)) * double(mDiffusion) * double(Ti - Tj)
               * double(xij.dot(gradW))
               / (double(r) * double(r) + double(DIFFUSION_GAMMA2 * R * R));
    }

    /// Eq. 17: buoyancy (m/s^2) of a particle at temperature Ti (K).
    Vec3 buoyancy(Real Ti) const { return mBuoyancy * (Ti - mAmbient) * mDirection; }

    /// Store dT_i/dt (K/s) of particle i: the summed Eq. 15 terms `diffusion` and, on the gas
    /// boundary (`surface`), Eq. 16's relaxation towards the ambient temperature.
    void setRate(std::size_t i, double diffusion, Real Ti, bool surface)
    {
        Real rate = Real(diffusion);
        if (mRadiates && surface) rate -= (Ti - mAmbient) / mRadiationTime; // Eq. 16
        mRate[i] = rate;
    }

    /// Explicit Euler on particle i's temperature T[i] (K) over dt (s) with the stored rate.
    void advance(std::vector<Real>& T, std::size_t i, Real dt) const { T[i] += dt * mRate[i]; }

private:
    /// gamma^2 of Eq. 15 as a fraction of the squared pair support ([RYY15]: "gamma^2 << 1";
    /// the usual SPH choice 0.01 h^2 keeps it small against the smallest particle distance).
    static constexpr Real DIFFUSION_GAMMA2 = Real(0.01);

    Real mDiffusion;         ///< D_c of Eq. 15 (kg/(m s))
    Real mAmbient;           ///< T_ambient (K)
    bool mRadiates;          ///< Eq. 16 on: no ambient air and D_r > 0
    Real mRadiationTime;     ///< D_r of Eq. 16 (s)
    Real mBuoyancy;          ///< C_b of Eq. 17 (m/s^2 per K)
    Vec3 mDirection;         ///< b of Eq. 17, unit
    std::vector<Real> mRate; ///< dT_i/dt (K/s) of the last force pass
};

} // namespace gas
} // namespace ghostfx
