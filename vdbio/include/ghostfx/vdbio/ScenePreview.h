/// @file   ScenePreview.h
/// @brief  A preview of a whole scene: solids, liquid and gas in their own colours, one camera
///         framed on the scene.
/// @details `ghostfx run` writes one per frame (outputs.preview): the solids' level sets in a
///          warm grey, the liquid surface in blue (or its density as blue fog), gas as white fog,
///          so a reader can tell the tomato from a fountain. A small ray caster of its own: per
///          pixel, the nearest level-set hit of any surface layer (OpenVDB's
///          LevelSetRayIntersector, a moving solid's ray taken into its own frame), shaded by one
///          key light (Lambert plus ambient), then the fog layers marched in front of it (single
///          scattering without shadows). Transparent background, premultiplied alpha.
#pragma once

#include <cstdint>

#include <ghostfx/vdbio/Preview.h>

#include <openvdb/openvdb.h>

#include <array>
#include <string>
#include <utility>
#include <vector>

namespace ghostfx {
namespace vdbio {

/// One thing a scene preview draws.
struct PreviewLayer
{
    enum class Kind { Surface, Fog };

    std::string name;                  ///< for messages
    openvdb::FloatGrid::ConstPtr grid; ///< a level set (Surface) or a fog volume (Fog)
    Kind kind = Kind::Surface;
    std::array<float, 3> albedo{{0.6f, 0.6f, 0.6f}}; ///< linear RGB
    /// Fog layers: extinction at density 1 (1/m); 0: PreviewOptions::extinction.
    double extinction = 0;
    /// Rigid placement of the grid's frame in the world, x_world = rotation x + translation (a
    /// moving solid's shape lives in its own frame); identity for grids already in the world.
    openvdb::math::Mat3d rotation = openvdb::math::Mat3d::identity();
    openvdb::Vec3d translation{0.0};
    /// A container (a tank around the liquid): its outer hull and every face the camera sees
    /// from behind are skipped, so the camera looks through the near walls and lid at the inner
    /// faces of the far walls and floor. Surface layers only.
    bool cutaway = false;
    /// The same grid at the same placement in every frame of a sequence (a static solid): its
    /// surface hits may be kept between frames in a PreviewCache. Surface layers only.
    bool fixed = false;
};

/// Surface hits of the fixed layers, per pixel, kept from one frame's preview to the next
/// while the camera and those layers stay the same (they are recomputed when either changes).
/// A preview drawn with a cache is identical to one drawn without.
struct PreviewCache
{
    std::vector<double> key;            ///< camera, image size and fixed layers' placements
    std::vector<const void*> grids;     ///< the fixed layers' grids
    std::vector<double> t;              ///< per pixel: distance to the nearest fixed-layer hit
    std::vector<std::uint32_t> layer;   ///< per pixel: its layer index, or the layer count
    std::vector<openvdb::Vec3d> normal; ///< per pixel: its world normal
    /// Per pixel: the camera ray's direction (world) and the colour of the fixed layers alone
    /// over the background, so a pixel whose ray misses every other layer is copied.
    std::vector<openvdb::Vec3f> direction;
    std::vector<std::array<float, 4>> base;
    /// The active voxel boxes of the fixed layers' grids (index space), by grid.
    std::vector<std::pair<const void*, openvdb::CoordBBox>> activeBoxes;
    std::size_t reused = 0, computed = 0; ///< previews that used the hits, that computed them
};

/// The colours `ghostfx run` gives solids, a liquid (surface or density), gas and whitewater.
constexpr std::array<float, 3> SOLID_ALBEDO{{0.62f, 0.58f, 0.52f}};
constexpr std::array<float, 3> LIQUID_ALBEDO{{0.18f, 0.42f, 0.85f}};
constexpr std::array<float, 3> GAS_ALBEDO{{0.92f, 0.92f, 0.95f}};
constexpr std::array<float, 3> WHITEWATER_ALBEDO{{1.0f, 1.0f, 1.0f}};

struct ScenePreviewSummary
{
    /// Per layer (in order): pixels whose nearest surface it is (surface layers), or pixels
    /// it covers by more than 5 % opacity (fog layers).
    std::vector<std::size_t> pixels;
    double seconds = 0; ///< ray casting time (s), without file I/O
};

/// Render `layers` with `options` (size, azimuth, elevation, fog extinction; `grid` unused) to
/// `path` (.exr, or .png for an 8-bit sRGB image), atomically. The camera frames `bounds`
/// (world, m); an empty box frames the union of the layers' active voxels. Throws ValueError
/// for bad options or no layers, GridError for a layer that is not a float grid of its kind
/// with cubic voxels, IoError if the image cannot be written.
/// With `cache`, the fixed layers' hits come from it when the camera and those layers match
/// the last preview drawn with it, and are stored in it otherwise.
ScenePreviewSummary renderScenePreview(const std::vector<PreviewLayer>& layers,
                                       const PreviewOptions& options, const openvdb::BBoxd& bounds,
                                       const std::string& path, PreviewCache* cache = nullptr);

} // namespace vdbio
} // namespace ghostfx
