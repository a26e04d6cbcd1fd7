/// @file   FrameFiles.h
/// @brief  Per-frame output files of a simulation: particles as a PointDataGrid, and volumes
///         (liquid surface level set, SPH density fog, velocity, scalar channels).
/// @details DESIGN.md, "Outputs". Files are written atomically (AtomicFile.h) and read by
///          Houdini, Blender and any OpenVDB tool:
///          - `writePointsFile`: one PointDataGrid named "particles" in a file of its own,
///            because Blender and pyopenvdb refuse files that contain point grids (STACK.md).
///          - `makeVolumeGrids` + `writeVolumeFile`: "surface" (level set), "density" (fog,
///            rho / rho0), "vel" (Vec3SGrid), one fog grid per scalar channel.
///
///          Density, velocity and channel grids are SPH rasterisations computed by gathering:
///          each voxel sums the particles within the kernel support around its centre,
///            rho(x) = sum_j m_j W(|x - x_j|, R)                      ([SB12] Eq. 1 at x),
///            v(x)   = sum_j m_j v_j W / sum_j m_j W                  (Shepard normalisation),
///          so the grids are identical at any thread count (DESIGN.md, Parallelism).
///          The surface is OpenVDB's particle surfacing (tools::ParticlesToLevelSet, after
///          Zhu and Bridson 2005, "Animating sand as a fluid", union-of-spheres variant) followed
///          by a morphological closing and mean-curvature smoothing (tools::LevelSetFilter's
///          arithmetic, computed by NarrowBandFlow in LevelSetFlow.h with the same result bit
///          for bit, [Osher and Fedkiw 2003, Ch. 4]), the recipe of Houdini's "VDB from
///          Particles" + "VDB Smooth SDF".
///
///          The heavy OpenVDB headers (points, particle surfacing, level-set filters) stay in
///          the .cc files (STACK.md: minutes of compile time each); this header needs only
///          <openvdb/openvdb.h>.
#pragma once

#include <ghostfx/sph/ParticleSet.h>
#include <ghostfx/vdbio/SurfaceMethod.h>

#include <openvdb/openvdb.h>

#include <limits>
#include <string>
#include <vector>

namespace ghostfx {
namespace vdbio {

/// Float metadata of a gas "temperature" grid: the ambient temperature (K), which is also the
/// grid's background (VolumeOptions::ambientTemperature).
constexpr const char* AMBIENT_TEMPERATURE_METADATA = "ghostfx_ambient_temperature";

// ---------------------------------------------------------------------------------------------
// Points
// ---------------------------------------------------------------------------------------------

/// What `writePointsFile` writes.
struct PointsOptions
{
    /// Points per occupied voxel aimed at by the automatic voxel size (OpenVDB's
    /// points::computeVoxelSize): a few attribute values per voxel keep the per-voxel offsets
    /// small while the leaves stay few (measured 8.0 on a Poisson-sampled liquid sphere).
    static constexpr unsigned AUTO_POINTS_PER_VOXEL = 8;

    /// Channels written besides P. Built-ins: "v" (m/s, vec3f), "id" (int64), "density"
    /// (kg/m^3), "pressure" (Pa), "mass" (kg), "kind" (int32, ParticleKind value; the grid
    /// metadata "kind_names" lists the names). Any named scalar (float) or vector (vec3f)
    /// channel of the ParticleSet may be added (e.g. "temperature"); a channel of the set
    /// takes the place of a render attribute of the same name. Render attributes (float,
    /// RenderAttributes.h): "age" (s), "pscale" (m) and, on liquid points, "vorticity" (1/s)
    /// and "curvature" (1/m).
    /// Unknown names throw ValueError naming the channel and listing those available.
    std::vector<std::string> channels = {"v", "id", "density", "pressure"};
    /// Particle kinds written. Ghost particles are never written unless listed here.
    std::vector<sph::ParticleKind> kinds = {sph::ParticleKind::Liquid};
    /// PointDataGrid voxel size (m); 0 = automatic (AUTO_POINTS_PER_VOXEL, 0.1 m when fewer
    /// than two points are selected). The voxel size only affects how points are bucketed,
    /// not their positions.
    double voxelSize = 0;

