/// @file   Scene.h
/// @brief  Scenes: a versioned JSON file (or a .vdb whose grids carry roles) read into
///         level sets, motions, emitters and output requests, ready for a solver.
/// @details The reader is strict (JsonReader.h): unknown keys, wrong types and values out of
///          range stop the read with one line naming the file, the key path and what was
///          expected. Level sets are read from .vdb files by file and grid name, relative to the
///          scene's folder, and validated (class, uniform voxels, finite values); built-in shapes
///          (sphere, box, container) need no input files.
///
///          vdbio knows no solver: the solver-specific part of `settings` is left to the caller,
///          who reads it from Scene::settings and then calls Scene::settings.finish() so that a
///          misspelt key there is reported too.
///
///          A minimal scene:
///          @code{.json}
///          { "ghostfx_scene": 1,
///            "settings": { "method": "ghost", "spacing": 0.02, "frame_range": [1, 48] },
///            "solids":  [ { "name": "tank", "geometry": { "container": { "min": [0,0,0], "max": [1,1,0.4] } } } ],
///            "liquids": [ { "name": "water", "geometry": { "file": "water.vdb", "grid": "surface" } } ] }
///          @endcode
///          The full format is in docs/scene-format.md.
#pragma once

#include <ghostfx/sph/KeyedMotion.h>
#include <ghostfx/sph/LevelSet.h>
#include <ghostfx/sph/Types.h>
#include <ghostfx/vdbio/JsonReader.h>
#include <ghostfx/vdbio/SurfaceMethod.h>

#include <openvdb/math/Mat3.h>

#include <array>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace ghostfx {
namespace vdbio {

/// Version of the scene format this ghostfx reads.
constexpr int SCENE_FORMAT_VERSION = 1;

/// Metadata key of a grid's role in a role-tagged .vdb scene ("solid", "liquid", "emitter", "source").
constexpr const char* ROLE_METADATA = "ghostfx_role";

/// The largest frame number a scene or `--frames` may name: frame files carry the number in
/// their names and frames count in an int; ten million frames is days of film at any rate.
constexpr int MAX_FRAME = 9999999;

/// The finest particle spacing a scene may ask for (m): grids use voxels of half the spacing,
/// and OpenVDB refuses transforms whose voxels are below about 1.5e-5 m (the determinant of the
/// scale must exceed 3e-15).
constexpr double MIN_SPACING = 4e-5;

/// What every shaped entry of a scene has: a name, where its shape came from, and the shape.
struct SceneShape
{
    SceneShape(std::string name_, std::string geometry_, sph::LevelSet shape_)
        : name(std::move(name_))
        , geometry(std::move(geometry_))
        , shape(std::move(shape_))
    {}

    std::string name;
    std::string geometry; ///< where the shape came from, for messages and reports
    sph::LevelSet shape;
};

/// A solid's `dynamic` object: a uniform rigid body the liquid moves and that moves it
/// (ghost::DynamicSolid), given by exactly one of its density or its mass.
struct SceneDynamic
{
    double density = 0;            ///< kg/m^3; 0 when the mass is given
    double mass = 0;               ///< kg; 0 when the density is given
    sph::Vec3d velocity{0};        ///< initial, of the centre of mass (m/s)
    sph::Vec3d angularVelocity{0}; ///< initial (rad/s)
    double restitution = 0.2;      ///< of the normal velocity at a contact, 0 to 1
    double friction = 0.5;         ///< Coulomb coefficient of its contacts, >= 0
};

struct SceneSolid : SceneShape
{
    using SceneShape::SceneShape;

    sph::Vec3d velocity{0}; ///< constant velocity (m/s), if no keys
    sph::KeyedMotion motion;     ///< keyed rigid motion (empty: constant velocity)
    /// Per-frame shapes (deforming solid): file pattern with $F and grid name; empty if static.
    std::string sequenceFile, sequenceGrid;
    /// A rigid body moved by the liquid and its contacts (no velocity, motion or sequence);
    /// empty: the solid follows its velocity or motion.
    std::optional<SceneDynamic> dynamic;

