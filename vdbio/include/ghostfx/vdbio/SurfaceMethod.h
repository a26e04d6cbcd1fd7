/// @file   SurfaceMethod.h
/// @brief  How the liquid surface level set is built from particles, and the method names used
///         in scenes (`outputs.volume.surface_method`) and messages.
/// @details A light header (no OpenVDB grids), so Scene.h can hold the choice without pulling in
///          FrameFiles.h:
///          - "spheres": union of spheres, closed and smoothed (SurfaceGrid.cc; Zhu and Bridson
///            2005, "Animating sand as a fluid");
///          - "anisotropic": anisotropic kernels stretched along the local particle distribution
///            (AnisotropicSurface.cc; Yu and Turk, "Reconstructing surfaces of particle-based
///            fluids using anisotropic kernels", SCA 2010 / ACM TOG 32(1) 2013).
#pragma once

#include <ghostfx/sph/EnumNames.h>

#include <string>
#include <vector>

namespace ghostfx {
namespace vdbio {

/// The liquid surface reconstruction of VolumeOptions::surfaceMethod.
enum class SurfaceMethod { Spheres, Anisotropic };

/// Scene and message names of the surface methods.
inline constexpr sph::EnumName<SurfaceMethod> SURFACE_METHOD_NAMES[] = {
    {SurfaceMethod::Spheres, "spheres"},
    {SurfaceMethod::Anisotropic, "anisotropic"},
};

/// The names of SURFACE_METHOD_NAMES in table order ("spheres", "anisotropic").
inline std::vector<std::string> surfaceMethodNames()
{
    std::vector<std::string> names;
    for (const auto& e : SURFACE_METHOD_NAMES) names.emplace_back(e.name);
    return names;
}

} // namespace vdbio
} // namespace ghostfx