    /// Time of the particles' state (s): "age" is this minus each particle's birth time.
    double time = 0;
    /// Rest density rho0 of the medium (kg/m^3), for "pscale" and the neighbour volumes
    /// m_j / rho0 of "vorticity" and "curvature"; 0 refuses those channels.
    double restDensity = 0;
    /// Kernel support radius R of the medium (m), for "vorticity" and "curvature"; 0 refuses
    /// them.
    double kernelSupport = 0;

    /// Throw ValueError naming the first bad field (negative voxel size, duplicate channel,
    /// no kind).
    void validate() const;
};

/// Write the selected particles of `particles` as one PointDataGrid named "particles" to
/// `path`, atomically (temporary file, then rename).
/// @details Attributes: "P" (world position, vec3f, no compression: OpenVDB stores it as a
///          float offset from the voxel centre, exact to about 1e-7 voxel), then the channels
///          in the order asked. Scalars are written as float and vectors as vec3f in both
///          precisions of Real. The points are written in OpenVDB's voxel order, not in the
///          order of the set: match them by "id".
/// @param fileMetadata  file-level metadata (frame, time, scene...) written with the grid
/// @throw ValueError for a bad option or an unknown channel; IoError if the file cannot be
///        written.
void writePointsFile(const std::string& path, const sph::ParticleSet& particles,
                     const PointsOptions& options,
                     const openvdb::MetaMap& fileMetadata = openvdb::MetaMap());

/// The PointDataGrid "particles" that writePointsFile writes (nothing written). `where`
/// prefixes an unknown-channel error ("points output 'path'").
/// @throw ValueError for a bad option or an unknown channel.
openvdb::GridBase::Ptr makePointsGrid(const sph::ParticleSet& particles,
                                      const PointsOptions& options,
                                      const std::string& where = "points output");

/// Refuse what makePointsGrid would refuse for `particles`, without building anything: a bad
/// option, or a channel the set does not have (named in a ValueError prefixed by `where`). A
/// run calls it before its first step, so no output is written before such an error.
void checkPointsOutput(const sph::ParticleSet& particles, const PointsOptions& options,
                       const std::string& where = "points output");

/// True when `options` asks for a render attribute that sums over neighbours ("vorticity",
/// "curvature") and that `particles` does not carry as a channel.
bool needsNeighbourAttributes(const sph::ParticleSet& particles, const PointsOptions& options);

/// How far (m) from a particle the neighbours that its attributes of needsNeighbourAttributes
/// read can lie: the kernel support, three times it for "curvature"; 0 when none is asked.
double neighbourAttributeReach(const sph::ParticleSet& particles, const PointsOptions& options);

/// The first `count` particles of `particles`, with each render attribute of `options` that
/// sums over neighbours computed over all of `particles` and kept as a scalar channel of that
/// name, which makePointsGrid then writes as it is. A run over several processes passes its
/// own particles followed by copies of the others' within the kernel support, so that the
/// estimate sees across the border before the points travel to the process that writes them.
sph::ParticleSet withNeighbourAttributes(const sph::ParticleSet& particles, std::size_t count,
                                         const PointsOptions& options);

/// The voxel size PointsOptions::voxelSize = 0 picks for these positions (OpenVDB's
/// points::computeVoxelSize at AUTO_POINTS_PER_VOXEL; 0.1 m for fewer than two).
double autoPointsVoxelSize(const std::vector<sph::Vec3>& positions);

/// Write a grid made by makePointsGrid or mergePointsGrids to `path` atomically.
/// @throw IoError if the file cannot be written.
void writePointsGridFile(const std::string& path, const openvdb::GridBase::ConstPtr& grid,
                         const openvdb::MetaMap& fileMetadata = openvdb::MetaMap());

/// One PointDataGrid from pieces made by makePointsGrid with the same options and voxel size
/// whose leaves do not overlap (a run over several processes: each makes the leaves it owns,
/// DistributedFrames.h). The leaves are moved out of the pieces; "point_count" is the sum.
/// @throw ValueError for overlapping leaves, different voxel sizes or attributes, or no piece.
openvdb::GridBase::Ptr mergePointsGrids(const std::vector<openvdb::GridBase::Ptr>& pieces);

// ---------------------------------------------------------------------------------------------
// Volumes
// ---------------------------------------------------------------------------------------------

/// What `makeVolumeGrids` builds. Distances are in metres; factors named `...Spacings` are in
/// units of the particle spacing h, so one setting suits every resolution.
struct VolumeOptions
{
    /// Voxel edge (m) of the surface level set, required > 0. h / 2 resolves the surface
    /// between particles.
    double voxelSize = 0;
    /// Voxel edge (m) of the density, velocity and channel grids; 0 (the default): the particle
    /// spacing h. These fields are sums of the kernel over its support R = 3 h, smooth on that
    /// scale: at h they cost an eighth of h / 2 (voxels and kernel evaluations) and keep the
    /// mass (to 4e-6) and the rho / rho0 = 0.5 contour (to 0.06 h); read back trilinearly at the
    /// h / 2 voxel centres they differ by up to 2.4 % of rho0 inside the liquid and 8 % in the
    /// fringe where the density falls to zero across the surface (rms 1.9 %; measured on a
    /// liquid sphere, tests/vdbio/test_frame_files.cc, DensityVoxelOfOneSpacing*). Set h / 2
    /// for those fringe values.
    double densityVoxelSize = 0;
    /// SPH kernel support radius R (m) of the density, velocity and channel grids, required
    /// > 0 (sph::CubicSplineKernel; [SB12] Sec. 3 uses R = 3 h).
    double kernelSupport = 0;
    /// A scalar channel holding each particle's own support radius (m), or "" (the default):
    /// every particle spreads over kernelSupport. With a channel a particle spreads over its own
    /// support, kept within [1, MAX_SUPPORT_SCALE] x kernelSupport, so particles grown by the air
    /// they entrained (the gas's "h") spread their mass over their own support instead of piling
    /// it into a blob of the rest size.
    std::string supportChannel;
    /// The largest support a particle gets with supportChannel, in kernelSupports (2: eight
    /// times the rest mass at the rest density); volumeReach() reaches that far.
    static constexpr double MAX_SUPPORT_SCALE = 2.0;
    /// rho0 (kg/m^3): the density grid stores rho / rho0.
    double restDensity = 1000;
    /// Particle spacing h (m), required > 0: sets the surface sphere radius and the closing.
    double particleSpacing = 0;
    /// Particle kinds rasterised (ghosts are left out unless listed).
    std::vector<sph::ParticleKind> kinds = {sph::ParticleKind::Liquid};
    bool surface = true;  ///< build "surface" (level set)
    bool density = true;  ///< build "density" (fog, rho / rho0)
    bool velocity = true; ///< build "vel" (Vec3SGrid, Shepard-normalised)
    /// Named scalar channels of the ParticleSet (or the built-in "pressure"), each rasterised
    /// as a Shepard-normalised fog grid named after the channel, e.g. {"temperature"}.
    std::vector<std::string> scalarChannels;
    /// The gas's ambient temperature (K), > 0: the "temperature" channel grid's background and
    /// the value of its voxels outside the gas (inactive), stored as the grid's float metadata
    /// AMBIENT_TEMPERATURE_METADATA. NaN (the default): background 0 and no metadata.
    double ambientTemperature = std::numeric_limits<double>::quiet_NaN();

