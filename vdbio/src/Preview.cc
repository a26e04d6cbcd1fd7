/// @file   Preview.cc
/// @brief  EXR previews of fog volumes and level sets (tools::VolumeRender, LevelSetRayTracer).
/// @details The ray tracers are instantiated here only, behind the non-template API of
///          Preview.h (STACK.md: ray tracing is one of the slower translation units to build).
#include <ghostfx/vdbio/Preview.h>

#include "PngFile.h"
#include "PreviewDetail.h"

#include <ghostfx/sph/Exceptions.h>
#include <ghostfx/vdbio/AtomicFile.h>

#include <openvdb/io/File.h>
#include <openvdb/tools/RayIntersector.h>
#include <openvdb/tools/RayTracer.h>

#include <OpenEXR/ImfHeader.h>
#include <OpenEXR/ImfRgbaFile.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <exception>
#include <filesystem>
#include <limits>
#include <vector>

namespace ghostfx {
namespace vdbio {

namespace fs = std::filesystem;
using openvdb::Vec3R;
using openvdb::tools::Film;

namespace {

// Image size limit: 16384^2 RGBA floats is 4 GiB of film, far beyond a preview.
constexpr int MAX_IMAGE_SIDE = 16384;
// The camera frames the bounding sphere of the active voxels with this much room around it.
constexpr double FRAMING_MARGIN = 1.05;
using detail::APERTURE_MM;
using detail::CameraSetup;
using detail::FOCAL_LENGTH_MM;
using detail::SURFACE_AMBIENT;
// Fog: single-scattering albedo (fraction of the extinction that scatters, the rest absorbs).
constexpr double FOG_ALBEDO = 0.9;
// Fog: ray-marching step along primary rays (voxels, VolumeRender's unit): one voxel, so thin
// sheets of liquid are not stepped over.
constexpr double PRIMARY_STEP_VOXELS = 1.0;
// Fog: shadow rays only dim the light, so they may step further: as far as an optical depth of
// SHADOW_STEP_DEPTH at density 1, between MIN and MAX voxels. On fine grids this cuts the
// render time several-fold at no visible cost.
constexpr double SHADOW_STEP_DEPTH = 0.2;
constexpr double MIN_SHADOW_STEP_VOXELS = 2.0, MAX_SHADOW_STEP_VOXELS = 8.0;
// Level set: surface albedo and the share of light that reaches faces turned from the key light.
const Film::RGBA SURFACE_ALBEDO(0.75f, 0.8f, 0.88f, 1.0f);
// Film colour of level-set rays that miss the surface (see renderSurface).
const Film::RGBA MISSED_RAY(-1.0f, -1.0f, -1.0f, 0.0f);
// Above this |elevation| (degrees) the camera looks (nearly) along y, so "up" cannot be +y.
constexpr double POLAR_ELEVATION = 89.0;

double radians(double degrees) { return degrees * openvdb::math::pi<double>() / 180.0; }

/// Place the camera so the bounding sphere of `grid`'s active voxels fills the frame.
CameraSetup frameGrid(const openvdb::GridBase& grid, const PreviewOptions& options,
                      const std::string& where)
{
    const openvdb::CoordBBox ibox = grid.evalActiveVoxelBoundingBox();
    if (ibox.empty()) throw GridError(msg(where, " has no active voxels: nothing to render"));

    // World box of the active voxels' extent (voxel centres +- half a voxel), all 8 corners
    // mapped so any linear transform is handled.
    const Vec3R lo = ibox.min().asVec3d() - Vec3R(0.5), hi = ibox.max().asVec3d() + Vec3R(0.5);
    Vec3R wmin(std::numeric_limits<double>::max()), wmax(-std::numeric_limits<double>::max());
    for (int corner = 0; corner < 8; ++corner) {
        const Vec3R c((corner & 1) ? hi.x() : lo.x(), (corner & 2) ? hi.y() : lo.y(),
                      (corner & 4) ? hi.z() : lo.z());
        const Vec3R w = grid.transform().indexToWorld(c);
        wmin = openvdb::math::minComponent(wmin, w);
        wmax = openvdb::math::maxComponent(wmax, w);
    }
    return detail::frameBox(wmin, wmax, options);
}

/// Lambertian shading from one key light plus a constant ambient share, opaque, two-sided
/// (the normal is turned towards the camera).
class KeyLightShader : public openvdb::tools::BaseShader
{
public:
    KeyLightShader(const Vec3R& toLight, const Film::RGBA& albedo, float ambient)
        : mToLight(toLight)
        , mAlbedo(albedo)
        , mAmbient(ambient)
    {}
    Film::RGBA operator()(const Vec3R&, const Vec3R& normal, const Vec3R& rayDir) const override
    {
        Vec3R n = normal;
        if (!n.normalize()) n = -rayDir;
        if (n.dot(rayDir) > 0) n = -n;
        const float diffuse = float(std::max(0.0, n.dot(mToLight)));
        const float shade = mAmbient + (1.0f - mAmbient) * diffuse;
        return Film::RGBA(mAlbedo.r * shade, mAlbedo.g * shade, mAlbedo.b * shade, 1.0f);
    }
    BaseShader* copy() const override { return new KeyLightShader(*this); }

private:
    Vec3R mToLight;
    Film::RGBA mAlbedo;
    float mAmbient;
};

void renderFog(const openvdb::FloatGrid& grid, const PreviewOptions& options,
               const CameraSetup& setup, openvdb::tools::BaseCamera& camera)
{
    using Intersector = openvdb::tools::VolumeRayIntersector<openvdb::FloatGrid>;
    Intersector intersector(grid);
    openvdb::tools::VolumeRender<Intersector, openvdb::tools::BoxSampler> renderer(intersector,
                                                                                   camera);
    // VolumeRender integrates in index space: coefficients are per voxel, so scale the
    // per-metre extinction by the voxel edge to keep the look independent of resolution.
    const double sigmaPerVoxel = options.extinction * grid.voxelSize()[0];
    renderer.setScattering(FOG_ALBEDO * sigmaPerVoxel, FOG_ALBEDO * sigmaPerVoxel,
                           FOG_ALBEDO * sigmaPerVoxel);
    const double absorption = (1.0 - FOG_ALBEDO) * sigmaPerVoxel;
    renderer.setAbsorption(absorption, absorption, absorption);
    renderer.setLightDir(setup.toLight.x(), setup.toLight.y(), setup.toLight.z());
    renderer.setLightColor(1.0, 1.0, 1.0);
    renderer.setPrimaryStep(PRIMARY_STEP_VOXELS);
    renderer.setShadowStep(std::clamp(SHADOW_STEP_DEPTH / sigmaPerVoxel, MIN_SHADOW_STEP_VOXELS,
                                      MAX_SHADOW_STEP_VOXELS));
    // The gain fakes multiple scattering by a falloff measured in voxels along the shadow ray,
    // which would make the look depend on resolution: off.
    renderer.setLightGain(0.0);
    renderer.render(true);
}

void renderSurface(const openvdb::FloatGrid& grid, const CameraSetup& setup,
                   openvdb::tools::BaseCamera& camera, Film& film)
{
    using Intersector = openvdb::tools::LevelSetRayIntersector<openvdb::FloatGrid>;
    // LevelSetRayTracer leaves missed pixels at the film's colour but resets their alpha to 1.
    // Prefill a colour no shader returns (negative), then turn exactly those pixels transparent.
    // (With one sample per pixel the tracer copies the prefill unchanged.)
    film.fill(MISSED_RAY);
    const KeyLightShader shader(setup.toLight, SURFACE_ALBEDO, SURFACE_AMBIENT);
    openvdb::tools::LevelSetRayTracer<openvdb::FloatGrid, Intersector> tracer(grid, shader, camera,
                                                                              /*pixelSamples=*/1);
    tracer.render(true);
    for (std::size_t y = 0; y < film.height(); ++y) {
        for (std::size_t x = 0; x < film.width(); ++x) {
            Film::RGBA& p = film.pixel(x, y);
            if (p.r == MISSED_RAY.r) p = Film::RGBA(0.0f, 0.0f, 0.0f, 0.0f);
        }
    }
}

/// An error message from a library that wrote to the temporary file, naming the target
/// instead (the temporary name means nothing to the user).
std::string withoutTemporaryName(std::string text, const std::string& tmp,
                                 const std::string& target)
{
    for (std::size_t at = text.find(tmp); at != std::string::npos; at = text.find(tmp, at)) {
        text.replace(at, tmp.size(), target);
        at += target.size();
    }
    return text;
}

/// A .png path gets an 8-bit sRGB PNG (for READMEs and quick looks), anything else an EXR.
void writePngImage(const Film& film, const std::string& path)
{
    const int width = int(film.width()), height = int(film.height());
    std::vector<float> rgba(std::size_t(width) * std::size_t(height) * 4);
    for (int y = 0; y < height; ++y) {
        for (int x = 0; x < width; ++x) {
            const Film::RGBA& p = film.pixel(std::size_t(x), std::size_t(y));
            float* q = &rgba[(std::size_t(y) * std::size_t(width) + std::size_t(x)) * 4];
            q[0] = p.r;
            q[1] = p.g;
            q[2] = p.b;
            q[3] = p.a;
        }
    }
    writeAtomically(path, [&](const std::string& tmp) { writePng(tmp, width, height, rgba); });
}

void writeExr(const Film& film, const std::string& exrPath)
{
    if (extensionOf(exrPath) == ".png") {
        writePngImage(film, exrPath);
        return;
    }
    const int width = int(film.width()), height = int(film.height());
    // Float to half by rows in parallel (a serial loop was a third of writing a preview).
    std::vector<Imf::Rgba> pixels(std::size_t(width) * std::size_t(height));
    tbb::parallel_for(tbb::blocked_range<int>(0, height, 16),
                      [&](const tbb::blocked_range<int>& rows) {
        for (int y = rows.begin(); y < rows.end(); ++y) {
            for (int x = 0; x < width; ++x) {
                const Film::RGBA& p = film.pixel(std::size_t(x), std::size_t(y));
                pixels[std::size_t(y) * width + x] = Imf::Rgba(p.r, p.g, p.b, p.a);
            }
        }
    });
    writeAtomically(exrPath, [&](const std::string& tmp) {
        try {
            // RLE: a preview is mostly flat background and smooth shading, which runs of equal
            // values compress well; 2.8 ms a 480 x 270 frame against PIZ's 5.4 ms (ZIP 4.4 ms)
            // for 50 KB against 34 KB (bench/RESULTS.md, "Previews").
            Imf::Header header(width, height);
            header.compression() = Imf::RLE_COMPRESSION;
            Imf::RgbaOutputFile file(tmp.c_str(), header, Imf::WRITE_RGBA);
            file.setFrameBuffer(pixels.data(), 1, std::size_t(width));
            file.writePixels(height);
        } catch (const std::exception& e) {
            throw IoError(msg("preview image '", exrPath, "': cannot write (",
                              withoutTemporaryName(e.what(), tmp, exrPath), ")"));
        }
    });
}

} // namespace

namespace detail {

CameraSetup frameBox(const Vec3R& wmin, const Vec3R& wmax, const PreviewOptions& options)
{
    CameraSetup s;
    s.target = 0.5 * (wmin + wmax);
    const double radius = 0.5 * (wmax - wmin).length();

    // Direction from the target to the camera: azimuth about +y from +z, elevation above xz.
    const double az = radians(options.azimuth), el = radians(options.elevation);
    const Vec3R toCamera(std::cos(el) * std::sin(az), std::sin(el), std::cos(el) * std::cos(az));
    s.up = std::abs(options.elevation) > POLAR_ELEVATION
               ? Vec3R(-std::sin(az), 0.0, -std::cos(az)) * (options.elevation > 0 ? 1.0 : -1.0)
               : Vec3R(0.0, 1.0, 0.0);

    // Distance at which the sphere fits the narrower field of view.
    const double tanHalfWidth = 0.5 * APERTURE_MM / FOCAL_LENGTH_MM;
    const double tanHalf =
        tanHalfWidth * std::min(1.0, double(options.height) / double(options.width));
    const double sinHalf = tanHalf / std::sqrt(1.0 + tanHalf * tanHalf);
    const double distance = FRAMING_MARGIN * radius / sinHalf;
    s.eye = s.target + distance * toCamera;
    s.nearPlane = std::max(1e-6 * distance, 0.5 * (distance - radius));
    s.farPlane = distance + 2.0 * radius;

    // Key light from above and to the left of the camera.
    const Vec3R forward = -toCamera;
    Vec3R right = forward.cross(s.up);
    right.normalize();
    const Vec3R cameraUp = right.cross(forward);
    s.toLight = toCamera + 0.5 * cameraUp - 0.4 * right;
    s.toLight.normalize();
    return s;
}

float keyLightShade(const CameraSetup& setup, Vec3R normal, const Vec3R& rayDir)
{
    if (!normal.normalize()) normal = -rayDir;
    if (normal.dot(rayDir) > 0) normal = -normal;
    const float diffuse = float(std::max(0.0, normal.dot(setup.toLight)));
    return SURFACE_AMBIENT + (1.0f - SURFACE_AMBIENT) * diffuse;
}

void writeImage(const Film& film, const std::string& path) { writeExr(film, path); }

/// Fail before rendering if the image cannot be created where asked.
void checkImagePath(const std::string& exrPath)
{
    const fs::path folder = fs::path(exrPath).parent_path();
    std::error_code ec;
    if (!folder.empty() && !fs::is_directory(folder, ec)) {
        throw IoError(
            msg("preview image '", exrPath, "': folder '", folder.string(), "' does not exist"));
    }
    if (fs::is_directory(exrPath, ec)) {
        throw IoError(
            msg("preview image '", exrPath, "' is a folder, expected an .exr or .png file"));
    }
}

} // namespace detail

namespace {

PreviewSummary render(const openvdb::GridBase& grid, const PreviewOptions& options,
                      const std::string& exrPath, const std::string& where)
{
    options.validate();
    const auto floatGrid = dynamic_cast<const openvdb::FloatGrid*>(&grid);
    if (!floatGrid) {
        throw GridError(msg(where, " has value type ", grid.valueType(),
                            ": preview renders float grids (fog volumes or level sets)"));
    }
    const openvdb::GridClass gridClass = grid.getGridClass();
    const bool isLevelSet = gridClass == openvdb::GRID_LEVEL_SET;
    // A float grid of unknown class with a zero background reads as a density.
    const bool isFog = gridClass == openvdb::GRID_FOG_VOLUME
                       || (gridClass == openvdb::GRID_UNKNOWN && floatGrid->background() == 0.0f);
    if (!isLevelSet && !isFog) {
        throw GridError(msg(where, " is of class '",
                            openvdb::GridBase::gridClassToString(gridClass), "' with background ",
                            floatGrid->background(),
                            ": preview renders fog volumes and level sets"));
    }
    if (!grid.hasUniformVoxels()) {
        throw GridError(msg(where, " has non-uniform voxels ", grid.voxelSize(),
                            ": preview needs cubic voxels"));
    }
    detail::checkImagePath(exrPath);

    const CameraSetup setup = frameGrid(grid, options, where);
    Film film(std::size_t(options.width), std::size_t(options.height),
              Film::RGBA(0.0f, 0.0f, 0.0f, 0.0f));
    openvdb::tools::PerspectiveCamera camera(film, Vec3R(0.0), setup.eye, FOCAL_LENGTH_MM,
                                             APERTURE_MM, setup.nearPlane, setup.farPlane);
    camera.lookAt(setup.target, setup.up);

    PreviewSummary summary;
    summary.gridName = grid.getName();
    summary.gridClass = isLevelSet ? "level set" : "fog volume";
    summary.activeVoxels = grid.activeVoxelCount();
    const auto t0 = std::chrono::steady_clock::now();
    try {
        if (isLevelSet) renderSurface(*floatGrid, setup, camera, film);
        else renderFog(*floatGrid, options, setup, camera);
    } catch (const openvdb::Exception& e) {
        throw GridError(msg(where, ": cannot be rendered (", e.what(), ")"));
    }
    summary.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();

    writeExr(film, exrPath);
    return summary;
}

std::string listNames(const openvdb::GridPtrVec& grids)
{
    std::string names;
    for (const auto& g : grids) names += (names.empty() ? "" : ", ") + ("'" + g->getName() + "'");
    return names.empty() ? "none" : names;
}

} // namespace

void PreviewOptions::validate() const
{
    if (width < 1 || width > MAX_IMAGE_SIDE) {
        throw ValueError(
            msg("preview width = ", width, ": expected 1 to ", MAX_IMAGE_SIDE, " pixels"));
    }
    if (height < 1 || height > MAX_IMAGE_SIDE) {
        throw ValueError(
            msg("preview height = ", height, ": expected 1 to ", MAX_IMAGE_SIDE, " pixels"));
    }
    if (!std::isfinite(azimuth)) {
        throw ValueError(msg("preview azimuth = ", azimuth, ": expected a finite angle (degrees)"));
    }
    if (!(elevation >= -90.0 && elevation <= 90.0)) {
        throw ValueError(msg("preview elevation = ", elevation, ": expected -90 to 90 degrees"));
    }
    for (float c : background) {
        if (!(c >= 0.0f && c <= 1.0f)) {
            throw ValueError(msg("preview background component = ", c, ": expected 0 to 1"));
        }
    }
    if (!(extinction > 0.0) || !std::isfinite(extinction)) {
        throw ValueError(msg("preview extinction = ", extinction, ": expected > 0 (1/m)"));
    }
}

PreviewSummary renderPreview(const openvdb::GridBase& grid, const PreviewOptions& options,
                             const std::string& exrPath)
{
    return render(grid, options, exrPath, msg("grid '", grid.getName(), "'"));
}

namespace {

/// The grid of `vdbPath` (grid headers `headers`) a preview draws: `asked`, or by default the
/// liquid's "surface", else "density", else the first float grid. GridError when there is none
/// or `asked` is not in the file.
std::string previewGridName(const std::string& vdbPath, const openvdb::GridPtrVec& headers,
                            const std::string& asked)
{
    if (!asked.empty()) {
        const bool found = std::any_of(headers.begin(), headers.end(),
                                       [&](const auto& g) { return g->getName() == asked; });
        if (!found) {
            throw GridError(msg("grid '", asked, "' not found in '", vdbPath,
                                "' (grids: ", listNames(headers), ")"));
        }
        return asked;
    }
    for (const char* preferred : {"surface", "density"}) {
        for (const auto& g : headers) {
            if (g->getName() == preferred) return preferred;
        }
    }
    for (const auto& g : headers) {
        if (g->isType<openvdb::FloatGrid>()) return g->getName();
    }
    throw GridError(
        msg("'", vdbPath, "' holds no float grid to preview (grids: ", listNames(headers), ")"));
}

} // namespace

PreviewSummary renderPreviewFromFile(const std::string& vdbPath, const PreviewOptions& options,
                                     const std::string& exrPath)
{
    options.validate();
    std::error_code ec;
    if (!fs::exists(vdbPath, ec)) throw IoError(msg("'", vdbPath, "': no such file"));

    openvdb::io::File file(vdbPath);
    openvdb::GridPtrVecPtr headers;
    try {
        file.open(/*delayLoad=*/false);
        headers = file.readAllGridMetadata();
    } catch (const openvdb::Exception& e) {
        throw IoError(msg("'", vdbPath, "': cannot read as a .vdb file (", e.what(), ")"));
    }

    const std::string name = previewGridName(vdbPath, *headers, options.grid);
    openvdb::GridBase::Ptr grid;
    try {
        grid = file.readGrid(name);
    } catch (const openvdb::Exception& e) {
        throw IoError(msg("'", vdbPath, "': cannot read grid '", name, "' (", e.what(), ")"));
    }
    file.close();
    return render(*grid, options, exrPath, msg("grid '", name, "' in '", vdbPath, "'"));
}

RgbaImage readExrImage(const std::string& exrPath)
{
    if (extensionOf(exrPath) == ".png") {
        RgbaImage image;
        const std::vector<std::uint8_t> bytes = readPngRgba8(exrPath, image.width, image.height);
        image.rgba.reserve(bytes.size());
        for (std::uint8_t b : bytes) image.rgba.push_back(float(b) / 255.0f);
        return image;
    }
    try {
        Imf::RgbaInputFile file(exrPath.c_str());
        const Imath::Box2i window = file.dataWindow();
        RgbaImage image;
        image.width = window.max.x - window.min.x + 1;
        image.height = window.max.y - window.min.y + 1;
        std::vector<Imf::Rgba> pixels(std::size_t(image.width) * std::size_t(image.height));
        // The frame buffer is addressed by data-window coordinates: shift its origin.
        file.setFrameBuffer(pixels.data() - window.min.x
                                - std::ptrdiff_t(window.min.y) * image.width,
                            1, std::size_t(image.width));
        file.readPixels(window.min.y, window.max.y);
        image.rgba.reserve(4 * pixels.size());
        for (const Imf::Rgba& p : pixels) {
            image.rgba.insert(image.rgba.end(), {float(p.r), float(p.g), float(p.b), float(p.a)});
        }
        return image;
    } catch (const std::exception& e) {
        throw IoError(msg("'", exrPath, "': cannot read as an EXR image (", e.what(), ")"));
    }
}

} // namespace vdbio
} // namespace ghostfx
