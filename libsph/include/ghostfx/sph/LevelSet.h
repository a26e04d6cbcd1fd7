/// @file   LevelSet.h
/// @brief  Queries on an OpenVDB narrow-band level set: signed distance, gradient, normal,
///         closest point, inside/outside, in world space.
/// @details The one interface through which the sampler, the ghost-solid layer and the collision
///          projection see solids, emitters and liquid shapes (DESIGN.md, "Level sets"). This
///          header keeps OpenVDB's grid headers out of the files that include it; construct a
///          LevelSet from a grid with LevelSetGrid.h.
///
///          Narrow band: OpenVDB stores phi only within `halfWidth` voxels of the surface and
///          clamps it to +/- the background value beyond. Queries beyond the band therefore see
///          a constant phi and a zero gradient: `phi()` keeps the correct sign there, and
///          `projectToSurface()` reports failure instead of walking in a made-up direction.
///
///          All methods are const and safe to call from many threads at once (each thread uses
///          its own cached tree accessor).
#pragma once

#include "ghostfx/sph/Types.h"

#include <array>
#include <memory>
#include <string>
#include <vector>

namespace ghostfx {
namespace sph {

/// Result of a closest-point projection.
struct SurfaceProjection
{
    Vec3 point{0};      ///< the projected point (m); the last iterate if it did not converge
    Real residual = 0;  ///< |phi(point)| (m)
    int iterations = 0; ///< Newton-like steps taken
    bool converged = false;
};

class LevelSet
{
public:
    struct Impl;

    /// Use LevelSetGrid.h: `LevelSet(openvdb::FloatGrid::ConstPtr, name)`.
    explicit LevelSet(std::shared_ptr<const Impl> impl);
    ~LevelSet();
    LevelSet(const LevelSet&);
    LevelSet& operator=(const LevelSet&);

    /// Grid name, for error messages.
    const std::string& name() const;

    /// Voxel edge length (m); voxels are checked to be uniform cubes.
    Real voxelSize() const;
    /// Distance from the surface (m) beyond which phi is clamped: the grid's background value.
    Real bandWidth() const;
    /// World-space box enclosing every active voxel (m).
    Aabb bounds() const;
    /// A 64-bit hash of everything phi() reads: every voxel and tile value with its active
    /// state and place, the background and the transform (SampleStore keys).
    std::uint64_t contentHash() const;

    /// Signed distance (m), negative inside. Trilinear; clamped to +/- bandWidth() beyond the band.
    Real phi(const Vec3& x) const;
    /// Gradient of phi by central differences one voxel apart (unitless, about unit length
    /// inside the band, zero where the stencil sees only clamped values).
    Vec3 gradient(const Vec3& x) const;
    /// phi (m) and its gradient from one trilinear 8-voxel stencil: about 6x cheaper than
    /// phi() + gradient(), exact for the interpolant, but the gradient jumps across cell faces.
    /// Used by the projection inner loop.
    Real phiAndGradient(const Vec3& x, Vec3& grad) const;
    /// Outward unit normal, or zero where the gradient vanishes (beyond the band).
    Vec3 normal(const Vec3& x) const;
    /// phi(x) < 0.
    bool inside(const Vec3& x) const { return phi(x) < Real(0); }
    /// Fraction of the surface (its voxels within half a voxel of phi = 0) where the shape is
    /// thinner than `depth` (m): the point `depth` inward along the normal lies outside again.
    /// A boundary layer of particles one kernel radius deep does not fit there.
    double fractionThinnerThan(Real depth) const;
    /// The same for this shape as a part of its union with `others` (the solids beside it): a
    /// surface voxel inside one of `others`, or within a voxel of one, is buried (no liquid
    /// reaches it) and not counted,
    /// and a surface point is thin only where the point `depth` inward lies outside this shape
    /// and all of `others` (a plate lying on a floor is as thick as both).
    double fractionThinnerThan(Real depth, const std::vector<const LevelSet*>& others) const;
    /// Area (m^2) of the shadow the shape casts along `direction` (any length but zero): the
    /// cross-section through which a body translating along it sweeps. Rays along `direction`
    /// through the centres of a square grid of `resolution` (m) over the projected bounds are
    /// sphere-traced through phi (steps of at least resolution / 4); each counts the share
    /// of its cell that its least phi puts inside the outline (all of it once phi reaches
    /// -resolution / 2). Features thinner than resolution / 4 may be missed.
    double shadowArea(const Vec3& direction, Real resolution) const;
    /// Whether x is far enough inside the narrow band for phi and its gradient to be exact
    /// (one voxel short of the clamp).
    bool inBand(const Vec3& x) const;

    /// Project x onto the zero level set by x <- x - phi(x) n(x), iterated until |phi| falls
    /// below `tolerance` (m; default 1e-3 voxel) or `maxIterations` steps. Fails (converged =
    /// false) when x or an iterate is beyond the band, where no direction to the surface is known.
    SurfaceProjection projectToSurface(const Vec3& x, Real tolerance = Real(-1),
                                       int maxIterations = 20) const;
    /// The same projection for a caller that has phiAndGradient(x) already (`phiX`, `gradX`):
    /// the same iterates, one stencil lookup fewer.
    SurfaceProjection projectToSurface(const Vec3& x, Real phiX, const Vec3& gradX,
                                       Real tolerance = Real(-1), int maxIterations = 20) const;
    /// Move a point inside (phi < 0) to just outside the surface: Newton steps along the
    /// smooth (central-difference) gradient until phi >= 0. Where projectToSurface() oscillates
    /// (at edges and corners the trilinear gradient jumps between cells) this still ends
    /// outside. Fails (converged = false) beyond the band, where no direction is known.
    SurfaceProjection pushOutside(const Vec3& x, int maxSteps = 64) const;

    /// Index-space coordinates (i, j, k) of every grid cell [i, i+1] x [j, j+1] x [k, k+1] whose
    /// 8 corner samples do not all share a sign: the cells the surface passes through. Sorted.
    std::vector<std::array<std::int32_t, 3>> surfaceCells() const;

    /// World position (m) of a point given in index space (voxel centres at integer coordinates).
    Vec3 indexToWorld(const Vec3& ijk) const;
    /// Index-space position of a world point.
    Vec3 worldToIndex(const Vec3& x) const;

    /// Access to the implementation for code that includes LevelSetGrid.h.
    const Impl& impl() const { return *mImpl; }

private:
    std::shared_ptr<const Impl> mImpl;
};

/// The shape `depth` (m) inside `shape`'s surface (its inner parallel surface), as a new
/// narrow band of the same voxel size and band width (OpenVDB's levelSetRebuild of the
/// isosurface phi = -depth; LevelSetOffset.cc). Throws ValueError naming the level set when
/// `depth` is beyond its band less half a voxel, or when nothing of the shape is that deep.
LevelSet erodedLevelSet(const LevelSet& shape, Real depth);

} // namespace sph
} // namespace ghostfx
