/// @file   RenderAttributes.cc
#include "RenderAttributes.h"

#include <ghostfx/sph/Exceptions.h>
#include <ghostfx/sph/Parallel.h>
#include <ghostfx/sph/ParticleAge.h>
#include <ghostfx/sph/RenderEstimates.h>

#include <algorithm>
#include <cmath>

namespace ghostfx {
namespace vdbio {
namespace detail {

namespace {

bool holdsLiquid(const PointsOptions& options)
{
    return std::find(options.kinds.begin(), options.kinds.end(), sph::ParticleKind::Liquid)
           != options.kinds.end();
}

std::vector<float> ages(const sph::ParticleSet& p, const std::vector<sph::Index>& selection,
                        double time)
{
    const std::vector<sph::Real>& birth = p.scalarChannel(sph::BIRTH_TIME_CHANNEL);
    std::vector<float> out(selection.size());
    parallel::forEach(
        0, selection.size(),
        [&](std::size_t k) { out[k] = float(time - double(birth[selection[k]])); }, 4096);
    return out;
}

std::vector<float> radii(const sph::ParticleSet& p, const std::vector<sph::Index>& selection,
                         double restDensity)
{
    // The sphere of volume m / rho0: V = 4/3 pi r^3.
    const double perMass = 3.0 / (4.0 * 3.14159265358979323846 * restDensity);
    std::vector<float> out(selection.size());
    parallel::forEach(
        0, selection.size(),
        [&](std::size_t k) { out[k] = float(std::cbrt(double(p.masses()[selection[k]]) * perMass)); },
        4096);
    return out;
}

} // namespace

std::vector<std::string> renderAttributeNames(const PointsOptions& options)
{
    std::vector<std::string> names{"age", "pscale"};
    if (holdsLiquid(options)) names.push_back("vorticity");
    return names;
}

bool checkRenderAttribute(const sph::ParticleSet& particles, const PointsOptions& options,
                          const std::string& name, const std::string& where)
{
    const std::vector<std::string> names = renderAttributeNames(options);
    if (std::find(names.begin(), names.end(), name) == names.end()) return false;
    if (name == "age") {
        if (!particles.hasScalarChannel(sph::BIRTH_TIME_CHANNEL)) {
            throw ValueError(msg(where, ": channel 'age': the particles carry no birth times ('",
                                 sph::BIRTH_TIME_CHANNEL, "' channel)"));
        }
        return true;
    }
    if (!(options.restDensity > 0) || !std::isfinite(options.restDensity)) {
        throw ValueError(msg(where, ": channel '", name, "': rest density = ", options.restDensity,
                             " kg/m^3: expected a finite value > 0"));
    }
    if (name == "vorticity" && (!(options.kernelSupport > 0) || !std::isfinite(options.kernelSupport))) {
        throw ValueError(msg(where, ": channel '", name, "': kernel support = ",
                             options.kernelSupport, " m: expected a finite value > 0"));
    }
    return true;
}

std::vector<float> renderAttribute(const sph::ParticleSet& particles,
                                   const std::vector<sph::Index>& selection,
                                   const PointsOptions& options, const std::string& name)
{
    if (name == "age") return ages(particles, selection, options.time);
    if (name == "pscale") return radii(particles, selection, options.restDensity);
    sph::EstimateSettings es;
    es.supportRadius = sph::Real(options.kernelSupport);
    es.restDensity = sph::Real(options.restDensity);
    es.kind = sph::ParticleKind::Liquid;
    const std::vector<sph::Real> values = sph::vorticityMagnitude(particles, selection, es);
    return std::vector<float>(values.begin(), values.end());
}

} // namespace detail
} // namespace vdbio
} // namespace ghostfx
