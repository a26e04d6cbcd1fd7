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

} // namespace

ScenePreviewSummary renderScenePreview(const std::vector<PreviewLayer>& layers,
                                       const PreviewOptions& options, const openvdb::BBoxd& bounds,
                                       const std::string& path, PreviewCache* cache)
{
    options.validate();
    if (layers.empty()) throw ValueError(msg("preview '", path, "': nothing to draw"));
    for (const PreviewLayer& l : layers) checkLayer(l);
    detail::checkImagePath(path);

    // Fog layers are marched inside their own box (in the layer's frame).
    std::vector<openvdb::BBoxd> localBoxes;
    std::vector<double> voxel;
    const bool frameLayers = !(bounds.max().x() > bounds.min().x());
    openvdb::BBoxd frame = frameLayers ? openvdb::BBoxd() : bounds;
    for (const PreviewLayer& l : layers) {
        // The active voxel box walks the whole tree: a fixed layer's is kept in the cache.
        openvdb::CoordBBox ibox;
        bool known = false;
        if (cache && l.fixed) {
            for (const auto& [grid, box] : cache->activeBoxes) {
                if (grid == l.grid.get()) ibox = box, known = true;
            }
        }
        if (!known) {
            ibox = l.grid->evalActiveVoxelBoundingBox();
            if (cache && l.fixed) cache->activeBoxes.emplace_back(l.grid.get(), ibox);
        }
        localBoxes.push_back(layerBox(l, ibox, false));
        voxel.push_back(l.grid->voxelSize()[0]);
        const openvdb::BBoxd placed = layerBox(l, ibox, true);
        if (frameLayers && !isEmpty(placed)) frame.expand(placed);
    }
    if (isEmpty(frame)) {
        throw GridError(msg("preview '", path, "': every layer is empty, nothing to frame"));
    }
    const detail::CameraSetup setup = detail::frameBox(frame.min(), frame.max(), options);
    Film film(std::size_t(options.width), std::size_t(options.height),
              Film::RGBA(0.0f, 0.0f, 0.0f, 0.0f));
    openvdb::tools::PerspectiveCamera camera(film, Vec3d(0.0), setup.eye, detail::FOCAL_LENGTH_MM,
                                             detail::APERTURE_MM, setup.nearPlane, setup.farPlane);
    camera.lookAt(setup.target, setup.up);

    const std::size_t n = layers.size();
    // Fixed surface layers are intersected first, then the others: the same order with or
    // without a cache, so the nearest hit (ties included) does not depend on it.
    std::vector<std::uint8_t> fixed(n, 0);
    std::vector<double> key = {setup.eye.x(),         setup.eye.y(),    setup.eye.z(),
                               setup.target.x(),      setup.target.y(), setup.target.z(),
                               setup.up.x(),          setup.up.y(),     setup.up.z(),
                               setup.nearPlane,       setup.farPlane,   double(film.width()),
                               double(film.height()), double(n)};
    for (float c : options.background) key.push_back(double(c));
    std::vector<const void*> fixedGrids;
    for (std::size_t k = 0; k < n; ++k) {
        fixed[k] = layers[k].fixed && layers[k].kind == PreviewLayer::Kind::Surface;
        if (!fixed[k]) continue;
        fixedGrids.push_back(layers[k].grid.get());
        key.push_back(double(k));
        for (int i = 0; i < 3; ++i) {
            for (int j = 0; j < 3; ++j) key.push_back(layers[k].rotation(i, j));
            key.push_back(layers[k].translation[i]);
        }
        key.push_back(layers[k].cutaway ? 1.0 : 0.0);
    }
    const std::size_t pixelCount = film.width() * film.height();
    const bool reuse =
        cache && cache->key == key && cache->grids == fixedGrids && cache->t.size() == pixelCount;
    if (cache && !reuse) {
        cache->key = key;
        cache->grids = fixedGrids;
        cache->t.assign(pixelCount, std::numeric_limits<double>::max());
        cache->layer.assign(pixelCount, std::uint32_t(n));
        cache->normal.assign(pixelCount, Vec3d(0.0));
        cache->direction.assign(pixelCount, openvdb::Vec3f(0.0f));
        cache->base.assign(pixelCount, {0.0f, 0.0f, 0.0f, 0.0f});
    }
    // A kept pixel whose ray cannot meet any other layer is the fixed layers' colour, copied
    // without casting its ray: when no surface layer moves, and the ray's line misses every fog
    // layer's box (grown by a rounding margin, so a ray the full test would count as a hit is
    // never skipped). The picture is the same (ScenePreview tests).
    bool copyable = reuse;
    for (std::size_t k = 0; k < n; ++k) {
        if (layers[k].kind == PreviewLayer::Kind::Surface && !fixed[k]) copyable = false;
    }
    struct FogBox
    {
        openvdb::math::Mat3d back; ///< world to layer rotation
        Vec3d eye;                 ///< the camera in the layer's frame
        Vec3d lo, hi;              ///< the layer's box, grown by a margin
    };
    std::vector<FogBox> fogBoxes;
    for (std::size_t k = 0; copyable && k < n; ++k) {
        if (layers[k].kind == PreviewLayer::Kind::Surface || isEmpty(localBoxes[k])) continue;
        FogBox f;
        f.back = layers[k].rotation.transpose();
        f.eye = f.back * (setup.eye - layers[k].translation);
        const Vec3d size = localBoxes[k].max() - localBoxes[k].min();
        const double margin = 1e-6 * (size.length() + f.eye.length()) + 1e-9;
        f.lo = localBoxes[k].min() - Vec3d(margin);
        f.hi = localBoxes[k].max() + Vec3d(margin);
        fogBoxes.push_back(f);
    }
    auto missesFog = [&](const openvdb::Vec3f& dirF) {
        const Vec3d dir(dirF.x(), dirF.y(), dirF.z());
        for (const FogBox& f : fogBoxes) {
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
    };
    if (cache) ++(reuse ? cache->reused : cache->computed);
    // The colour of a pixel with only its fixed-layer hit and no fog, over the background: the
    // same arithmetic as the full path below with transmittance 1, so a copied pixel is
    // bit-identical to one traced.
    auto fixedColour = [&](std::size_t hitLayer, const Vec3d& hitNormal, const Vec3d& dir) {
        float r = 0, g = 0, b = 0, surfaceAlpha = 0;
        if (hitLayer < n) {
            const float shade = detail::keyLightShade(setup, hitNormal, dir);
            const auto& a = layers[hitLayer].albedo;
            r = a[0] * shade, g = a[1] * shade, b = a[2] * shade, surfaceAlpha = 1;
        }
        const float tr = 1.0f, fr = 0.0f, fg = 0.0f, fb = 0.0f;
        const float behind = tr * (1 - surfaceAlpha);
        const auto& bg = options.background;
        return std::array<float, 4>{
            fr + tr * r + behind * bg[0] * bg[3], fg + tr * g + behind * bg[1] * bg[3],
            fb + tr * b + behind * bg[2] * bg[3], (1 - tr) + tr * surfaceAlpha + behind * bg[3]};
    };
    std::vector<std::atomic<std::size_t>> pixels(n);
    for (auto& p : pixels) p = 0;
    const auto t0 = std::chrono::steady_clock::now();
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, film.height()), [&](const auto& rows) {
        Tracers tracers(layers);
        std::vector<std::size_t> counts(n, 0);
        for (std::size_t y = rows.begin(); y != rows.end(); ++y) {
            for (std::size_t x = 0; x < film.width(); ++x) {
                const std::size_t pixel = y * film.width() + x;
                if (copyable && missesFog(cache->direction[pixel])) {
                    const auto& c = cache->base[pixel];
                    film.pixel(x, y) = Film::RGBA(c[0], c[1], c[2], c[3]);
                    if (cache->layer[pixel] < n) ++counts[cache->layer[pixel]];
                    continue;
                }
                const Ray ray = camera.getRay(x, y);
                // The nearest surface: the fixed layers' hit (kept, or computed and stored),
                // then the other surface layers.
                double nearest = std::numeric_limits<double>::max();
                std::size_t hitLayer = n;
                Vec3d hitNormal(0.0);
                auto nearestOf = [&](bool fixedPass) {
                    for (std::size_t k = 0; k < n; ++k) {
                        if (!tracers.surfaces[k] || bool(fixed[k]) != fixedPass) continue;
                        Ray local = intoLayer(ray, layers[k]);
                        Vec3d xyz, normal;
                        bool hit = false;
                        for (int crossing = 0; crossing < MAX_CUTAWAY_CROSSINGS; ++crossing) {
                            if (!tracers.surfaces[k]->intersectsWS(local, xyz, normal)) break;
                            if (!layers[k].cutaway
                                || isInnerFace(xyz, normal, local.dir(), localBoxes[k], voxel[k],
                                               double(layers[k].grid->background()))) {
                                hit = true;
                                break;
                            }
                            // Past this crossing, and look for the next one.
                            const double along =
                                (xyz - local.eye()).dot(local.dir()) / local.dir().lengthSqr();
                            local.setTimes(along + 1.5 * voxel[k] / local.dir().length(),
                                           local.t1());
                        }
                        if (!hit) continue;
                        const double t = (xyz - local.eye()).length();
                        if (t < nearest) {
                            nearest = t;
                            hitLayer = k;
                            hitNormal = layers[k].rotation * normal;
                        }
                    }
                };
                if (reuse) {
                    nearest = cache->t[pixel];
                    hitLayer = cache->layer[pixel];
                    hitNormal = cache->normal[pixel];
                } else {
                    nearestOf(true);
                    if (cache) {
                        cache->t[pixel] = nearest;
                        cache->layer[pixel] = std::uint32_t(hitLayer);
                        cache->normal[pixel] = hitNormal;
                        cache->direction[pixel] = openvdb::Vec3f(ray.dir());
                        cache->base[pixel] = fixedColour(hitLayer, hitNormal, ray.dir());
                    }
                }
                nearestOf(false);
                float r = 0, g = 0, b = 0, surfaceAlpha = 0;
                if (hitLayer < n) {
                    const float shade = detail::keyLightShade(setup, hitNormal, ray.dir());
                    const auto& a = layers[hitLayer].albedo;
                    r = a[0] * shade, g = a[1] * shade, b = a[2] * shade, surfaceAlpha = 1;
                    ++counts[hitLayer];
                }
                // Fog in front of it: march each fog layer's box up to the surface.
                double transmittance = 1;
                float fr = 0, fg = 0, fb = 0;
                for (std::size_t k = 0; k < n; ++k) {
                    if (!tracers.fogs[k]) continue;
                    const Ray local = intoLayer(ray, layers[k]);
                    double tin = 0, tout = 0;
                    if (isEmpty(localBoxes[k]) || !local.intersects(localBoxes[k], tin, tout))
                        continue;
                    tout = std::min(tout, nearest);
                    const double step = FOG_STEP_VOXELS * layers[k].grid->voxelSize()[0];
                    const double before = transmittance;
                    for (double t = std::max(tin, 0.0) + 0.5 * step; t < tout; t += step) {
                        const double d = tracers.fogs[k]->wsSample(local(t));
                        if (!(d > 0)) continue;
                        const double pass = std::exp(-options.extinction * d * step);
                        const float scattered = float(transmittance * (1 - pass)) * FOG_SHADE;
                        fr += scattered * layers[k].albedo[0];
                        fg += scattered * layers[k].albedo[1];
                        fb += scattered * layers[k].albedo[2];
                        transmittance *= pass;
                        if (transmittance < OPAQUE_TRANSMITTANCE) break;
                    }
                    if (before - transmittance > 0.05) ++counts[k];
                }
                const float tr = float(transmittance);
                // The scene over the background: what the surface leaves uncovered shows it.
                const float behind = tr * (1 - surfaceAlpha);
                const auto& bg = options.background;
                film.pixel(x, y) = Film::RGBA(fr + tr * r + behind * bg[0] * bg[3],
                                              fg + tr * g + behind * bg[1] * bg[3],
                                              fb + tr * b + behind * bg[2] * bg[3],
                                              (1 - tr) + tr * surfaceAlpha + behind * bg[3]);
            }
        }
        for (std::size_t k = 0; k < n; ++k) pixels[k] += counts[k];
    });
    ScenePreviewSummary summary;
    summary.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    for (auto& p : pixels) summary.pixels.push_back(p.load());
    detail::writeImage(film, path);
    return summary;
}

} // namespace vdbio
} // namespace ghostfx
