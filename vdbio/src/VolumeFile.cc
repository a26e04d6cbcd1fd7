/// @file   VolumeFile.cc
/// @brief  Volume frame outputs: option checks, particle selection, the grid list and the
///         atomic .vdb write. The grids themselves are built in SurfaceGrid.cc and
///         ParticleGrids.cc.
#include "FrameGridsDetail.h"

#include <ghostfx/sph/Exceptions.h>
#include <ghostfx/vdbio/AtomicFile.h>
#include <ghostfx/vdbio/FrameFiles.h>

#include <openvdb/io/Archive.h>
#include <openvdb/io/File.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <set>

namespace ghostfx {
namespace vdbio {

namespace {

/// Grid names the volume output uses itself: a scalar channel may not take them.
const char* const RESERVED_GRID_NAMES[] = {"surface", "density", "vel"};

bool isPositiveFinite(double v) { return std::isfinite(v) && v > 0.0; }

/// The anisotropic surface's fields (VolumeOptions, Yu and Turk 2013); `where` prefixes messages.
void validateAnisotropic(const VolumeOptions& o, const char* where)
{
    if (!isPositiveFinite(o.restDensity)) {
        throw ValueError(msg(where, "rest density = ", o.restDensity,
                             " kg/m^3: expected > 0 (anisotropic surface volumes are m / rho0)"));
    }
    if (!isPositiveFinite(o.anisotropicKernelSpacings)) {
        throw ValueError(msg(where, "anisotropic kernel = ", o.anisotropicKernelSpacings,
                             " spacings: expected > 0 (2 by default)"));
    }
    if (!isPositiveFinite(o.anisotropicIsolatedScale)) {
        throw ValueError(msg(where, "anisotropic isolated scale = ", o.anisotropicIsolatedScale,
                             ": expected > 0 (the paper uses 0.5)"));
    }
    const double isolatedRadius =
        o.anisotropicIsolatedScale * o.anisotropicKernelSpacings * o.particleSpacing;
    if (isolatedRadius < o.voxelSize) {
        throw ValueError(msg(where, "anisotropic isolated kernel radius = ", isolatedRadius,
                             " m (isolated scale x kernel) is below one voxel (", o.voxelSize,
                             " m): lower the voxel size (h / 2 is typical)"));
    }
    if (!(std::isfinite(o.anisotropicNeighborhoodSpacings)
          && o.anisotropicNeighborhoodSpacings >= 1.0)) {
        throw ValueError(msg(where,
                             "anisotropic neighbourhood = ", o.anisotropicNeighborhoodSpacings,
                             " spacings: expected >= 1 (the paper uses twice the kernel)"));
    }
    if (!(o.anisotropicSmoothing >= 0.0 && o.anisotropicSmoothing <= 1.0)) {
        throw ValueError(msg(where, "anisotropic smoothing = ", o.anisotropicSmoothing,
                             ": expected in [0, 1] (the paper uses 0.9 to 1)"));
    }
    if (!(std::isfinite(o.anisotropicMaxStretch) && o.anisotropicMaxStretch >= 1.0)) {
        throw ValueError(msg(where, "anisotropic max stretch = ", o.anisotropicMaxStretch,
                             ": expected >= 1 (the paper uses 4)"));
    }
    if (o.anisotropicMinNeighbors < 0) {
        throw ValueError(msg(where, "anisotropic min neighbours = ", o.anisotropicMinNeighbors,
                             ": expected >= 0 (the paper uses 25)"));
    }
    if (!isPositiveFinite(o.anisotropicScale)) {
        throw ValueError(msg(where, "anisotropic scale = ", o.anisotropicScale,
                             ": expected > 0 (1: interior kernels of the kernel radius)"));
    }
    if (!(o.anisotropicIsoValue > 0.0 && o.anisotropicIsoValue < 1.0)) {
        throw ValueError(msg(where, "anisotropic iso-value = ", o.anisotropicIsoValue,
                             ": expected in (0, 1) (a volume fraction)"));
    }
}

} // namespace

// ---------------------------------------------------------------------------------------------
// Helpers shared by the frame-output translation units
// ---------------------------------------------------------------------------------------------

namespace detail {

std::vector<sph::Index> selectKinds(const sph::ParticleSet& particles,
                                    const std::vector<sph::ParticleKind>& kinds)
{
    bool wanted[256] = {};
    for (sph::ParticleKind k : kinds) wanted[static_cast<unsigned>(k)] = true;
    std::vector<sph::Index> selection;
    const auto& kind = particles.kinds();
    for (std::size_t i = 0; i < kind.size(); ++i) {
        if (wanted[static_cast<unsigned>(kind[i])]) selection.push_back(sph::Index(i));
    }
    return selection;
}

std::string joinNames(const std::vector<std::string>& names)
{
    std::string out;
    for (const std::string& n : names) out += (out.empty() ? "" : ", ") + n;
    return out.empty() ? std::string("(none)") : out;
}

void setCommonGridMetadata(openvdb::GridBase& grid)
{
    grid.setCreator("ghostfx");
    // Half floats would round rho / rho0 and distances to 3 significant digits.
    grid.setSaveFloatAsHalf(false);
}

namespace {

/// OpenVDB's file format (what io::File::write writes: a seekable stream with grid offsets)
/// into a stream whose errors are checked. io::File::write does not look at its stream after
/// writing, so a full disk left an empty or cut file that was then renamed into place.
class CheckedVdbWriter : public openvdb::io::Archive
{
public:
    /// Throws IoError naming `target` (the file `file` will become).
    void write(const std::string& file, const std::string& target, const char* what,
               const openvdb::GridCPtrVec& grids, const openvdb::MetaMap& fileMetadata) const
    {
        std::ofstream out(file, std::ios_base::out | std::ios_base::binary | std::ios_base::trunc);
        if (!out) {
            throw IoError(
                msg(what, " '", target, "': cannot create it (", std::strerror(errno), ")"));
        }
        Archive::write(out, grids, /*seekable=*/true, fileMetadata);
        out.close();
        if (out.fail()) {
            throw IoError(msg(what, " '", target, "': cannot write it (",
                              errno != 0 ? std::strerror(errno) : "the stream failed", ")"));
        }
    }
};

} // namespace

void writeVdbFile(const std::string& path, const char* what, const openvdb::GridCPtrVec& grids,
                  const openvdb::MetaMap& fileMetadata)
{
    writeAtomically(path, [&](const std::string& tmp) {
        try {
            CheckedVdbWriter().write(tmp, path, what, grids, fileMetadata);
        } catch (const openvdb::Exception& e) {
            throw IoError(msg(what, " '", path, "': cannot write (", e.what(), ")"));
        } catch (const std::ios_base::failure& e) {
            throw IoError(msg(what, " '", path, "': cannot write (", e.what(), ")"));
        }
    });
}

void checkOutputFolder(const std::string& path, const char* what)
{
    const std::filesystem::path folder = std::filesystem::path(path).parent_path();
    if (folder.empty()) return; // the working directory
    std::error_code ec;
    if (!std::filesystem::is_directory(folder, ec)) {
        throw IoError(msg(what, " '", path, "': folder '", folder.string(),
                          "' does not exist or is not a folder"));
    }
}

} // namespace detail

// ---------------------------------------------------------------------------------------------
// VolumeOptions
// ---------------------------------------------------------------------------------------------

namespace {

/// The gathered grids' fields (density, vel, scalar channels); `where` prefixes messages.
void validateGathered(const VolumeOptions& o, const char* where)
{
    if (!isPositiveFinite(o.kernelSupport)) {
        throw ValueError(msg(where, "kernel support = ", o.kernelSupport,
                             " m: expected > 0 (the SPH support radius, 3 h in [SB12])"));
    }
    if (!isPositiveFinite(o.restDensity)) {
        throw ValueError(msg(where, "rest density = ", o.restDensity, " kg/m^3: expected > 0"));
    }
    if (!(std::isfinite(o.densityVoxelSize) && o.densityVoxelSize >= 0.0)) {
        throw ValueError(msg(where, "density voxel size = ", o.densityVoxelSize,
                             " m: expected > 0, or 0 for the particle spacing"));
    }
    if (o.densityVoxelSize == 0.0 && !isPositiveFinite(o.particleSpacing)) {
        throw ValueError(msg(where, "particle spacing = ", o.particleSpacing,
                             " m: expected > 0 (the density voxel defaults to it)"));
    }
    if (!(o.densityCutoff >= 0.0 && o.densityCutoff < 1.0)) {
        throw ValueError(msg(where, "density cutoff = ", o.densityCutoff,
                             ": expected in [0, 1) (a fraction of the rest density)"));
    }
}

/// The surface's size fields: spacing, radius, closing, smoothing, offset, spray, half width.
void validateSurfaceSizes(const VolumeOptions& o, const char* where)
{
    if (!isPositiveFinite(o.particleSpacing)) {
        throw ValueError(msg(where, "particle spacing = ", o.particleSpacing, " m: expected > 0"));
    }
    if (!isPositiveFinite(o.surfaceRadiusSpacings)) {
        throw ValueError(
            msg(where, "surface radius = ", o.surfaceRadiusSpacings, " spacings: expected > 0"));
    }
    const double radius = o.surfaceRadiusSpacings * o.particleSpacing;
    if (o.surfaceMethod == SurfaceMethod::Spheres && radius < o.voxelSize) {
        throw ValueError(msg(where, "surface sphere radius = ", radius, " m (",
                             o.surfaceRadiusSpacings, " spacings) is below one voxel (",
                             o.voxelSize, " m): lower the voxel size (h / 2 is typical)"));
    }
    if (!(std::isfinite(o.surfaceClosingSpacings) && o.surfaceClosingSpacings >= 0.0)) {
        throw ValueError(
            msg(where, "surface closing = ", o.surfaceClosingSpacings, " spacings: expected >= 0"));
    }
    if (o.surfaceSmoothingIterations < 0) {
        throw ValueError(msg(where, "surface smoothing iterations = ", o.surfaceSmoothingIterations,
                             ": expected >= 0"));
    }
    const double outermost = o.surfaceRadiusSpacings + o.surfaceClosingSpacings;
    if (!std::isfinite(o.surfaceOffsetSpacings) || o.surfaceOffsetSpacings > outermost) {
        throw ValueError(msg(where, "surface offset = ", o.surfaceOffsetSpacings,
                             " spacings: expected finite and <= radius + closing = ", outermost));
    }
    if (!(std::isfinite(o.surfaceSprayRadiusSpacings) && o.surfaceSprayRadiusSpacings >= 0.0)) {
        throw ValueError(msg(where, "surface spray radius = ", o.surfaceSprayRadiusSpacings,
                             " spacings: expected >= 0 (0 leaves spray out)"));
    }
    if (o.surfaceHalfWidthVoxels < 3) {
        throw ValueError(msg(where, "surface half width = ", o.surfaceHalfWidthVoxels,
                             " voxels: expected >= 3 (the level-set filters' stencils)"));
    }
}

/// The surface's fields: its sizes, then those of its method.
void validateSurface(const VolumeOptions& o, const char* where)
{
    validateSurfaceSizes(o, where);
    if (o.surfaceMethod == SurfaceMethod::Anisotropic) {
        validateAnisotropic(o, where);
    } else if (o.surfaceMethod != SurfaceMethod::Spheres) {
        throw ValueError(msg(where, "surface method = ", int(o.surfaceMethod), ": expected ",
                             sph::quotedNames(SURFACE_METHOD_NAMES)));
    }
}

/// The scalar channels' names: not empty, not a built-in grid's, each once.
void validateChannelNames(const std::vector<std::string>& scalarChannels, const char* where)
{
    std::set<std::string> seen;
    for (const std::string& name : scalarChannels) {
        if (name.empty()) throw ValueError(msg(where, "scalar channel with an empty name"));
        for (const char* reserved : RESERVED_GRID_NAMES) {
            if (name == reserved) {
                throw ValueError(msg(where, "scalar channel '", name,
                                     "': the name is taken by a built-in grid (surface, "
                                     "density, vel)"));
            }
        }
        if (!seen.insert(name).second) {
            throw ValueError(msg(where, "scalar channel '", name, "' listed twice"));
        }
    }
}

} // namespace

void VolumeOptions::validate() const
{
    const char* where = "volume output: ";
    if (!isPositiveFinite(voxelSize)) {
        throw ValueError(msg(where, "voxel size = ", voxelSize, " m: expected > 0"));
    }
    if (density || velocity || !scalarChannels.empty()) validateGathered(*this, where);
    if (surface) validateSurface(*this, where);
    validateChannelNames(scalarChannels, where);
    if (!std::isnan(ambientTemperature) && !isPositiveFinite(ambientTemperature)) {
        throw ValueError(msg(where, "ambient temperature = ", ambientTemperature,
                             ": expected a temperature > 0 (K), or none"));
    }
}

// ---------------------------------------------------------------------------------------------
// makeVolumeGrids
// ---------------------------------------------------------------------------------------------

void checkVolumeOutput(const sph::ParticleSet& particles, const VolumeOptions& options,
                       const std::string& where)
{
    detail::validateFor(options, where, "volume output");
    for (const std::string& name : options.scalarChannels) {
        if (name == "pressure" || particles.hasScalarChannel(name)) continue;
        std::vector<std::string> available{"pressure"};
        for (const std::string& n : particles.scalarChannelNames()) available.push_back(n);
        throw ValueError(msg(where, ": scalar channel '", name,
                             "' not found: available: ", detail::joinNames(available)));
    }
}

openvdb::GridPtrVec makeVolumeGrids(const sph::ParticleSet& particles, const VolumeOptions& options)
{
    checkVolumeOutput(particles, options);

    const std::vector<sph::Index> selection = detail::selectKinds(particles, options.kinds);
    openvdb::GridPtrVec grids;
    if (options.surface) {
        grids.push_back(options.surfaceMethod == SurfaceMethod::Anisotropic
                            ? detail::makeAnisotropicSurfaceGrid(particles, selection, options)
                            : detail::makeSurfaceGrid(particles, selection, options));
    }
    if (options.density || options.velocity || !options.scalarChannels.empty()) {
        openvdb::GridPtrVec gathered = detail::makeParticleGrids(particles, selection, options);
        grids.insert(grids.end(), gathered.begin(), gathered.end());
    }
    for (const openvdb::GridBase::Ptr& grid : grids) detail::setCommonGridMetadata(*grid);
    return grids;
}

// ---------------------------------------------------------------------------------------------
// writeVolumeFile
// ---------------------------------------------------------------------------------------------

void writeVolumeFile(const std::string& path, const openvdb::GridPtrVec& grids,
                     const openvdb::MetaMap& fileMetadata)
{
    std::set<std::string> names;
    for (std::size_t i = 0; i < grids.size(); ++i) {
        const openvdb::GridBase::Ptr& grid = grids[i];
        if (!grid) throw ValueError(msg("volume output '", path, "': grid ", i, " is null"));
        const std::string name = grid->getName();
        if (name.empty()) {
            throw ValueError(
                msg("volume output '", path, "': grid ", i, " (", grid->type(), ") has no name"));
        }
        const std::string valueType = grid->valueType();
        if (valueType == openvdb::typeNameAsString<openvdb::PointDataIndex32>()
            || valueType == openvdb::typeNameAsString<openvdb::PointIndex32>()) {
            throw ValueError(msg("volume output '", path, "': grid '", name,
                                 "' is a point grid: write it with writePointsFile (Blender "
                                 "refuses volume files that hold point grids)"));
        }
        if (!names.insert(name).second) {
            throw ValueError(msg("volume output '", path, "': two grids named '", name, "'"));
        }
        grid->setSaveFloatAsHalf(false);
    }

    detail::checkOutputFolder(path, "volume output");
    detail::writeVdbFile(path, "volume output", openvdb::GridCPtrVec(grids.begin(), grids.end()),
                         fileMetadata);
}

} // namespace vdbio
} // namespace ghostfx
