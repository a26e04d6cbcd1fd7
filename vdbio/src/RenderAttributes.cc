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
    if (holdsLiquid(options)) {
        names.push_back("vorticity");
        names.push_back("curvature");
    }
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
    if (name != "pscale" && (!(options.kernelSupport > 0) || !std::isfinite(options.kernelSupport))) {
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
    const std::vector<sph::Real> values = name == "vorticity"
                                              ? sph::vorticityMagnitude(particles, selection, es)
                                              : sph::meanCurvature(particles, selection, es);
    return std::vector<float>(values.begin(), values.end());
}

} // namespace detail

namespace {

/// The render attributes `options` asks for that sum over neighbours and that `particles`
/// does not carry as channels.
std::vector<std::string> neighbourAttributes(const sph::ParticleSet& particles,
                                             const PointsOptions& options)
{
    const std::vector<std::string> names = detail::renderAttributeNames(options);
    std::vector<std::string> out;
    for (const std::string& name : options.channels) {
        if ((name == "vorticity" || name == "curvature")
            && std::find(names.begin(), names.end(), name) != names.end()
            && !particles.hasScalarChannel(name) && !particles.hasVectorChannel(name)) {
            out.push_back(name);
        }
    }
    return out;
}

} // namespace

bool needsNeighbourAttributes(const sph::ParticleSet& particles, const PointsOptions& options)
{
    return !neighbourAttributes(particles, options).empty();
}

double neighbourAttributeReach(const sph::ParticleSet& particles, const PointsOptions& options)
{
    // Curvature differentiates normals that differentiate the colour field, itself a sum over
    // neighbours: three support radii in all.
    double reach = 0;
    for (const std::string& name : neighbourAttributes(particles, options))
        reach = std::max(reach, (name == "curvature" ? 3.0 : 1.0) * options.kernelSupport);
    return reach;
}

sph::ParticleSet withNeighbourAttributes(const sph::ParticleSet& particles, std::size_t count,
                                         const PointsOptions& options)
{
    std::vector<sph::Index> first(std::min(count, particles.size()));
    for (std::size_t k = 0; k < first.size(); ++k) first[k] = sph::Index(k);
    std::vector<std::uint8_t> keep(particles.size(), 0);
    std::fill(keep.begin(), keep.begin() + first.size(), std::uint8_t(1));
    sph::ParticleSet out = particles.select(keep);
    for (const std::string& name : neighbourAttributes(particles, options)) {
        detail::checkRenderAttribute(particles, options, name, "points output");
        const std::vector<float> values = detail::renderAttribute(particles, first, options, name);
        std::vector<sph::Real>& channel = out.addScalarChannel(name);
        for (std::size_t k = 0; k < values.size(); ++k) channel[k] = sph::Real(values[k]);
    }
    return out;
}

} // namespace vdbio
} // namespace ghostfx
