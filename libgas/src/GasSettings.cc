/// @file   GasSettings.cc
/// @brief  Method names and validation of the gas solver settings ([RYY15]).
#include "ghostfx/gas/GasSettings.h"

#include <ghostfx/sph/EnumNames.h>
#include <ghostfx/sph/Exceptions.h>
#include <ghostfx/sph/SettingCheck.h>

#include <algorithm>
#include <cmath>
#include <limits>

namespace ghostfx {
namespace gas {

namespace {

const sph::EnumName<Method> METHOD_NAMES[] = {
    {Method::Fast, "fast"}, {Method::Ambient, "ambient"}, {Method::Uncorrected, "uncorrected"}};
const sph::EnumName<Falloff> FALLOFF_NAMES[] = {{Falloff::InverseSquare, "inverse_square"},
                                                {Falloff::Constant, "constant"}};

} // namespace

const char* methodName(Method method) { return sph::nameOf(METHOD_NAMES, method); }

Method methodFromName(const std::string& name)
{
    return sph::valueOf(METHOD_NAMES, name, "gas method");
}

const char* falloffName(Falloff falloff) { return sph::nameOf(FALLOFF_NAMES, falloff); }

Falloff falloffFromName(const std::string& name)
{
    return sph::valueOf(FALLOFF_NAMES, name, "attractor falloff");
}

Vec3 Attractor::acceleration(const Vec3& x) const
{
    const Vec3 d = position - x; // towards c
    const Real r = d.length();
    if (r < radius) return d * (strength / radius); // linear core, zero at c
    const Real s = falloff == Falloff::InverseSquare ? strength * sph::sqr(radius / r) : strength;
    return d * (s / r);
}

Real GasSettings::soundSpeed() const { return std::sqrt(kappa); }

Real GasSettings::speedLimit(Real dt) const
{
    if (maxSpeed > Real(0)) return maxSpeed;
    // Ten spacings in one step is far beyond any CFL number a run could survive; the sound-speed
    // bound catches blow-ups at tiny time steps.
    const Real perStep = dt > Real(0) ? Real(10) * spacing / dt : std::numeric_limits<Real>::max();
    return std::min(perStep, Real(100) * std::max(soundSpeed(), Real(1e-3)));
}

void GasSettings::validate() const
{
    const sph::SettingCheck check("gas setting");
    check.require(spacing > 0 && check.finite(spacing), "spacing", spacing,
                  "a finite value > 0 (m)");
    check.require(supportFactor >= Real(1.2) && supportFactor <= Real(6), "supportFactor",
                  supportFactor, "1.2 to 6 particle spacings (default 2)");
    check.require(particleMass >= 0 && check.finite(particleMass), "particleMass", particleMass,
                  ">= 0 (kg; 0 = automatic)");
    check.require(restDensity > 0 && check.finite(restDensity), "restDensity", restDensity,
                  "a finite value > 0 (kg/m^3; [RYY15] Sec. 6: 1/1000 of the liquid's)");
    check.require(kappa > 0 && check.finite(kappa), "kappa", kappa,
                  "a finite value > 0 (m^2/s^2, Eq. 11)");
    check.require(delta >= Real(0.4) && delta <= Real(0.7), "delta", delta,
                  "0.4 to 0.7 ([RYY15] Sec. 3.1)");
    check.require(atmosphericPressure >= 0 && check.finite(atmosphericPressure),
                  "atmosphericPressure", atmosphericPressure, ">= 0 (Pa, P_a of Eq. 13)");
    check.require(interiorPressureScale >= 0 && interiorPressureScale <= 1, "interiorPressureScale",
                  interiorPressureScale, "0 to 1 (beta of [RYY15] Sec. 5)");
    check.require(normalThreshold > 0 && normalThreshold <= Real(10), "normalThreshold",
                  normalThreshold, "0 < C_N <= 10 (|n_i| h_i, dimensionless; default 0.5)");
    check.require(damping >= 0 && check.finite(damping), "damping", damping,
                  ">= 0 (1/s, C_d of Eq. 14)");
    check.require(viscosity >= 0 && check.finite(viscosity), "viscosity", viscosity, ">= 0 (Pa s)");
    check.require(sph::isFinite(gravity), "gravity", gravity.length(), "finite components (m/s^2)");
    check.require(check.finite(ambientTemperature), "ambientTemperature", ambientTemperature,
                  "a finite value (K)");
    check.require(diffusion >= 0 && check.finite(diffusion), "diffusion", diffusion,
                  ">= 0 (kg/(m s), D_c of Eq. 15)");
    check.require(radiationTime >= 0 && check.finite(radiationTime), "radiationTime", radiationTime,
                  ">= 0 (s, D_r of Eq. 16; 0 = off)");
    check.require(check.finite(buoyancy), "buoyancy", buoyancy,
                  "a finite value (m/s^2 per K, C_b of Eq. 17)");
    check.require(sph::isFinite(buoyancyDirection) && buoyancyDirection.length() > Real(1e-6),
                  "buoyancyDirection", buoyancyDirection.length(), "a finite non-zero vector");
    check.require(check.finite(vorticityGeneration), "vorticityGeneration", vorticityGeneration,
                  "a finite value (m, beta of Eq. 25)");
    check.require(vorticityStrength >= 0 && check.finite(vorticityStrength), "vorticityStrength",
                  vorticityStrength, ">= 0 (1/s)");
    check.require(lifeStrength >= 0 && check.finite(lifeStrength), "lifeStrength", lifeStrength,
                  ">= 0 (s; 0 = isolated particles live forever)");
    for (std::size_t k = 0; k < attractors.size(); ++k) {
        const Attractor& a = attractors[k];
        const std::string name = "attractors[" + std::to_string(k) + "].";
        check.require(sph::isFinite(a.position), (name + "position").c_str(), a.position.length(),
                      "finite coordinates (m)");
        check.require(check.finite(a.strength), (name + "strength").c_str(), a.strength,
                      "a finite value (m/s^2; < 0 repels)");
        check.require(a.radius > 0 && check.finite(a.radius), (name + "radius").c_str(), a.radius,
                      "a finite value > 0 (m)");
    }
    if (method == Method::Ambient) {
        const Vec3 e = domain.extent();
        check.require(
            !domain.empty() && e[0] >= 2 * supportRadius() && e[1] >= 2 * supportRadius()
                && e[2] >= 2 * supportRadius(),
            "domain extent", domain.empty() ? 0.0 : double(std::min({e[0], e[1], e[2]})),
            "a box at least two kernel radii wide on every axis (m) for method 'ambient'");
    }
    check.require(frameRate > 0 && check.finite(frameRate), "frameRate", frameRate,
                  "> 0 (frames/s)");
    check.require(substeps >= 0 && substeps <= 100000, "substeps", substeps,
                  "0 (CFL-adaptive) to 100000 ([RYY15] Sec. 6: 2)");
    check.require(cflNumber > 0 && cflNumber <= 2, "cflNumber", cflNumber, "0 < cfl <= 2");
    check.require(maxSpeed >= 0 && check.finite(maxSpeed), "maxSpeed", maxSpeed,
                  ">= 0 (m/s; 0 = automatic)");
}

} // namespace gas
} // namespace ghostfx