    // Rasterisation -----------------------------------------------------------------------
    /// Voxels whose rho / rho0 falls below this stay inactive, so the grids stay sparse. With
    /// R = 3 h the default drops the outermost 8 % of the support radius around an isolated
    /// particle of mass rho0 h^3 (where the M4 spline is below 0.1 % of its peak), about 6e-4 of
    /// its mass (measured 6.8e-4); inside the liquid the tails overlap and nothing is dropped
    /// (measured 5e-6 of the mass of a liquid sphere). 0 keeps every voxel within the support.
    double densityCutoff = 1e-4;

    // Surface reconstruction ----------------------------------------------------------------
    // 1. Union of spheres of radius `surfaceRadiusSpacings` h (ParticlesToLevelSet).
    // 2. Closing: dilate by `surfaceClosingSpacings` h, `surfaceSmoothingIterations` passes
    //    of mean-curvature flow, erode by the closing distance plus the sphere radius minus
    //    `surfaceOffsetSpacings` h (LevelSetFilter::offset / meanCurvature, as NarrowBandFlow).
    // On a flat free surface the zero crossing ends about `surfaceOffsetSpacings` h outside the
    // outermost particle centres (measured 0.42 h for 0.5 on a lattice block: the smoothing
    // averages the remaining dips in), on a sphere of radius 6 h 0.37 h (curvature flow shrinks
    // convex parts slightly); the zero crossing's radius there varies by 0.01 h rms, against
    // 0.07 h for the raw union of spheres.

