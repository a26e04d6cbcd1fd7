/// @file   PreviewDetail.h
/// @brief  What the single-grid preview (Preview.cc) and the scene preview (ScenePreview.cc)
///         share: the camera placement, the key light and the image writers.
#pragma once

#include <ghostfx/vdbio/Preview.h>

#include <openvdb/tools/RayTracer.h>

#include <string>

namespace ghostfx {
namespace vdbio {
namespace detail {

/// PerspectiveCamera's defaults (Houdini's default camera): 50 mm lens, 41.2136 mm aperture.
constexpr double FOCAL_LENGTH_MM = 50.0;
constexpr double APERTURE_MM = 41.2136;
/// Level sets: the share of light that reaches faces turned from the key light.
constexpr float SURFACE_AMBIENT = 0.2f;

/// Where the camera sits and where the key light comes from.
struct CameraSetup
{
    openvdb::Vec3R eye, target, up;
    openvdb::Vec3R toLight; ///< unit vector from the scene towards the key light
    double nearPlane = 1e-3, farPlane = 1e30;
};

/// Place the camera (options.azimuth, options.elevation) so the bounding sphere of the world box
/// [wmin, wmax] fills the frame, the key light above and to the left of it.
CameraSetup frameBox(const openvdb::Vec3R& wmin, const openvdb::Vec3R& wmax,
                     const PreviewOptions& options);

/// Lambert shade of a hit with normal `normal` seen along `rayDir` (two-sided), in [ambient, 1].
float keyLightShade(const CameraSetup& setup, openvdb::Vec3R normal, const openvdb::Vec3R& rayDir);

/// Fail before rendering if the image cannot be created where asked.
void checkImagePath(const std::string& path);

/// Write `film` atomically: an 8-bit sRGB PNG for a .png path, else a half-float RGBA EXR.
void writeImage(const openvdb::tools::Film& film, const std::string& path);

} // namespace detail
} // namespace vdbio
} // namespace ghostfx
