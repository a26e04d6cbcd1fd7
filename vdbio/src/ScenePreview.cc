/// @file   ScenePreview.cc
/// @brief  The scene preview's ray caster (ScenePreview.h).
#include <ghostfx/vdbio/ScenePreview.h>

#include "PreviewDetail.h"

#include <ghostfx/sph/Exceptions.h>

#include <openvdb/tools/Interpolation.h>
#include <openvdb/tools/RayIntersector.h>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <limits>
#include <memory>

namespace ghostfx {
namespace vdbio {

using openvdb::Vec3d;
using openvdb::tools::Film;

namespace {

using Ray = openvdb::math::Ray<double>;
using Intersector = openvdb::tools::LevelSetRayIntersector<openvdb::FloatGrid>;
using Sampler =
    openvdb::tools::GridSampler<openvdb::FloatGrid::ConstAccessor, openvdb::tools::BoxSampler>;

/// Fog stops being marched once less than this much light gets through.
constexpr double OPAQUE_TRANSMITTANCE = 0.01;
/// Fog is sampled every this many voxels along a ray: a density rasterised with an SPH kernel
/// of support 2-3 h (4-6 voxels at the default h / 2) varies little within two voxels.
constexpr double FOG_STEP_VOXELS = 2.0;
/// Fog: the light a voxel scatters towards the camera, as a share of its albedo (no shadows).
constexpr float FOG_SHADE = 0.85f;

/// The box of a layer's active voxels `ibox` (the grid's active voxel box: their extent, every
/// corner through the grid's transform and then, with `placed`, the layer's placement); empty
/// for an empty grid.
openvdb::BBoxd layerBox(const PreviewLayer& layer, const openvdb::CoordBBox& ibox, bool placed)
{
    openvdb::BBoxd box;
    if (ibox.empty()) return box;
    const Vec3d lo = ibox.min().asVec3d() - Vec3d(0.5), hi = ibox.max().asVec3d() + Vec3d(0.5);
    for (int corner = 0; corner < 8; ++corner) {
        const Vec3d c((corner & 1) ? hi.x() : lo.x(), (corner & 2) ? hi.y() : lo.y(),
                      (corner & 4) ? hi.z() : lo.z());
        const Vec3d w = layer.grid->transform().indexToWorld(c);
        box.expand(placed ? layer.rotation * w + layer.translation : w);
    }
    return box;
}

bool isEmpty(const openvdb::BBoxd& box) { return !(box.max().x() >= box.min().x()); }

/// Crossings of a cutaway layer skipped along one ray, at most (near wall in and out, a lid...).
constexpr int MAX_CUTAWAY_CROSSINGS = 8;

/// A cutaway layer's face worth drawing: the ray enters the solid there (the normal, outward
/// from the solid, faces the ray) and it is not on the outer hull (more than 1.5 voxels inside
/// the surface's box, the layer's box less its narrow band `band`): the inner face of a
/// container's far wall or floor.
bool isInnerFace(const Vec3d& xyz, const Vec3d& normal, const Vec3d& dir, const openvdb::BBoxd& box,
                 double voxel, double band)
{
    if (normal.dot(dir) >= 0) return false;
    const double margin = band + 1.5 * voxel;
    for (int a = 0; a < 3; ++a) {
        if (xyz[a] < box.min()[a] + margin || xyz[a] > box.max()[a] - margin) return false;
    }
    return true;
}

/// A ray of the world taken into a layer's own frame (rotation^T (x - translation)).
Ray intoLayer(const Ray& world, const PreviewLayer& layer)
{
    const openvdb::math::Mat3d back = layer.rotation.transpose();
    Ray local(back * (world.eye() - layer.translation), back * world.dir());
    local.setTimes(world.t0(), world.t1());
    return local;
}

void checkLayer(const PreviewLayer& layer)
{
    const std::string where = msg("preview layer '", layer.name, "'");
    if (!layer.grid) throw ValueError(msg(where, ": no grid"));
    if (!layer.grid->hasUniformVoxels()) {
        throw GridError(msg(where, " has non-uniform voxels ", layer.grid->voxelSize(),
                            ": preview needs cubic voxels"));
    }
    if (layer.kind == PreviewLayer::Kind::Surface
        && layer.grid->getGridClass() != openvdb::GRID_LEVEL_SET) {
        throw GridError(msg(where, " is drawn as a surface but is not a level set"));
    }
}

/// Per task: an intersector for every surface layer and a sampler for every fog layer (neither
/// is thread-safe: they cache tree nodes).
struct Tracers
{
    std::vector<std::unique_ptr<Intersector>> surfaces; ///< null for fog layers
    std::vector<std::unique_ptr<openvdb::FloatGrid::ConstAccessor>> accessors;
    std::vector<std::unique_ptr<Sampler>> fogs; ///< null for surface layers