    /// Sphere radius / h. 1 makes neighbouring spheres overlap (the dips between them are
    /// 0.13 h deep) and covers every gap of a Poisson-disk sampling with radius 0.92 h
    /// ([SB12] Sec. 4.6); smaller radii leave holes. Must be at least one voxel.
    double surfaceRadiusSpacings = 1.0;
    /// Closing distance / h: concavities narrower than about twice this are filled, which
    /// removes the dips between particles before smoothing. 0 disables the closing.
    double surfaceClosingSpacings = 1.0;
    /// Mean-curvature flow passes (OpenVDB's step dt = dx^2 / 3 each): removes bumps a few
    /// voxels wide while a sphere of radius rho shrinks by only about 2 dx^2 / (3 rho) per pass.
    int surfaceSmoothingIterations = 4;
    /// Final distance of the zero crossing outside the outermost particle centres / h. A
    /// particle stands for a cube of side h about its centre, so 0.5 makes the enclosed volume
    /// match N h^3 for a lattice.
    double surfaceOffsetSpacings = 0.5;
    /// Radius / h of the droplet kept around spray, a particle with no other within 2 h: the
    /// closing and smoothing erase a lone sphere, so without it spray leaves no surface. 0.62
    /// gives the droplet the particle's volume h^3; 0 leaves spray out.
    double surfaceSprayRadiusSpacings = 0.62;
    /// Narrow-band half width (voxels) of the written level set; background = this * voxelSize.
    int surfaceHalfWidthVoxels = 3;

    // Anisotropic surface (surfaceMethod = Anisotropic; AnisotropicSurface.cc, after Yu and Turk,
    // "Reconstructing surfaces of particle-based fluids using anisotropic kernels", SCA 2010 /
    // ACM TOG 2013). Each particle j gets a kernel stretched along the principal
    // axes of its neighbours' weighted covariance and centred at its Laplacian-smoothed position
    // xbar_j; the surface is an iso-contour of phi(x) = sum_j (m_j / rho0) det(G_j) P(|G_j (x -
    // xbar_j)|), a volume fraction (about 1 inside the liquid). The sphere fields above
    // (radius, closing, smoothing, offset) do not apply; the half width does.

    /// Surface reconstruction: union of spheres (default) or anisotropic kernels.
    SurfaceMethod surfaceMethod = SurfaceMethod::Spheres;
    /// Support radius h_k of the isotropic kernel P (M4 spline) / h. The paper uses the
    /// simulation's kernel radius; 2 h here (33 lattice particles within it).
    double anisotropicKernelSpacings = 2.0;
    /// Radius r of the weighted mean and covariance (weights 1 - (d / r)^3) / h. The paper uses
    /// r = 2 h_k; with the default h_k that is 4 h (about 270 neighbours inside the liquid).
    double anisotropicNeighborhoodSpacings = 4.0;
    /// lambda: kernel centres xbar = (1 - lambda) x + lambda (weighted mean of the neighbours).
    /// Paper: 0.9 to 1 (0.9 here); 0 keeps the particle positions.
    double anisotropicSmoothing = 0.9;
    /// k_r: largest ratio between the largest and smallest kernel axes (paper: 4).
    double anisotropicMaxStretch = 4.0;
    /// N_eps: particles with this many neighbours or fewer within r (itself not counted) get a
    /// round kernel of radius k_n h_k (paper: 25).
    int anisotropicMinNeighbors = 25;
    /// k_s: kernel semi-axis / h_k per covariance eigenvalue, the eigenvalues in units of that
    /// of a full uniform neighbourhood (0.15 r^2 for these weights), so an interior particle's
    /// kernel is round with radius k_s h_k at any resolution (the paper's k_s = 1400 plays this
    /// role in its own scene units). Not 1: the smoothing (lambda = 0.9) moves a flat surface's
    /// outer kernels about 0.5 h_k inwards while they reach about as far out, so with k_s = 1 no
    /// iso-value puts the surface outside the outer particles (measured: the crossing stays at
    /// the outer layer as the iso-value goes to 0). With 3 the calibrated iso-value is 0.2,
    /// where phi is still steep; with 2.5 it is 0.08, in the spline's tail, where a jittered
    /// face came out 1.3x rougher. The cost grows as k_s^3 (bench/history/diary-2026-11.md).
    double anisotropicScale = 3.0;
    /// k_n: kernel radius / h_k of a particle with too few neighbours (paper: 0.5).
    double anisotropicIsolatedScale = 0.5;
    /// Iso-value of phi (a volume fraction) taken as the surface, in (0, 1). Calibrated with the
    /// defaults above at voxel h / 2 so a flat free surface of a lattice block ends 0.50 h
    /// outside the outermost particle centres, as the sphere method's `surfaceOffsetSpacings`
    /// (tests/vdbio/test_surface_accuracy.cc: 0.19 gives 0.52 h, 0.20 gives 0.49 h). Other
    /// kernel settings need their own value.
    double anisotropicIsoValue = 0.196;