    /// Neither moves nor changes shape.
    bool isStatic() const
    {
        return !dynamic && sequenceFile.empty() && motion.keys.empty()
               && velocity == sph::Vec3d(0.0);
    }
};

struct SceneLiquid : SceneShape
{
    using SceneShape::SceneShape;

    sph::Vec3d velocity{0};
    /// The liquid's own kinematic viscosity (m^2/s); none: settings.viscosity. The solver
    /// checks its range (settings.viscosity's).
    std::optional<double> viscosity;
};

struct SceneEmitter : SceneShape
{
    using SceneShape::SceneShape;

    sph::Vec3d velocity{0}; ///< of the liquid leaving it, in its own frame (m/s)
    double start = 0, end = std::numeric_limits<double>::infinity();
    std::optional<double> viscosity; ///< of the new liquid, as SceneLiquid's
    sph::KeyedMotion motion; ///< a moving emitter (a hose sweeping a floor); empty: static
};

/// A gas source ([RYY15]): keeps its volume filled with gas at `temperature` (K) moving at
/// `velocity`, optionally limited to `rate` particles per second, between `start` and `end`.
struct SceneGasSource : SceneShape
{
    using SceneShape::SceneShape;

    sph::Vec3d velocity{0};
    double temperature = 373.15;
    double rate = 0; ///< particles per second; 0: keep the volume full
    double start = 0, end = std::numeric_limits<double>::infinity();
    sph::KeyedMotion motion; ///< a moving source (the paper's steam train); empty: static
};

/// A heater for the liquid-gas phase transition: liquid near it is heated towards `temperature`.
struct SceneHeater : SceneShape
{
    using SceneShape::SceneShape;

    double temperature = 400;
};

/// A point attractor of `force_fields` ([RYY15] Fig. 7, the "magic attractor"): pulls gas
/// towards `position` (m) with `strength` (m/s^2) at the core radius `radius` (m), linearly
/// inside the core and with `falloff` ("inverse_square" or "constant") outside. The formula is
/// gas::Attractor's (libgas/include/ghostfx/gas/GasSettings.h); docs/scene-format.md.
struct SceneAttractor
{
    sph::Vec3d position{0};
    double strength = 0;
    double radius = 0.1;
    std::string falloff = "inverse_square";
};

/// One entry of the scene's `force_fields`: a name and exactly one kind of field (so far:
/// `attractor`). Fields act on gas: gas scenes and the vapour of boiling scenes.
struct SceneForceField
{
    std::string name;
    SceneAttractor attractor;
};

/// What to write per frame. Paths are frame patterns relative to `directory`; empty = off.
struct SceneOutputs
{
    std::string directory = "out";
    // Points: a PointDataGrid "particles".
    std::string pointsFile = "liquid_points.$F4.vdb";
    std::vector<std::string> pointChannels{"v", "id", "density", "pressure"};
    bool pointGhosts = false; ///< also write ghost air / ghost solid particles (with "kind")
    // Volumes.
    std::string volumeFile = "liquid.$F4.vdb";
    std::vector<std::string> volumeGrids{"surface", "density", "vel"};
    SurfaceMethod surfaceMethod = SurfaceMethod::Spheres; ///< of the liquid surface
    double voxelSize = 0;        ///< of the surface; 0: half the particle spacing
    double densityVoxelSize = 0; ///< of density, vel, temperature; 0: the particle spacing
    /// Also every solid's level set where it is at the frame, a grid named after the solid.
    bool volumeSolids = false;
    // Liquid surface as a triangle mesh (MeshFile.h), .ply or .obj by the name's extension;
    // the volume's surface, whether or not the volume file is written. Empty: off.
    std::string meshFile;
    double meshAdaptivity = 0; ///< tools::volumeToMesh's adaptivity, 0 to 1
    /// The surface meshed: the volume's method and voxel size (0: h / 2), which a scene may set
    /// in outputs.mesh only where no volume file is written (or to the same values).
    SurfaceMethod meshSurfaceMethod = SurfaceMethod::Spheres;
    double meshVoxelSize = 0;
    // Whitewater (liquid scenes): spray, foam and bubbles made from the liquid each frame
    // (ghost::Whitewater), as points; empty: off (no whitewater is simulated).
    std::string whitewaterFile;
    /// Their fog grids "spray", "foam", "bubbles" in a file of their own (volume files hold no
    /// points), at this voxel size (m); 0: no fog file.
    std::string whitewaterFogFile = "whitewater_fog.$F4.vdb";
    double whitewaterFogVoxelSize = 0;
    double whitewaterRadius = 0; ///< "pscale" of the points (m); 0: a quarter of the spacing
    // Gas (gas scenes and boiling): points and volumes of the gas particles.
    std::string gasPointsFile = "gas_points.$F4.vdb";
    std::vector<std::string> gasPointChannels{"v", "id", "temperature"};
    std::string gasVolumeFile = "gas.$F4.vdb";
    std::vector<std::string> gasVolumeGrids{"density", "temperature", "vel"};
    double gasVoxelSize = 0; ///< 0: the gas particle spacing
    // Preview image of the scene (ScenePreview.h): solids, the liquid and the gas.
    std::string previewFile;
    std::string
        previewGrid; ///< the medium's grid to draw; "": liquid surface (else density), gas density
    int previewWidth = 640, previewHeight = 360;
    bool previewSolids = true;                         ///< draw the solids (containers cut away)
    double previewAzimuth = 30, previewElevation = 20; ///< camera direction (degrees)
    sph::Aabb previewFrame; ///< the world box the camera frames; empty: everything drawn
    /// Opaque colour behind the scene (linear RGB); none: a transparent background.
    std::optional<std::array<double, 3>> previewBackground =
        std::array<double, 3>{0.16, 0.17, 0.19};
    // HDF5 checkpoint every N frames (0: only at the end and on interruption).
    std::string checkpointFile = "checkpoint.$F4.h5";
    int checkpointEvery = 10;
    // Per-step statistics (HDF5, and a CSV beside it).
    std::string statsFile = "stats.h5";
};

struct Scene
{
    std::string file;   ///< the scene file as given
    std::string folder; ///< folder input paths are relative to
    int version = SCENE_FORMAT_VERSION;

