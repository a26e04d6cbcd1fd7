/// @file   RenderAttributes.h
/// @brief  Point attributes computed at output time for rendering: "age", "pscale",
///         "vorticity" and "curvature" (PointsOptions::channels; docs/scene-format.md,
///         outputs.points).
/// @details None of them is a solver quantity; each is computed from the particle set as it is
///          when the points are written:
///          - age (s) = PointsOptions::time - the particle's birth time (sph::BIRTH_TIME_CHANNEL,
///            ParticleAge.h);
///          - pscale (m) = (3 m / (4 pi rho0))^(1/3), the radius of the sphere of the particle's
///            own volume m / rho0 (Houdini's pscale is a radius);
///          - vorticity (1/s) = |curl v|, the corrected SPH estimate over the liquid neighbours
///            within the kernel support (sph::vorticityMagnitude, RenderEstimates.h);
///          - curvature (1/m): the mean curvature of the liquid surface at the particles of its
///            surface layer, 0 inside (sph::meanCurvature).
#pragma once

#include <ghostfx/sph/ParticleSet.h>
#include <ghostfx/vdbio/FrameFiles.h>

#include <string>
#include <vector>

namespace ghostfx {
namespace vdbio {
namespace detail {

/// The render attributes `options` can write (vorticity and curvature only on points that
/// hold liquid).
std::vector<std::string> renderAttributeNames(const PointsOptions& options);

/// True when `name` is a render attribute of `options`. Throws ValueError (prefixed by
/// `where`) when it is one that `particles` or `options` cannot give: no birth times for
/// "age", no rest density or kernel support for the others.
bool checkRenderAttribute(const sph::ParticleSet& particles, const PointsOptions& options,
                          const std::string& name, const std::string& where);

/// Values of render attribute `name` at the particles `selection` (checked beforehand).
std::vector<float> renderAttribute(const sph::ParticleSet& particles,
                                   const std::vector<sph::Index>& selection,
                                   const PointsOptions& options, const std::string& name);

} // namespace detail
} // namespace vdbio
} // namespace ghostfx