    explicit Tracers(const std::vector<PreviewLayer>& layers)
    {
        for (const PreviewLayer& l : layers) {
            const bool surface = l.kind == PreviewLayer::Kind::Surface;
            surfaces.push_back(surface ? std::make_unique<Intersector>(*l.grid) : nullptr);
            accessors.push_back(
                std::make_unique<openvdb::FloatGrid::ConstAccessor>(l.grid->getConstAccessor()));
            fogs.push_back(surface
                               ? nullptr
                               : std::make_unique<Sampler>(*accessors.back(), l.grid->transform()));
        }
    }
};

/// Where the layers lie: each in its own frame (fog is marched inside it), and the world box
/// the camera frames.
struct LayerBoxes
{
    std::vector<openvdb::BBoxd> local; ///< per layer: its active voxels in its own frame
    std::vector<double> voxel;         ///< per layer: its voxel size (m)
    openvdb::BBoxd frame;              ///< what the camera frames (world, m)
};

/// The active voxel box (index space) of `layer`'s grid. The walk covers the whole tree, so a
/// fixed layer's box is taken from `cache` when it is there and kept in it when it is not.
openvdb::CoordBBox activeBox(const PreviewLayer& layer, PreviewCache* cache)
{
    const bool kept = cache && layer.fixed;
    if (kept) {
        for (const auto& [grid, box] : cache->activeBoxes) {
            if (grid == layer.grid.get()) return box;
        }
    }
    const openvdb::CoordBBox ibox = layer.grid->evalActiveVoxelBoundingBox();
    if (kept) cache->activeBoxes.emplace_back(layer.grid.get(), ibox);
    return ibox;
}

/// Every layer's box and voxel size; the frame is `bounds`, or with an empty `bounds` the
/// union of the placed layers' boxes.
LayerBoxes measureLayers(const std::vector<PreviewLayer>& layers, const openvdb::BBoxd& bounds,
                         PreviewCache* cache)
{
    LayerBoxes boxes;
    const bool frameLayers = !(bounds.max().x() > bounds.min().x());
    boxes.frame = frameLayers ? openvdb::BBoxd() : bounds;
    for (const PreviewLayer& l : layers) {
        const openvdb::CoordBBox ibox = activeBox(l, cache);
        boxes.local.push_back(layerBox(l, ibox, false));
        boxes.voxel.push_back(l.grid->voxelSize()[0]);
        const openvdb::BBoxd placed = layerBox(l, ibox, true);
        if (frameLayers && !isEmpty(placed)) boxes.frame.expand(placed);
    }
    return boxes;
}

/// The surface layers whose hits a cache may keep, and what those hits depend on.
struct FixedLayers
{
    std::vector<std::uint8_t> fixed; ///< per layer: a fixed surface layer
    std::vector<const void*> grids;  ///< the fixed layers' grids
    /// The camera, the image size, the layer count, the background and each fixed layer's
    /// index, placement and cutaway flag.
    std::vector<double> key;
};

/// The fixed surface layers of `layers` seen by the camera `setup` on `film`.
FixedLayers fixedLayers(const std::vector<PreviewLayer>& layers, const detail::CameraSetup& setup,
                        const Film& film, const PreviewOptions& options)
{
    const std::size_t n = layers.size();
    FixedLayers f;
    f.fixed.assign(n, 0);
    f.key = {setup.eye.x(),         setup.eye.y(),    setup.eye.z(),  setup.target.x(),
             setup.target.y(),      setup.target.z(), setup.up.x(),   setup.up.y(),
             setup.up.z(),          setup.nearPlane,  setup.farPlane, double(film.width()),
             double(film.height()), double(n)};
    for (float c : options.background) f.key.push_back(double(c));
    for (std::size_t k = 0; k < n; ++k) {
        f.fixed[k] = layers[k].fixed && layers[k].kind == PreviewLayer::Kind::Surface;
        if (!f.fixed[k]) continue;
        f.grids.push_back(layers[k].grid.get());
        f.key.push_back(double(k));
        for (int i = 0; i < 3; ++i) {
            for (int j = 0; j < 3; ++j) f.key.push_back(layers[k].rotation(i, j));
            f.key.push_back(layers[k].translation[i]);
        }
        f.key.push_back(layers[k].cutaway ? 1.0 : 0.0);
    }
    return f;
}

/// Whether `cache` holds the hits of `fixed` for `pixelCount` pixels; if not, it is emptied
/// for them (no hit anywhere) to be filled by this preview. Counts the use in `cache`.
bool prepareCache(PreviewCache* cache, const FixedLayers& fixed, std::size_t pixelCount,
                  std::size_t layerCount)
{
    if (!cache) return false;
    const bool reuse =
        cache->key == fixed.key && cache->grids == fixed.grids && cache->t.size() == pixelCount;
    if (!reuse) {
        cache->key = fixed.key;
        cache->grids = fixed.grids;
        cache->t.assign(pixelCount, std::numeric_limits<double>::max());
        cache->layer.assign(pixelCount, std::uint32_t(layerCount));
        cache->normal.assign(pixelCount, Vec3d(0.0));
        cache->direction.assign(pixelCount, openvdb::Vec3f(0.0f));
        cache->base.assign(pixelCount, {0.0f, 0.0f, 0.0f, 0.0f});
    }
    ++(reuse ? cache->reused : cache->computed);
    return reuse;
}

/// The fog layers' boxes, to tell whether a camera ray's line misses all of them.
class FogBoxes
{
public:
    /// The non-empty fog layers of `layers` (boxes `local`) seen from `eye` (world, m).
    FogBoxes(const std::vector<PreviewLayer>& layers, const std::vector<openvdb::BBoxd>& local,
             const Vec3d& eye)
    {
        for (std::size_t k = 0; k < layers.size(); ++k) {
            if (layers[k].kind == PreviewLayer::Kind::Surface || isEmpty(local[k])) continue;
            FogBox f;
            f.back = layers[k].rotation.transpose();
            f.eye = f.back * (eye - layers[k].translation);
            const Vec3d size = local[k].max() - local[k].min();
            const double margin = 1e-6 * (size.length() + f.eye.length()) + 1e-9;
            f.lo = local[k].min() - Vec3d(margin);
            f.hi = local[k].max() + Vec3d(margin);
            mBoxes.push_back(f);
        }
    }