    /// Throw ValueError naming the first bad field and its value, e.g.
    /// "volume output: voxel size = 0 m: expected > 0".
    void validate() const;

    /// The voxel edge (m) the density, velocity and channel grids use.
    double fogVoxelSize() const
    {
        return densityVoxelSize > 0 ? densityVoxelSize : particleSpacing;
    }
};

/// Refuse what makeVolumeGrids would refuse for `particles`, without building anything: a bad
/// option, or a scalar channel the set does not have (a ValueError prefixed by `where`).
void checkVolumeOutput(const sph::ParticleSet& particles, const VolumeOptions& options,
                       const std::string& where = "volume output");

/// Build the grids asked for, in this order: "surface" (GRID_LEVEL_SET FloatGrid, background
/// = half width in metres), "density" (GRID_FOG_VOLUME FloatGrid, rho / rho0, metadata
/// "rest_density" and "units"), "vel" (Vec3SGrid, VEC_CONTRAVARIANT_RELATIVE, m/s), then one
/// GRID_FOG_VOLUME FloatGrid per scalar channel. The surface has the linear transform of
/// `voxelSize` (voxel (i,j,k) centred at (i,j,k) * voxelSize), the others that of
/// fogVoxelSize(). Density, vel and channel grids share one sparse topology: voxels within
/// `kernelSupport` of a selected particle whose rho / rho0 reaches `densityCutoff`, so
/// mass = restDensity * sum(density values) * fogVoxelSize()^3.
/// No selected particle gives valid empty grids.
/// @throw ValueError for a bad option or unknown channel.
openvdb::GridPtrVec makeVolumeGrids(const sph::ParticleSet& particles,
                                    const VolumeOptions& options);

/// The distance (m) from a selected particle beyond which it changes no voxel of the grids
/// `options` asks for: a grid built from every particle within this reach of a region has the
/// values of the grid built from all particles at every voxel centre in the region (used to
/// build a frame in pieces, one per process: keepVoxelsIn, mergeVolumeGrids). A bound, not a
/// measurement: the surface's union of spheres, its interior clean-up, the re-normalisation
/// and band growth of each filter pass and offset step (two voxels each, plus one for a
/// curvature stencil), and the density kernel's support (VolumeFile.cc says each term).
double volumeReach(const VolumeOptions& options);

/// Keep of each grid only the voxels whose centres lie in `region` (min <= x < max on each
/// axis, the convention of sph::DomainDecomposition: a point on a cut belongs to the upper
/// side); the rest is deactivated (leaves wholly outside dropped).
void keepVoxelsIn(openvdb::GridPtrVec& grids, const sph::Aabb& region);

/// The grids of several pieces cut by keepVoxelsIn from disjoint regions, as one list (the
/// first piece's names, order, metadata and transforms): every piece's active values copied
/// into fresh grids; level sets then get their inside and outside signs anew
/// (tools::signedFloodFill). Grids of a name missing from the first piece are refused.
/// @throw ValueError for pieces with different grid lists, types or transforms.
openvdb::GridPtrVec mergeVolumeGrids(std::vector<openvdb::GridPtrVec> pieces);

/// Grids as bytes (an OpenVDB stream) and back, to send them between processes.
std::string gridsToBytes(const openvdb::GridPtrVec& grids);
openvdb::GridPtrVec gridsFromBytes(const std::string& bytes);

/// Write `grids` to `path` atomically, with `fileMetadata`. Each grid is stored at full float
/// precision (saveFloatAsHalf off). Point grids are refused (ValueError): they go to their
/// own file (writePointsFile) so that Blender can read the volumes.
/// @throw ValueError for a null grid, a point grid or an empty name; IoError if the file
///        cannot be written.
void writeVolumeFile(const std::string& path, const openvdb::GridPtrVec& grids,
                     const openvdb::MetaMap& fileMetadata = openvdb::MetaMap());

} // namespace vdbio
} // namespace ghostfx
