/// @file   GasSettings.cc
/// @brief  Method names, settings tables and validation of the gas solver and the phase
///         transition settings ([RYY15]).
#include "ghostfx/gas/GasSettings.h"
#include "ghostfx/gas/PhaseTransition.h"

#include <ghostfx/sph/EnumNames.h>
#include <ghostfx/sph/Exceptions.h>
#include <ghostfx/sph/SettingCheck.h>
#include <ghostfx/sph/SettingSpec.h>

#include <algorithm>
#include <cmath>
#include <limits>

namespace ghostfx {
namespace gas {

namespace {

const sph::EnumName<Method> METHOD_NAMES[] = {
    {Method::Fast, "fast"}, {Method::Ambient, "ambient"}, {Method::Uncorrected, "uncorrected"}};
const sph::EnumName<Turbulence> TURBULENCE_NAMES[] = {{Turbulence::Automatic, "auto"},
                                                      {Turbulence::None, "none"},
                                                      {Turbulence::Entrainment, "entrainment"}};
const sph::EnumName<Falloff> FALLOFF_NAMES[] = {{Falloff::InverseSquare, "inverse_square"},
                                                {Falloff::Constant, "constant"}};

} // namespace

const char* methodName(Method method) { return sph::nameOf(METHOD_NAMES, method); }

Method methodFromName(const std::string& name)
{
    return sph::valueOf(METHOD_NAMES, name, "gas method");
}

const char* turbulenceName(Turbulence turbulence)
{
    return sph::nameOf(TURBULENCE_NAMES, turbulence);
}

Turbulence turbulenceFromName(const std::string& name)
{
    return sph::valueOf(TURBULENCE_NAMES, name, "gas turbulence model");
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

namespace {

using Row = sph::SettingSpec<GasSettings>;
using G = GasSettings;

/// The rows of the gas's own keys: discretisation, Eqs. 11-17, vorticity, isolated particles.
std::vector<Row> gasRows()
{
    return {
        Row::number("spacing", "spacing", &G::spacing, sph::positive(), "m", "gas particle spacing")
            .shownDefault("settings.spacing (boiling: h (rho_l / rho_g / 12)^(1/3))"),
        Row::number(nullptr, "frameRate", &G::frameRate, sph::positive(), "frames/s",
                    "frames per second (settings.frame_rate of the scene)"),
        Row::number("kernel_support", "supportFactor", &G::supportFactor, sph::between(1.5, 5),
                    "spacings", "support radius / spacing"),
        Row::number("particle_mass", "particleMass", &G::particleMass, sph::nonNegative(), "kg",
                    "particle mass; 0 = automatic (a block at rest starts at rho0)"),
        Row::number("rest_density", "restDensity", &G::restDensity, sph::positive(), "kg/m^3",
                    "rho0 of the gas ([RYY15] Sec. 6: 1/1000 of the liquid's)"),
        Row::number("kappa", "kappa", &G::kappa, sph::positive(), "m^2/s^2",
                    "Eq. 11 stiffness, p = kappa (rho - rho0)"),
        Row::flag("clamp_negative_pressure", "clampNegativePressure", &G::clampNegativePressure,
                  "clamp Eq. 11 at p >= 0: a gas cannot pull"),
        Row::number("delta", "delta", &G::delta, sph::between(0.4, 0.7), "h",
                    "virtual particle distance of Eqs. 5-8 ([RYY15] Sec. 3.1)"),
        Row::number("atmospheric_pressure", "atmosphericPressure", &G::atmosphericPressure,
                    sph::nonNegative(), "Pa", "P_a of Eqs. 12-13"),
        Row::number("interior_pressure_scale", "interiorPressureScale", &G::interiorPressureScale,
                    sph::between(0, 1), "", "beta of Sec. 5"),
        Row::number("normal_threshold", "normalThreshold", &G::normalThreshold, sph::above(0, 10),
                    "", "C_N of Eq. 14, on |n| h"),
        Row::number("damping", "damping", &G::damping, sph::nonNegative(), "1/s",
                    "C_d of Eq. 14: the drag of the air not simulated")
            .automaticWhenNegative(),
        Row::number("viscosity", "viscosity", &G::viscosity, sph::nonNegative(), "Pa s",
                    "dynamic viscosity of Eq. 22"),
        Row::vector("gravity", "gravity", &G::gravity, "m/s^2",
                    "gravity; zero: the missing atmosphere would cancel the gas's weight"),
        Row::number("ambient_temperature", "ambientTemperature", &G::ambientTemperature,
                    sph::positive(), "K", "temperature buoyancy and radiation act against"),
        Row::number("diffusion", "diffusion", &G::diffusion, sph::nonNegative(), "kg/(m s)",
                    "D_c of Eq. 15; 0 = off"),
        Row::number("radiation_time", "radiationTime", &G::radiationTime, sph::nonNegative(), "s",
                    "D_r of Eq. 16; 0 = off"),
        Row::number("buoyancy", "buoyancy", &G::buoyancy, sph::nonNegative(), "m/s^2 per K",
                    "C_b of Eq. 17"),
        Row::vector("buoyancy_direction", "buoyancyDirection", &G::buoyancyDirection, "",
                    "b of Eq. 17, non-zero"),
        Row::flag("vorticity", "vorticity", &G::vorticity, "artificial vorticity, Eqs. 25-26"),
        Row::number("vorticity_generation", "vorticityGeneration", &G::vorticityGeneration,
                    sph::nonNegative(), "m", "beta of Eq. 25"),
        Row::number("vorticity_strength", "vorticityStrength", &G::vorticityStrength,
                    sph::nonNegative(), "1/s", "scale of Eq. 26's vortex velocity"),
        Row::choice<&G::turbulence>("turbulence", "turbulence", sph::choicesOf(TURBULENCE_NAMES),
                                    "the eddies below the spacing: auto (entrainment; none for "
                                    "the ambient baseline), none, entrainment"),
        Row::number("entrainment", "entrainment", &G::entrainment, sph::between(0, 1), "",
                    "alpha of the entrainment model: air joins the gas boundary at alpha |v|"),
        Row::number("life_strength", "lifeStrength", &G::lifeStrength, sph::nonNegative(), "s",
                    "how long an isolated particle lives (Sec. 5); 0 = forever"),
    };
}

} // namespace

const sph::SettingTable<GasSettings>& gasSettingTable()
{
    static const sph::SettingTable<GasSettings> table = sph::withStepRows("gas setting", gasRows());
    return table;
}

namespace {

using PhaseRow = sph::SettingSpec<PhaseSettings>;
using P = PhaseSettings;

/// The rows of phase_transition (and the two fields only a library user sets).
std::vector<PhaseRow> phaseRows()
{
    return {
        PhaseRow::number("boiling_point", "boilingPoint", &P::boilingPoint, sph::positive(), "K",
                         "boiling point T_b"),
        PhaseRow::number("initial_temperature", "initialTemperature", &P::initialTemperature,
                         sph::positive(), "K", "temperature of the liquid at the start"),
        PhaseRow::number("latent_heat", "latentHeat", &P::latentHeat, sph::nonNegative(), "K",
                         "L / c_p absorbed at T_b before a particle boils"),
        PhaseRow::number("heater_band", "heaterBand", &P::heaterBand, sph::positive(), "m",
                         "liquid this close to a heater is heated")
            .shownDefault("1.5 h"),
        PhaseRow::number("heating_time", "heatingTime", &P::heatingTime, sph::positive(), "s",
                         "relaxation time towards the heater temperature"),
        PhaseRow::number("conductivity", "conductivity", &P::conductivity, sph::nonNegative(),
                         "kg/(m s)", "Eq. 15 diffusion among liquid particles"),
        PhaseRow::number(nullptr, "diffusionEpsilon", &P::diffusionEpsilon, sph::positive(), "",
                         "gamma^2 of Eq. 15 / the squared support radius"),
        PhaseRow::number("evaporation_rate", "evaporationRate", &P::evaporationRate,
                         sph::nonNegative(), "1/s",
                         "evaporation splits per second of a surface particle at T_b"),
        PhaseRow::number("evaporation_onset", "evaporationOnset", &P::evaporationOnset,
                         sph::positive(), "K", "nothing evaporates below it; below T_b"),
        PhaseRow::number("surface_threshold", "surfaceThreshold", &P::surfaceThreshold,
                         sph::positive(), "", "colour-field gradient of a surface particle"),
        PhaseRow::number(nullptr, "liquidResplitEpsilon", &P::liquidResplitEpsilon, sph::positive(),
                         "", "epsilon of the default liquid re-split"),
        PhaseRow::number("merge_every_steps", "mergeEverySteps", &P::mergeEverySteps,
                         sph::between(1, 100000), "steps",
                         "merging by mass decentration (Eqs. 19-20) every this many steps"),
    };
}

} // namespace

const sph::SettingTable<PhaseSettings>& phaseSettingTable()
{
    static const sph::SettingTable<PhaseSettings> table{"phase setting", phaseRows()};
    return table;
}

namespace {

/// Throw ValueError for the first attractor with a bad position, strength or radius.
void validateAttractors(const std::vector<Attractor>& attractors)
{
    const sph::SettingCheck check("gas setting");
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
}

} // namespace

void PhaseSettings::validate() const
{
    sph::validateTable(phaseSettingTable(), *this);
    if (!(evaporationOnset < boilingPoint)) {
        throw ValueError(msg("phase setting evaporationOnset = ", evaporationOnset,
                             " K: expected below boilingPoint = ", boilingPoint, " K"));
    }
    if (evaporationPattern && !evaporationPattern->hasCentre) {
        throw ValueError(msg("phase setting evaporationPattern '", evaporationPattern->name,
                             "' has no centre daughter: evaporation keeps the centre as liquid "
                             "([RYY15] Sec. 4.2)"));
    }
    merge.validate();
}

void GasSettings::validate() const
{
    sph::validateTable(gasSettingTable(), *this);
    const sph::SettingCheck check("gas setting");
    check.require(buoyancyDirection.length() > Real(1e-6), "buoyancyDirection",
                  buoyancyDirection.length(), "a finite non-zero vector");
    validateAttractors(attractors);
    if (turbulence == Turbulence::Entrainment && method == Method::Ambient) {
        throw ValueError(msg("gas setting turbulence = 'entrainment' with method 'ambient': "
                             "expected 'none' or 'auto' (the ambient baseline simulates the air "
                             "it would draw in)"));
    }
    if (method == Method::Ambient) {
        const Vec3 e = domain.extent();
        check.require(
            !domain.empty() && e[0] >= 2 * supportRadius() && e[1] >= 2 * supportRadius()
                && e[2] >= 2 * supportRadius(),
            "domain extent", domain.empty() ? 0.0 : double(std::min({e[0], e[1], e[2]})),
            "a box at least two kernel radii wide on every axis (m) for method 'ambient'");
    }
}

} // namespace gas
} // namespace ghostfx