    /// Whether the line from the eye along `dirF` (world) misses every box (slab test).
    bool missedBy(const openvdb::Vec3f& dirF) const
    {
        const Vec3d dir(dirF.x(), dirF.y(), dirF.z());
        for (const FogBox& f : mBoxes) {
            const Vec3d d = f.back * dir;
            double tmin = 0, tmax = std::numeric_limits<double>::max();
            for (int a = 0; a < 3; ++a) {
                if (std::abs(d[a]) < 1e-12) {
                    if (f.eye[a] < f.lo[a] || f.eye[a] > f.hi[a]) tmax = -1;
                    continue;
                }
                double t1 = (f.lo[a] - f.eye[a]) / d[a], t2 = (f.hi[a] - f.eye[a]) / d[a];
                if (t1 > t2) std::swap(t1, t2);
                tmin = std::max(tmin, t1);
                tmax = std::min(tmax, t2);
            }
            // The stored direction is a float copy: a line that passes within the margin
            // counts as a hit.
            if (tmax >= tmin * (1 - 1e-6) - 1e-9) return false;
        }
        return true;
    }

private:
    struct FogBox
    {
        openvdb::math::Mat3d back; ///< world to layer rotation
        Vec3d eye;                 ///< the camera in the layer's frame
        Vec3d lo, hi;              ///< the layer's box, grown by a margin
    };
    std::vector<FogBox> mBoxes;
};

/// The nearest surface along a ray: its distance (m), its layer (the layer count for none) and
/// its world normal.
struct SurfaceHit
{
    double t;
    std::size_t layer;
    Vec3d normal;
};

/// What reaches the camera along a ray: the shaded surface (alpha 1 where there is one), the
/// light the fog scatters and the fog's transmittance in front of the surface.
struct PixelLight
{
    float r = 0, g = 0, b = 0, surfaceAlpha = 0;
    float fr = 0, fg = 0, fb = 0;
    float tr = 1.0f;
};

/// `light` over the background `bg` (premultiplied RGBA): what the surface leaves uncovered
/// shows it.
std::array<float, 4> overBackground(const PixelLight& light, const std::array<float, 4>& bg)
{
    const PixelLight& l = light;
    const float behind = l.tr * (1 - l.surfaceAlpha);
    return {l.fr + l.tr * l.r + behind * bg[0] * bg[3], l.fg + l.tr * l.g + behind * bg[1] * bg[3],
            l.fb + l.tr * l.b + behind * bg[2] * bg[3],
            (1 - l.tr) + l.tr * l.surfaceAlpha + behind * bg[3]};
}

/// One preview's ray caster: the layers, the camera and the cache whose hits it reads or fills.
class Raycaster
{
public:
    Raycaster(const std::vector<PreviewLayer>& layers, const PreviewOptions& options,
              const detail::CameraSetup& setup, const LayerBoxes& boxes, const FixedLayers& fixed,
              PreviewCache* cache, bool reuse)
        : mLayers(layers)
        , mOptions(options)
        , mSetup(setup)
        , mBoxes(boxes)
        , mFixed(fixed.fixed)
        , mCache(cache)
        , mReuse(reuse)
        , mN(layers.size())
    {
        // A kept pixel whose ray cannot meet any other layer is the fixed layers' colour,
        // copied without casting its ray: when no surface layer moves and the ray's line misses
        // every fog layer's box (grown by a rounding margin, so a ray the full test would count
        // as a hit is never skipped). The picture is the same (ScenePreview tests).
        mCopyable = reuse;
        for (std::size_t k = 0; k < mN; ++k) {
            if (layers[k].kind == PreviewLayer::Kind::Surface && !mFixed[k]) mCopyable = false;
        }
        if (mCopyable) mFogBoxes = std::make_unique<FogBoxes>(layers, boxes.local, setup.eye);
    }

