/// @file   SurfaceGrid.cc
/// @brief  Liquid surface level set from particles: union of spheres, then a smoothed closing.
/// @details 1. tools::ParticlesToLevelSet rasterises a sphere of radius r = radius * h about
///             every selected particle into a narrow-band level set: the CSG union (the
///             union-of-spheres surface of Zhu and Bridson 2005, "Animating sand as a fluid").
///             Outside the spheres its values are exact distances; inside they are only the
///             depth below the nearest sphere (at most r), so with r below the band half width
///             the whole interior stays active.
///          2. Interior clean-up: voxels deeper than the half width below the exterior (measured
///             by dilating the mask of voxels with phi >= 0) become inactive interior, so the
///             filters below work on a narrow band only (2.5x faster at 1e5 particles).
///          3. tools::LevelSetFilter (Osher and Fedkiw 2003, Ch. 4 - 6):
///             - offset(-c): dilate by the closing distance c, which fills the dips between
///               neighbouring spheres and gaps narrower than about 2 c;
///             - meanCurvature() passes: motion by mean curvature removes the remaining bumps
///               (a few voxels wide) much faster than it shrinks the liquid body;
///             - offset(c + r - o): erode back so a flat surface ends o = offset * h outside the
///               outermost particle centres.
///             Each offset runs in steps of half a voxel, re-normalising the narrow band after
///             each (LevelSetTracker::track) so the band never runs out. One re-normalisation
///             sweep per step instead of OpenVDB's default three: on a flat face of a particle
///             block the distance profile differs by under 0.01 h, at 2.4x less cost.
///          The union and the filters use min / Jacobi updates, so the result does not depend on
///          the thread count. The recipe is that of Houdini's "VDB from Particles" followed by
///          "VDB Reshape SDF" (dilate, smooth, erode) and "VDB Smooth SDF".
#include "FrameGridsDetail.h"

#include <openvdb/tools/LevelSetFilter.h>
#include <openvdb/tools/Morphology.h>
#include <openvdb/tools/ParticlesToLevelSet.h>
#include <openvdb/tools/Prune.h>
#include <openvdb/tree/LeafManager.h>

#include <limits>

namespace ghostfx {
namespace vdbio {
namespace detail {

namespace {

/// The particle list interface of tools::ParticlesToLevelSet over a selection of a set.
class SelectedParticles
{
public:
    using PosType = openvdb::Vec3R;

    SelectedParticles(const std::vector<sph::Vec3>& x, const std::vector<sph::Index>& selection,
                      double radius)
        : mX(x)
        , mSelection(selection)
        , mRadius(radius)
    {}

    std::size_t size() const { return mSelection.size(); }
    void getPos(std::size_t n, openvdb::Vec3R& xyz) const
    {
        const sph::Vec3& x = mX[mSelection[n]];
        xyz = openvdb::Vec3R(x[0], x[1], x[2]);
    }
    void getPosRad(std::size_t n, openvdb::Vec3R& xyz, openvdb::Real& radius) const
    {
        getPos(n, xyz);
        radius = mRadius;
    }

private:
    const std::vector<sph::Vec3>& mX;
    const std::vector<sph::Index>& mSelection;
    double mRadius; ///< (m)
};

/// Re-normalisation sweeps per tracking step of the filters (see the file comment).
constexpr int NORMALISATION_SWEEPS = 1;

/// Make every interior voxel farther than `halfWidthVoxels` (Chebyshev, in voxels) from the
/// exterior (phi >= 0) an inactive interior voxel (value -background), then prune.
void trimInterior(openvdb::FloatGrid& grid, int halfWidthVoxels)
{
    using openvdb::FloatTree;
    using openvdb::MaskTree;
    const FloatTree& phi = grid.tree();
    MaskTree exterior(phi, false, openvdb::TopologyCopy());
    openvdb::tree::LeafManager<MaskTree> exteriorLeaves(exterior);
    exteriorLeaves.foreach ([&phi](MaskTree::LeafNodeType& leaf, std::size_t) {
        const FloatTree::LeafNodeType* values = phi.probeConstLeaf(leaf.origin());
        for (auto it = leaf.beginValueOn(); it; ++it) {
            if (values->getValue(it.pos()) < 0.0f) leaf.setValueOff(it.pos());
        }
    });
    openvdb::tools::dilateActiveValues(exterior, halfWidthVoxels,
                                       openvdb::tools::NN_FACE_EDGE_VERTEX,
                                       openvdb::tools::IGNORE_TILES);
    const float inside = -grid.background();
    openvdb::tree::LeafManager<FloatTree> leaves(grid.tree());
    leaves.foreach ([&exterior, inside](FloatTree::LeafNodeType& leaf, std::size_t) {
        const MaskTree::LeafNodeType* near = exterior.probeConstLeaf(leaf.origin());
        for (auto it = leaf.beginValueOn(); it; ++it) {
            if (*it < 0.0f && !(near && near->isValueOn(it.pos()))) {
                leaf.setValueOff(it.pos(), inside);
            }
        }
    });
    openvdb::tools::pruneLevelSet(grid.tree());
}

} // namespace

openvdb::FloatGrid::Ptr makeSurfaceGrid(const sph::ParticleSet& particles,
                                        const std::vector<sph::Index>& selection,
                                        const VolumeOptions& options)
{
    const double dx = options.voxelSize;
    const double h = options.particleSpacing;
    const double radius = options.surfaceRadiusSpacings * h;
    const double closing = options.surfaceClosingSpacings * h;
    const double offset = options.surfaceOffsetSpacings * h;

    openvdb::FloatGrid::Ptr grid =
        openvdb::createLevelSet<openvdb::FloatGrid>(dx, double(options.surfaceHalfWidthVoxels));
    grid->setName("surface");
    grid->setGridClass(openvdb::GRID_LEVEL_SET);
    grid->insertMeta("units", openvdb::StringMetadata("m (signed distance, negative inside)"));
    grid->insertMeta("particle_spacing", openvdb::FloatMetadata(float(h)));
    if (selection.empty()) return grid;

    const SelectedParticles list(particles.positions(), selection, radius);
    openvdb::tools::ParticlesToLevelSet<openvdb::FloatGrid> raster(*grid);
    // The radius is checked to be at least one voxel (VolumeOptions::validate); the default
    // minimum of 1.5 voxels would silently skip every sphere instead.
    raster.setRmin(0.0);
    raster.setRmax(std::numeric_limits<openvdb::Real>::max());
    raster.rasterizeSpheres(list, radius);
    raster.finalize(/*prune=*/true);
    trimInterior(*grid, options.surfaceHalfWidthVoxels);

    openvdb::tools::LevelSetFilter<openvdb::FloatGrid> filter(*grid);
    filter.setNormCount(NORMALISATION_SWEEPS);
    if (closing > 0.0) filter.offset(float(-closing));
    for (int i = 0; i < options.surfaceSmoothingIterations; ++i) filter.meanCurvature();
    const double erosion = closing + radius - offset;
    if (erosion != 0.0) filter.offset(float(erosion));
    return grid;
}

} // namespace detail
} // namespace vdbio
} // namespace ghostfx