    /// The document after `-D` overrides.
    std::shared_ptr<const Json> document;
    /// The settings object; the caller reads its solver-specific keys, then calls finish().
    JsonObject settings;

    // Settings every solver shares.
    std::string
        method; ///< settings.method: a name in the program's method registry (cmd/Methods.h), not checked here
    double spacing = 0;    ///< particle spacing h (m)
    double frameRate = 30; ///< frames per second
    int firstFrame = 1,
        lastFrame = 24; ///< frames written; frame f is the state at t = f / frameRate

    sph::Aabb killBox; ///< empty: none
    std::vector<SceneSolid> solids;
    std::vector<SceneLiquid> liquids;
    std::vector<SceneEmitter> emitters;
    std::vector<SceneGasSource> gasSources;
    std::vector<SceneHeater> heaters;
    std::vector<SceneForceField> forceFields;
    /// The `phase_transition` object (boiling / evaporation settings), read by the caller when
    /// the scene has heaters; empty otherwise.
    JsonObject phaseTransition;
    SceneOutputs outputs;

    /// Canonical JSON text of everything that changes the simulation (all but `outputs`, the
    /// frame range and the keys at the JSON pointers `freeOnResume`, "/settings/max_speed"):
    /// stored in checkpoints, compared on resume.
    std::string simulationFingerprint(const std::vector<std::string>& freeOnResume = {}) const;
};

/// Read a scene: a .json scene file, or a .vdb whose level-set grids carry a ROLE_METADATA
/// string (a complete scene with default settings). `overrides` are `path=value` assignments
/// applied to the document before reading (`-D` on the command line).
Scene readScene(const std::string& path, const std::vector<std::string>& overrides = {});

/// A keyed rigid motion from its object `{ "keys": [ { "time", "translate", "rotate" }, ... ] }`
/// (a solid's or a gas source's `motion`): keys in increasing time, at least one. Errors name the
/// key by the object's path.
sph::KeyedMotion readMotion(const JsonObject& motion);

/// Read and validate one level-set grid from a .vdb file; `context` names the scene key in
/// messages ("solids[0].geometry").
sph::LevelSet loadLevelSet(const std::string& file, const std::string& grid,
                           const std::string& context);

} // namespace vdbio
} // namespace ghostfx