    /// Draw rows `rows` of `film` seen by `camera`, adding to `counts` the pixels per layer
    /// (ScenePreviewSummary::pixels).
    void drawRows(const tbb::blocked_range<std::size_t>& rows, Film& film,
                  const openvdb::tools::PerspectiveCamera& camera,
                  std::vector<std::size_t>& counts) const
    {
        Tracers tracers(mLayers);
        for (std::size_t y = rows.begin(); y != rows.end(); ++y) {
            for (std::size_t x = 0; x < film.width(); ++x) {
                const std::size_t pixel = y * film.width() + x;
                std::array<float, 4> c;
                if (mCopyable && mFogBoxes->missedBy(mCache->direction[pixel])) {
                    c = mCache->base[pixel];
                    if (mCache->layer[pixel] < mN) ++counts[mCache->layer[pixel]];
                } else {
                    c = trace(camera.getRay(x, y), pixel, tracers, counts);
                }
                film.pixel(x, y) = Film::RGBA(c[0], c[1], c[2], c[3]);
            }
        }
    }

private:
    /// The colour of `pixel` seen along `ray`: its nearest surface (the fixed layers' hit kept
    /// in the cache, or computed and stored there, then the other surface layers), shaded, with
    /// the fog in front of it.
    std::array<float, 4> trace(const Ray& ray, std::size_t pixel, Tracers& tracers,
                               std::vector<std::size_t>& counts) const
    {
        SurfaceHit hit{std::numeric_limits<double>::max(), mN, Vec3d(0.0)};
        if (mReuse) {
            hit.t = mCache->t[pixel];
            hit.layer = mCache->layer[pixel];
            hit.normal = mCache->normal[pixel];
        } else {
            nearestSurface(ray, tracers, true, hit);
            if (mCache) {
                mCache->t[pixel] = hit.t;
                mCache->layer[pixel] = std::uint32_t(hit.layer);
                mCache->normal[pixel] = hit.normal;
                mCache->direction[pixel] = openvdb::Vec3f(ray.dir());
                mCache->base[pixel] = overBackground(shade(hit, ray.dir()), mOptions.background);
            }
        }
        nearestSurface(ray, tracers, false, hit);
        PixelLight light = shade(hit, ray.dir());
        if (hit.layer < mN) ++counts[hit.layer];
        marchFog(ray, tracers, hit.t, light, counts);
        return overBackground(light, mOptions.background);
    }

