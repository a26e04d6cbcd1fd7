/// @file   GhostSettings.cc
/// @brief  Method names and validation of the liquid solver settings.
#include "ghostfx/ghost/GhostSettings.h"

#include <ghostfx/sph/EnumNames.h>
#include <ghostfx/sph/Exceptions.h>
#include <ghostfx/sph/SettingCheck.h>

#include <algorithm>
#include <cmath>

namespace ghostfx {
namespace ghost {

namespace {

const sph::EnumName<Method> METHOD_NAMES[] = {{Method::Ghost, "ghost"}, {Method::Basic, "basic"}};

const sph::EnumName<PressureModel> PRESSURE_NAMES[] = {{PressureModel::Tait, "tait"},
                                                       {PressureModel::Dfsph, "dfsph"}};

} // namespace

const char* pressureName(PressureModel model) { return sph::nameOf(PRESSURE_NAMES, model); }

PressureModel pressureFromName(const std::string& name)
{
    return sph::valueOf(PRESSURE_NAMES, name, "pressure model");
}

const char* methodName(Method method) { return sph::nameOf(METHOD_NAMES, method); }

Method methodFromName(const std::string& name)
{
    return sph::valueOf(METHOD_NAMES, name, "liquid method");
}

Real GhostSettings::soundSpeed() const
{
    // dp/drho of the Tait equation at rho0: 7 k / rho0.
    return std::sqrt(Real(7) * stiffness / restDensity);
}

Real GhostSettings::solidDragReferenceStep(Real vmax) const
{
    // Why a rate (issue 18): with epsilon per step, the wall drag per second grows as 1 / dt,
    // i.e. as sqrt(k) on acoustic steps, and a stiff liquid crept along the floor. The
    // liquid's own epsilon stays per step, as [SB12] defines it: it damps the acoustic noise,
    // whose frequency grows with sqrt(k) as the steps do (bench/history/diary-2026-11.md, "Stiff
    // liquid").
    const Real referenceStiffness = Real(2000), referenceCfl = Real(0.4);
    const Real c = std::sqrt(Real(7) * referenceStiffness / restDensity);
    return referenceCfl * spacing / (c + vmax);
}

Real GhostSettings::airResampleSpan(Real dt, Real vmax) const
{
    if (pressure != PressureModel::Dfsph
        || dfsph.airResampling != DfsphSettings::AirResampling::Time)
        return Real(1);
    return std::min(Real(airResampleSteps), dt / solidDragReferenceStep(vmax));
}

Real GhostSettings::shifting() const
{
    if (shiftingCoefficient >= Real(0)) return shiftingCoefficient;
    return stiffness > Real(20000) ? Real(2) : Real(0);
}

int GhostSettings::relaxationPasses() const
{
    if (initialRelaxation >= 0) return initialRelaxation;
    // DFSPH holds the density to a fraction of a percent: the sampled error is a kick.
    if (pressure == PressureModel::Dfsph) return 20;
    return stiffness > Real(20000) ? 20 : 0;
}

Real GhostSettings::xsphEpsilonPerStep() const
{
    // Not dt over the acoustic step: where the force limit shortens the steps (a stiff k's
    // pressure noise), the per-step damping is what keeps that noise down (issue 18: scaled by
    // dt, k = 2e5 reached 8 x the free-fall speed).
    if (substeps > 0) return xsphEpsilon;
    return std::min(Real(1), xsphEpsilon * (cflNumber / Real(0.4)));
}

Real GhostSettings::solidEpsilonForStep(Real dt, Real vmax) const
{
    return std::min(Real(1), solidEpsilon * (dt / solidDragReferenceStep(vmax)));
}

Real GhostSettings::speedLimit() const
{
    return maxSpeed > Real(0) ? maxSpeed : Real(20) * soundSpeed();
}

void GhostSettings::validate() const
{
    const sph::SettingCheck check("liquid setting");
    check.require(spacing > 0 && check.finite(spacing), "spacing", spacing,
                  "a finite value > 0 (m)");
    check.require(supportFactor >= Real(1.5) && supportFactor <= Real(6), "supportFactor",
                  supportFactor, "1.5 to 6 particle spacings ([SB12]: 3)");
    check.require(restDensity > 0 && check.finite(restDensity), "restDensity", restDensity,
                  "> 0 (kg/m^3)");
    check.require(stiffness > 0 && check.finite(stiffness), "stiffness", stiffness, "> 0 (Pa)");
    check.require(sph::isFinite(gravity), "gravity", gravity.length(), "finite components (m/s^2)");
    check.require(xsphEpsilon >= 0 && xsphEpsilon <= 1, "xsphEpsilon", xsphEpsilon,
                  "0 to 1 ([SB12]: 0.05)");
    check.require(solidEpsilon >= 0 && solidEpsilon <= 1, "solidEpsilon", solidEpsilon, "0 to 1");
    check.require(shiftingCoefficient <= 20 && check.finite(shiftingCoefficient),
                  "shiftingCoefficient", shiftingCoefficient,
                  "0 (off) to 20, or negative (automatic)");
    check.require(initialRelaxation <= 1000, "initialRelaxation", initialRelaxation,
                  "0 (off) to 1000 passes, or negative (automatic)");
    check.require(airResampleSteps >= 1, "airResampleSteps", airResampleSteps,
                  ">= 1 ([SB12]: about 10)");
    check.require(airKeepFraction >= 0 && check.finite(airKeepFraction), "airKeepFraction",
                  airKeepFraction, ">= 0 (fraction of the Poisson radius)");
    check.require(basicXsphEpsilon >= 0 && basicXsphEpsilon <= 1, "basicXsphEpsilon",
                  basicXsphEpsilon, "0 to 1 ([SB12]: 0.5)");
    check.require(basicViscosityAlpha >= 0 && check.finite(basicViscosityAlpha),
                  "basicViscosityAlpha", basicViscosityAlpha, ">= 0 ([SB12]: 0.0005)");
    check.require(lennardJonesStrength >= 0 && check.finite(lennardJonesStrength),
                  "lennardJonesStrength", lennardJonesStrength, ">= 0 (m^2/s^2; 0 = automatic)");
    check.require(frameRate > 0 && check.finite(frameRate), "frameRate", frameRate,
                  "> 0 (frames/s)");
    check.require(substeps >= 0 && substeps <= 100000, "substeps", substeps,
                  "0 (CFL-adaptive) to 100000");
    check.require(cflNumber > 0 && cflNumber <= 2, "cflNumber", cflNumber, "0 < cfl <= 2");
    if (pressure == PressureModel::Dfsph) {
        if (method != Method::Ghost) {
            throw ValueError("liquid setting pressure = 'dfsph' with method 'basic': "
                             "expected 'tait' (Basic SPH is [SB12]'s weakly compressible "
                             "baseline, with no air for a pressure solve's free surface)");
        }
        check.require(dfsph.densityError >= Real(1e-7) && dfsph.densityError <= Real(0.1),
                      "dfsph.densityError", dfsph.densityError, "1e-7 to 0.1 (a fraction)");
        check.require(dfsph.divergenceError >= Real(1e-7) && dfsph.divergenceError <= Real(1),
                      "dfsph.divergenceError", dfsph.divergenceError, "1e-7 to 1 (a fraction)");
        check.require(dfsph.densityRelaxation > 0 && dfsph.densityRelaxation <= 1,
                      "dfsph.densityRelaxation", dfsph.densityRelaxation, "in (0, 1]");
        check.require(dfsph.keptGradientLimit >= 0 && check.finite(dfsph.keptGradientLimit),
                      "dfsph.keptGradientLimit", dfsph.keptGradientLimit,
                      "a finite value >= 0 (bytes)");
        check.require(dfsph.maxIterations >= 1 && dfsph.maxIterations <= 100000,
                      "dfsph.maxIterations", dfsph.maxIterations, "1 to 100000");
        check.require(dfsph.minTimeStep > 0 && check.finite(dfsph.minTimeStep), "dfsph.minTimeStep",
                      dfsph.minTimeStep, "a finite value > 0 (s)");
        check.require(dfsph.maxTimeStep >= dfsph.minTimeStep && check.finite(dfsph.maxTimeStep),
                      "dfsph.maxTimeStep", dfsph.maxTimeStep,
                      "finite and >= dfsph.minTimeStep (s)");
    }
    check.require(maxSpeed >= 0 && check.finite(maxSpeed), "maxSpeed", maxSpeed,
                  ">= 0 (m/s; 0 = 20 x sound speed)");
}

} // namespace ghost
} // namespace ghostfx
