/// @file   Preview.h
/// @brief  Quick EXR or PNG previews of a surface (level set) or density (fog volume) grid.
/// @details A look-dev aid, not a renderer: one directional key light, no global illumination.
///          Fog volumes go through OpenVDB's tools::VolumeRender (single scattering with shadow
///          rays), level sets through tools::LevelSetRayTracer with a Lambertian shader. The
///          camera is placed automatically: it looks at the centre of the grid's active bounding
///          box from the direction given by azimuth and elevation, far enough away that the
///          box's bounding sphere fills the frame. The background is transparent (RGBA = 0), so
///          the alpha channel is the coverage of the grid. Images are written atomically as
///          half-float RGBA OpenEXR (premultiplied alpha, the EXR convention), or as an 8-bit
///          sRGB PNG for a path ending in .png.
#pragma once

#include <openvdb/openvdb.h>

#include <array>
#include <string>
#include <vector>

namespace ghostfx {
namespace vdbio {

/// What to render and from where. Every field is checked by validate().
struct PreviewOptions
{
    /// Grid to render; "" picks the liquid's "surface" if present, else "density", else the
    /// first float grid.
    std::string grid;
    /// Image size (pixels), each in [1, 16384].
    int width = 640, height = 360;
    /// Camera direction (degrees) as seen from the bounding-box centre, y up: azimuth turns
    /// about +y, starting on +z (0 = camera on the +z side looking towards -z); elevation lifts
    /// the camera above the xz-plane, in [-90, 90].
    double azimuth = 30, elevation = 20;
    /// Extinction of a fog volume at density 1 (1/m). The default 10 /m gives a 0.2 m thick body
    /// of normalised liquid density an optical depth of 2 (86 % opaque). Must be > 0.
    double extinction = 10;
    /// Colour behind the scene (linear RGB and alpha, each in [0, 1]); the default is
    /// transparent. The scene preview (ScenePreview.h) composites the image over it; the
    /// single-grid preview ignores it.
    std::array<float, 4> background{{0.0f, 0.0f, 0.0f, 0.0f}};

    /// Throws ValueError naming the field and the bad value.
    void validate() const;
};

/// What renderPreview() did, for the command line's summary.
struct PreviewSummary
{
    std::string gridName;
    std::string gridClass; ///< "fog volume" or "level set"
    openvdb::Index64 activeVoxels = 0;
    double seconds = 0; ///< ray tracing time (s), without file I/O
};

/// Render `grid` and write `exrPath` atomically. A FloatGrid of class fog volume (or of unknown
/// class with a zero background) is volume-rendered; one of class level set is ray traced.
/// Throws GridError for other grid types or classes, non-uniform voxels or an empty grid, and
/// IoError if the image cannot be written.
PreviewSummary renderPreview(const openvdb::GridBase& grid, const PreviewOptions& options,
                             const std::string& exrPath);

/// Read the grid chosen by `options.grid` from `vdbPath` and render it as renderPreview() does.
/// Errors name the file and the grid; a missing grid lists the grids that are present.
PreviewSummary renderPreviewFromFile(const std::string& vdbPath, const PreviewOptions& options,
                                     const std::string& exrPath);

/// An RGBA image in float, rows from the top, as read back from an EXR file.
struct RgbaImage
{
    int width = 0, height = 0;
    std::vector<float> rgba; ///< 4 floats per pixel, row-major from the top-left pixel

    const float* pixel(int x, int y) const { return &rgba[4 * (std::size_t(y) * width + x)]; }
};

/// Read an RGBA OpenEXR image (any channels missing read as R = G = B = 0, A = 1), or a .png
/// written by the preview (its stored 8-bit sRGB values / 255).
/// Throws IoError naming the file if it cannot be read.
RgbaImage readExrImage(const std::string& exrPath);

} // namespace vdbio
} // namespace ghostfx