    /// `hit` shaded by the key light, seen along `dir`, without fog.
    PixelLight shade(const SurfaceHit& hit, const Vec3d& dir) const
    {
        PixelLight light;
        if (hit.layer < mN) {
            const float s = detail::keyLightShade(mSetup, hit.normal, dir);
            const auto& a = mLayers[hit.layer].albedo;
            light.r = a[0] * s, light.g = a[1] * s, light.b = a[2] * s, light.surfaceAlpha = 1;
        }
        return light;
    }

    /// Bring `hit` to the nearest crossing of `ray` with a fixed (`fixedPass`) or a moving
    /// surface layer, if one is nearer.
    void nearestSurface(const Ray& ray, Tracers& tracers, bool fixedPass, SurfaceHit& hit) const
    {
        for (std::size_t k = 0; k < mN; ++k) {
            if (!tracers.surfaces[k] || bool(mFixed[k]) != fixedPass) continue;
            const Ray local = intoLayer(ray, mLayers[k]);
            Vec3d xyz, normal;
            if (!drawnCrossing(local, *tracers.surfaces[k], k, xyz, normal)) continue;
            const double t = (xyz - local.eye()).length();
            if (t < hit.t) {
                hit.t = t;
                hit.layer = k;
                hit.normal = mLayers[k].rotation * normal;
            }
        }
    }

    /// The first crossing of `local` (in layer `k`'s frame) with its surface that is drawn:
    /// any crossing, or for a cutaway layer an inner face. Its point and normal go to `xyz` and
    /// `normal`; false when there is none.
    bool drawnCrossing(Ray local, const Intersector& surface, std::size_t k, Vec3d& xyz,
                       Vec3d& normal) const
    {
        const PreviewLayer& layer = mLayers[k];
        const double voxel = mBoxes.voxel[k];
        for (int crossing = 0; crossing < MAX_CUTAWAY_CROSSINGS; ++crossing) {
            if (!surface.intersectsWS(local, xyz, normal)) return false;
            if (!layer.cutaway
                || isInnerFace(xyz, normal, local.dir(), mBoxes.local[k], voxel,
                               double(layer.grid->background()))) {
                return true;
            }
            // Past this crossing, and look for the next one.
            const double along = (xyz - local.eye()).dot(local.dir()) / local.dir().lengthSqr();
            local.setTimes(along + 1.5 * voxel / local.dir().length(), local.t1());
        }
        return false;
    }

