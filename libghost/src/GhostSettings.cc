/// @file   GhostSettings.cc
/// @brief  Method names and validation of the liquid solver settings.
#include "ghostfx/ghost/GhostSettings.h"

#include <ghostfx/sph/Exceptions.h>

#include <cmath>

namespace ghostfx {
namespace ghost {

const char* methodName(Method method)
{
    switch (method) {
    case Method::Ghost:
        return "ghost";
    case Method::Basic:
        return "basic";
    }
    return "unknown";
}

Method methodFromName(const std::string& name)
{
    if (name == "ghost") return Method::Ghost;
    if (name == "basic") return Method::Basic;
    throw ValueError(msg("liquid method '", name, "': expected 'ghost' or 'basic'"));
}

Real GhostSettings::soundSpeed() const
{
    // dp/drho of the Tait equation at rho0: 7 k / rho0.
    return std::sqrt(Real(7) * stiffness / restDensity);
}

Real GhostSettings::speedLimit() const
{
    return maxSpeed > Real(0) ? maxSpeed : Real(20) * soundSpeed();
}

void GhostSettings::validate() const
{
    auto require = [](bool ok, const char* field, double value, const char* expected) {
        if (!ok)
            throw ValueError(msg("liquid setting ", field, " = ", value, ": expected ", expected));
    };
    auto finite = [](Real v) { return std::isfinite(v); };
    require(spacing > 0 && finite(spacing), "spacing", spacing, "a finite value > 0 (m)");
    require(supportFactor >= Real(1.5) && supportFactor <= Real(6), "supportFactor", supportFactor,
            "1.5 to 6 particle spacings ([SB12]: 3)");
    require(restDensity > 0 && finite(restDensity), "restDensity", restDensity, "> 0 (kg/m^3)");
    require(stiffness > 0 && finite(stiffness), "stiffness", stiffness, "> 0 (Pa)");
    require(sph::isFinite(gravity), "gravity", gravity.length(), "finite components (m/s^2)");
    require(xsphEpsilon >= 0 && xsphEpsilon <= 1, "xsphEpsilon", xsphEpsilon,
            "0 to 1 ([SB12]: 0.05)");
    require(solidEpsilon >= 0 && solidEpsilon <= 1, "solidEpsilon", solidEpsilon, "0 to 1");
    require(airResampleSteps >= 1, "airResampleSteps", airResampleSteps, ">= 1 ([SB12]: about 10)");
    require(airKeepFraction >= 0 && finite(airKeepFraction), "airKeepFraction", airKeepFraction,
            ">= 0 (fraction of the Poisson radius)");
    require(basicXsphEpsilon >= 0 && basicXsphEpsilon <= 1, "basicXsphEpsilon", basicXsphEpsilon,
            "0 to 1 ([SB12]: 0.5)");
    require(basicViscosityAlpha >= 0 && finite(basicViscosityAlpha), "basicViscosityAlpha",
            basicViscosityAlpha, ">= 0 ([SB12]: 0.0005)");
    require(lennardJonesStrength >= 0 && finite(lennardJonesStrength), "lennardJonesStrength",
            lennardJonesStrength, ">= 0 (m^2/s^2; 0 = automatic)");
    require(frameRate > 0 && finite(frameRate), "frameRate", frameRate, "> 0 (frames/s)");
    require(substeps >= 0 && substeps <= 100000, "substeps", substeps,
            "0 (CFL-adaptive) to 100000");
    require(cflNumber > 0 && cflNumber <= 2, "cflNumber", cflNumber, "0 < cfl <= 2");
    require(maxSpeed >= 0 && finite(maxSpeed), "maxSpeed", maxSpeed,
            ">= 0 (m/s; 0 = 20 x sound speed)");
}

} // namespace ghost
} // namespace ghostfx
