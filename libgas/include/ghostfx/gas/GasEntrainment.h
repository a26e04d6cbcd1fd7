/// @file   GasEntrainment.h
/// @brief  Ambient air entrained into the gas at its boundary, after the entrainment assumption
///         of Morton, Taylor and Turner 1956 ([MTT56], "Turbulent gravitational convection from
///         maintained and instantaneous sources", Proc. R. Soc. A 234): air at rest joins a
///         plume through its edge at the speed u_e = alpha |v|, alpha about 0.1.
/// @details The air-free gas [RYY15] simulates only the visible gas, so nothing can be drawn
///          into it and a plume rises as a column of constant volume. This part adds the air the
///          gas would have entrained, as mass: over dt a gas particle i gains
///
///              dm_i = rho0 alpha |v_i| A_i dt,    A_i = |n_i| m_i / rho_i,
///
///          A_i its share of the gas's boundary area (n_i the colour-field gradient of [RYY15]
///          Eq. 5, whose length is the boundary area per volume: its integral over the gas is
///          the gas's surface area; m_i / rho_i its volume, so vapour born compressed, far
///          denser than rho0, draws in air through the small surface it has). The air is at rest and at the ambient temperature, and
///          mixes into the particle: its momentum m v and its buoyancy m (T - T_a) are kept, so
///          it slows and cools as [MTT56]'s top-hat plume does, and the buoyancy flux of a
///          plume is conserved. The particle's volume grows with its mass (its support follows,
///          GasSolver::expandSupports), so the gas widens: [MTT56] b = 6/5 alpha z. Its share of
///          smoke (channel::SMOKE, 1 as emitted) falls as the air dilutes it, so sum_i m_i c_i
///          stays the mass emitted; the "smoke" volume grid draws the plume thinning.
#pragma once

#include <ghostfx/gas/GasSettings.h>
#include <ghostfx/sph/Types.h>

namespace ghostfx {
namespace gas {

class GasEntrainment
{
public:
    explicit GasEntrainment(const GasSettings& settings)
        : mAlpha(settings.entrainmentInUse())
        , mRestDensity(settings.restDensity)
        , mAmbient(settings.ambientTemperature)
    {}

    bool enabled() const { return mAlpha > Real(0); }

    /// Mix the air a particle of mass m (kg), velocity v (m/s), temperature T (K) and smoke
    /// share c (channel::SMOKE) with the colour gradient n (1/m) and density rho (kg/m^3)
    /// entrains over dt (s) into it.
    void entrain(Real& m, Vec3& v, Real& T, Real& c, const Vec3& n, Real rho, Real dt) const
    {
        const double length = double(n.length());
        if (!(length > 0) || !(rho > Real(0))) return;
        const double area = length * double(m) / double(rho);
        // The speed along the boundary: the shear that draws the air in.
        const openvdb::math::Vec3<double> vd(v), unit = openvdb::math::Vec3<double>(n) / length;
        const double along = (vd - unit * vd.dot(unit)).length();
        const double dm = double(mRestDensity) * double(mAlpha) * along * area * double(dt);
        if (!(dm > 0)) return;
        const double total = double(m) + dm;
        const double keep = double(m) / total;
        T = Real(double(mAmbient) + (double(T) - double(mAmbient)) * keep);
        v = Vec3(openvdb::math::Vec3<double>(v) * keep);
        c = Real(double(c) * keep);
        m = Real(total);
    }

private:
    Real mAlpha;       ///< [MTT56]'s alpha
    Real mRestDensity; ///< rho0 (kg/m^3), of the gas and of the air it entrains
    Real mAmbient;     ///< T_a (K) of the entrained air
};

} // namespace gas
} // namespace ghostfx
