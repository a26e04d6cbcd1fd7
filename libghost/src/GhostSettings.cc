/// @file   GhostSettings.cc
/// @brief  Method names, the settings tables and validation of the liquid solver settings.
#include "ghostfx/ghost/GhostSettings.h"

#include <ghostfx/sph/EnumNames.h>
#include <ghostfx/sph/Exceptions.h>
#include <ghostfx/sph/SettingCheck.h>
#include <ghostfx/sph/SettingSpec.h>

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

int GhostSettings::relaxationPasses(bool bodies) const
{
    if (initialRelaxation >= 0) return initialRelaxation;
    // DFSPH holds the density to a fraction of a percent: the sampled error is a kick.
    if (pressure == PressureModel::Dfsph || bodies) return 20;
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

namespace {

using LiquidRow = sph::SettingSpec<GhostSettings>;
using DfsphRow = sph::SettingSpec<DfsphSettings>;
using G = GhostSettings;
using D = DfsphSettings;

const sph::EnumName<SolidSlip> SOLID_SLIP_NAMES[] = {{SolidSlip::Free, "free"},
                                                     {SolidSlip::NoSlip, "no_slip"}};
using Relaxation = sph::PoissonSettings::Relaxation;
const sph::EnumName<Relaxation> RELAXATION_NAMES[] = {{Relaxation::Sb12, "sb12"},
                                                      {Relaxation::Packing, "packing"}};

/// The rows of the liquid itself: spacing, frames, pressure model and its material.
std::vector<LiquidRow> materialRows()
{
    return {
        LiquidRow::number(nullptr, "spacing", &G::spacing, sph::positive(), "m",
                          "particle spacing h (settings.spacing of the scene)"),
        LiquidRow::number(nullptr, "frameRate", &G::frameRate, sph::positive(), "frames/s",
                          "frames per second (settings.frame_rate of the scene)"),
        LiquidRow::choice<&G::pressure>("pressure", "pressure", sph::choicesOf(PRESSURE_NAMES),
                                        "liquid pressure model of method ghost"),
        LiquidRow::number("stiffness", "stiffness", &G::stiffness, sph::positive(), "Pa",
                          "Tait k: p = k ((rho / rho0)^7 - 1) ([SB12]: 2000)"),
        LiquidRow::number("rest_density", "restDensity", &G::restDensity, sph::positive(), "kg/m^3",
                          "rest density rho0"),
        LiquidRow::vector("gravity", "gravity", &G::gravity, "m/s^2", "gravity"),
        LiquidRow::number("viscosity", "viscosity", &G::viscosity, sph::between(0, 1e5), "m^2/s",
                          "kinematic viscosity nu, solved implicitly; 0 = none"),
        LiquidRow::number("viscosity_error", "viscosityError", &G::viscosityError,
                          sph::between(1e-10, 0.1), "",
                          "relative residual the viscosity solve stops at"),
        LiquidRow::number("viscosity_max_iterations", "viscosityMaxIterations",
                          &G::viscosityMaxIterations, sph::between(1, 100000), "",
                          "iteration cap of each viscosity solve"),
        LiquidRow::number("surface_tension", "surfaceTension", &G::surfaceTension,
                          sph::between(0, 1000), "N/m",
                          "surface tension coefficient sigma; 0 = none"),
    };
}

/// The rows of the method's own keys (kernel, XSPH, ghosts, Basic SPH, sampling).
std::vector<LiquidRow> methodRows()
{
    return {
        LiquidRow::number("kernel_support", "supportFactor", &G::supportFactor,
                          sph::between(1.5, 5), "h", "kernel support radius / h ([SB12]: 3)"),
        LiquidRow::number("xsph_epsilon", "xsphEpsilon", &G::xsphEpsilon, sph::between(0, 1), "",
                          "XSPH epsilon of [SB12] Eq. 2 among liquid particles"),
        LiquidRow::number("solid_epsilon", "solidEpsilon", &G::solidEpsilon, sph::between(0, 1), "",
                          "XSPH epsilon towards ghost solids, per reference step"),
        LiquidRow::number("initial_relaxation", "initialRelaxation", &G::initialRelaxation,
                          sph::between(0, 1000), "passes",
                          "relaxation passes towards rest density before the first step")
            .automaticWhenNegative(),
        LiquidRow::number("shifting", "shiftingCoefficient", &G::shiftingCoefficient,
                          sph::between(0, 20), "", "particle shifting coefficient A; 0 = off")
            .automaticWhenNegative(),
        LiquidRow::choice<&G::solidSlip>("solid_slip", "solidSlip",
                                         sph::choicesOf(SOLID_SLIP_NAMES),
                                         "boundary condition at solids ([SB12] Sec. 4.4)"),
        LiquidRow::number("air_resample_steps", "airResampleSteps", &G::airResampleSteps,
                          sph::between(1, 1000), "steps",
                          "ghost air resampling interval ([SB12]: about 10)"),
        LiquidRow::number("air_keep_fraction", "airKeepFraction", &G::airKeepFraction,
                          sph::between(0, 10), "r",
                          "air closer than this to the liquid is replaced at a resampling"),
        LiquidRow::number("basic_xsph_epsilon", "basicXsphEpsilon", &G::basicXsphEpsilon,
                          sph::between(0, 1), "", "Basic SPH: XSPH on positions ([SB12]: 0.5)"),
        LiquidRow::number("basic_viscosity_alpha", "basicViscosityAlpha", &G::basicViscosityAlpha,
                          sph::nonNegative(), "", "Basic SPH: Becker-Teschner viscosity alpha"),
        LiquidRow::number("lennard_jones_strength", "lennardJonesStrength",
                          &G::lennardJonesStrength, sph::nonNegative(), "m^2/s^2",
                          "Basic SPH: wall strength D; 0 = 5 |g| H"),
        LiquidRow::choice<&G::samplingRelaxation>("sampling_relaxation", "samplingRelaxation",
                                                  sph::choicesOf(RELAXATION_NAMES),
                                                  "volume relaxation of sampled bodies"),
        LiquidRow::flag("tiled_sampling", "tiledSampling", &G::tiledSampling,
                        "sample deep interiors from a relaxed periodic tile"),
    };
}

/// The rows of the liquid's own keys, in the order scenes and docs list them.
std::vector<LiquidRow> liquidRows()
{
    std::vector<LiquidRow> rows = materialRows();
    const std::vector<LiquidRow> method = methodRows();
    rows.insert(rows.end(), method.begin(), method.end());
    return rows;
}

} // namespace

const sph::SettingTable<GhostSettings>& liquidSettingTable()
{
    static const sph::SettingTable<GhostSettings> table =
        sph::withStepRows("liquid setting", liquidRows());
    return table;
}

namespace {

/// The rows of settings.dfsph.
std::vector<DfsphRow> dfsphRows()
{
    constexpr double GiB = 1024.0 * 1024.0 * 1024.0;
    return {
        DfsphRow::number("density_error", "dfsph.densityError", &D::densityError,
                         sph::between(1e-7, 0.1), "",
                         "mean density error the constant-density solve stops at"),
        DfsphRow::number("divergence_error", "dfsph.divergenceError", &D::divergenceError,
                         sph::between(1e-7, 1), "",
                         "mean density change per step the divergence solve stops at"),
        DfsphRow::number("density_relaxation", "dfsph.densityRelaxation", &D::densityRelaxation,
                         sph::between(1e-6, 1), "",
                         "share of the density error removed per step at CFL 0.4"),
        DfsphRow::choice<&D::airDensity>(
            "air_density", "dfsph.airDensity",
            {{"full", int(D::AirDensity::Full)}, {"fill", int(D::AirDensity::Fill)}},
            "how much of the ghost air a density counts"),
        DfsphRow::choice<&D::airResampling>(
            "air_resampling", "dfsph.airResampling",
            {{"step", int(D::AirResampling::Step)}, {"time", int(D::AirResampling::Time)}},
            "how often the ghost air is resampled"),
        DfsphRow::number("max_iterations", "dfsph.maxIterations", &D::maxIterations,
                         sph::between(1, 100000), "", "iteration cap of each solve"),
        DfsphRow::number("min_dt", "dfsph.minTimeStep", &D::minTimeStep, sph::between(1e-9, 1), "s",
                         "shortest CFL step"),
        DfsphRow::number("max_dt", "dfsph.maxTimeStep", &D::maxTimeStep, sph::between(1e-9, 1), "s",
                         "longest CFL step, at least min_dt"),
        DfsphRow::flag("warm_start", "dfsph.warmStart", &D::warmStart,
                       "start each solve from the last step's pressure"),
        DfsphRow::flag("divergence_warm_start", "dfsph.divergenceWarmStart",
                       &D::divergenceWarmStart,
                       "with warm_start: the divergence solve from its last pressure too"),
        DfsphRow::flag("keep_gradients", "dfsph.keepGradients", &D::keepGradients,
                       "keep the pairs' kernel gradients for the step's passes")
            .freeOnResume(),
        DfsphRow::number("kept_gradients_gb", "dfsph.keptGradientLimit", &D::keptGradientLimit,
                         sph::between(0, 1e6), "GiB",
                         "most memory the kept gradients may take; 0 = never keep")
            .scaled(GiB)
            .freeOnResume(),
    };
}

} // namespace

void checkOwnViscosity(Real nu, const std::string& what)
{
    const auto& rows = liquidSettingTable().rows;
    const auto row = std::find_if(rows.begin(), rows.end(), [](const auto& r) {
        return r.key && std::string(r.key) == "viscosity";
    });
    if (!row->range.contains(double(nu))) {
        throw ValueError(msg(what, ": viscosity = ", nu, ": expected ", row->expected(false),
                                  ", as settings.viscosity"));
    }
}

const sph::SettingTable<DfsphSettings>& dfsphSettingTable()
{
    static const sph::SettingTable<DfsphSettings> table{"liquid setting", dfsphRows()};
    return table;
}

void GhostSettings::validate() const
{
    sph::validateTable(liquidSettingTable(), *this);
    if (surfaceTension > Real(0) && method != Method::Ghost) {
        throw ValueError(msg("liquid setting surface_tension = ", surfaceTension,
                             " N/m with method 'basic': expected 0 (the surface force uses the "
                             "ghost air, which Basic SPH has not)"));
    }
    if (viscosity > Real(0) && method != Method::Ghost) {
        throw ValueError(msg("liquid setting viscosity = ", viscosity,
                             " m^2/s with method 'basic': expected 0 (Basic SPH has its own "
                             "artificial viscosity, basic_viscosity_alpha)"));
    }
    if (pressure != PressureModel::Dfsph) return;
    if (method != Method::Ghost) {
        throw ValueError("liquid setting pressure = 'dfsph' with method 'basic': "
                         "expected 'tait' (Basic SPH is [SB12]'s weakly compressible "
                         "baseline, with no air for a pressure solve's free surface)");
    }
    sph::validateTable(dfsphSettingTable(), dfsph);
    const sph::SettingCheck check("liquid setting");
    check.require(dfsph.maxTimeStep >= dfsph.minTimeStep, "dfsph.maxTimeStep", dfsph.maxTimeStep,
                  msg("at least dfsph.minTimeStep (", dfsph.minTimeStep, " s)").c_str());
}

} // namespace ghost
} // namespace ghostfx