    /// The fog in front of the surface at distance `nearest` along `ray`: each fog layer's box
    /// marched up to it, its light and transmittance added to `light`.
    void marchFog(const Ray& ray, Tracers& tracers, double nearest, PixelLight& light,
                  std::vector<std::size_t>& counts) const
    {
        double transmittance = 1;
        for (std::size_t k = 0; k < mN; ++k) {
            if (!tracers.fogs[k]) continue;
            const Ray local = intoLayer(ray, mLayers[k]);
            double tin = 0, tout = 0;
            if (isEmpty(mBoxes.local[k]) || !local.intersects(mBoxes.local[k], tin, tout)) continue;
            tout = std::min(tout, nearest);
            const double step = FOG_STEP_VOXELS * mLayers[k].grid->voxelSize()[0];
            const double extinction =
                mLayers[k].extinction > 0 ? mLayers[k].extinction : mOptions.extinction;
            const double before = transmittance;
            for (double t = std::max(tin, 0.0) + 0.5 * step; t < tout; t += step) {
                const double d = tracers.fogs[k]->wsSample(local(t));
                if (!(d > 0)) continue;
                const double pass = std::exp(-extinction * d * step);
                const float scattered = float(transmittance * (1 - pass)) * FOG_SHADE;
                light.fr += scattered * mLayers[k].albedo[0];
                light.fg += scattered * mLayers[k].albedo[1];
                light.fb += scattered * mLayers[k].albedo[2];
                transmittance *= pass;
                if (transmittance < OPAQUE_TRANSMITTANCE) break;
            }
            if (before - transmittance > 0.05) ++counts[k];
        }
        light.tr = float(transmittance);
    }

    const std::vector<PreviewLayer>& mLayers;
    const PreviewOptions& mOptions;
    const detail::CameraSetup& mSetup;
    const LayerBoxes& mBoxes;
    const std::vector<std::uint8_t>& mFixed;
    PreviewCache* mCache;
    bool mReuse;
    bool mCopyable;
    std::unique_ptr<FogBoxes> mFogBoxes;
    std::size_t mN;
};

} // namespace

ScenePreviewSummary renderScenePreview(const std::vector<PreviewLayer>& layers,
                                       const PreviewOptions& options, const openvdb::BBoxd& bounds,
                                       const std::string& path, PreviewCache* cache)
{
    options.validate();
    if (layers.empty()) throw ValueError(msg("preview '", path, "': nothing to draw"));
    for (const PreviewLayer& l : layers) checkLayer(l);
    detail::checkImagePath(path);

    const LayerBoxes boxes = measureLayers(layers, bounds, cache);
    if (isEmpty(boxes.frame)) {
        throw GridError(msg("preview '", path, "': every layer is empty, nothing to frame"));
    }
    const detail::CameraSetup setup =
        detail::frameBox(boxes.frame.min(), boxes.frame.max(), options);
    Film film(std::size_t(options.width), std::size_t(options.height),
              Film::RGBA(0.0f, 0.0f, 0.0f, 0.0f));
    openvdb::tools::PerspectiveCamera camera(film, Vec3d(0.0), setup.eye, detail::FOCAL_LENGTH_MM,
                                             detail::APERTURE_MM, setup.nearPlane, setup.farPlane);
    camera.lookAt(setup.target, setup.up);

    // Fixed surface layers are intersected first, then the others: the same order with or
    // without a cache, so the nearest hit (ties included) does not depend on it.
    const FixedLayers fixed = fixedLayers(layers, setup, film, options);
    const bool reuse = prepareCache(cache, fixed, film.width() * film.height(), layers.size());
    const Raycaster raycaster(layers, options, setup, boxes, fixed, cache, reuse);

    std::vector<std::atomic<std::size_t>> pixels(layers.size());
    for (auto& p : pixels) p = 0;
    const auto t0 = std::chrono::steady_clock::now();
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, film.height()), [&](const auto& rows) {
        std::vector<std::size_t> counts(layers.size(), 0);
        raycaster.drawRows(rows, film, camera, counts);
        for (std::size_t k = 0; k < counts.size(); ++k) pixels[k] += counts[k];
    });
    ScenePreviewSummary summary;
    summary.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    for (auto& p : pixels) summary.pixels.push_back(p.load());
    detail::writeImage(film, path);
    return summary;
}

} // namespace vdbio
} // namespace ghostfx
