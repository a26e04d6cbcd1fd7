/// @file   ParticleGrids.cc
/// @brief  SPH rasterisation of particles into sparse OpenVDB grids by gathering: "density"
///         (rho / rho0), "vel" and Shepard-normalised scalar channels.
/// @details At a voxel centre x ([SB12] Eq. 1 evaluated off the particles, with the M4 cubic
///          spline of support R, sph::CubicSplineKernel):
///            rho(x) = sum_j m_j W(|x - x_j|, R)
///            v(x)   = sum_j m_j v_j W(|x - x_j|, R) / rho(x)      (Shepard 1968 normalisation)
///            a(x)   = sum_j m_j a_j W(|x - x_j|, R) / rho(x)      (any scalar channel a)
///          Since the M4 spline integrates to one, sum_voxels rho dx^3 = sum_j m_j up to the
///          quadrature error of the voxel lattice (tested: 1.8e-5 at dx = h / 2, R = 3 h).
///
///          Algorithm, gather over destinations (STYLE.md rule 5):
///          1. Candidate leaves: every 8^3 leaf whose voxel range meets the axis-aligned box of a
///             particle's support. Computed per block of particles, then merged, sorted and
///             made unique, so the list is independent of the thread count.
///          2. Per leaf, in parallel: the particles within R + (leaf half-diagonal) of the leaf
///             centre (sph::NeighborGrid::forEachInRadius); each adds m_j W to the voxels of the
///             leaf inside its support, visiting the rows of its support's box that meet its
///             sphere, each row whole (W is 0 past R; a row's weights are computed in a loop
///             the compiler vectorises, then summed). The task owns its leaf's accumulators and
///             adds the particles in the neighbour grid's order, which does not depend on
///             threads, so results are bit-identical at any thread count.
///          3. Voxels with rho / rho0 below the cutoff stay inactive; leaves with no active voxel
///             are dropped; the others are attached to the trees serially.
///          Cost: sum over particles of the voxels in their support ((4/3) pi (R / dx)^3: 113 at
///          the default voxel of h with R = 3 h, 905 at h / 2) plus the candidate search per leaf.
#include "FrameGridsDetail.h"

#include <ghostfx/sph/Exceptions.h>
#include <ghostfx/sph/Kernels.h>
#include <ghostfx/sph/NeighborGrid.h>
#include <ghostfx/sph/Parallel.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <memory>

namespace ghostfx {
namespace vdbio {
namespace detail {

namespace {

using VecLeaf = openvdb::Vec3STree::LeafNodeType;

/// Particles per block when listing candidate leaves: large enough to amortise the local sort,
/// small enough that a block's leaves stay few (particles are visited in cell order).
constexpr std::size_t LEAF_KEY_BLOCK = 4096;

/// The selected particles, copied into dense arrays (only what the asked grids need).
struct Selected
{
    std::vector<sph::Vec3> x;              ///< positions (m)
    std::vector<sph::Real> m;              ///< masses (kg)
    std::vector<sph::Vec3> v;              ///< velocities (m/s), if "vel" is asked
    std::vector<std::vector<sph::Real>> a; ///< scalar channels, in the order asked
    /// Each particle's kernel support (m), with VolumeOptions::supportChannel; else empty.
    std::vector<sph::Real> R;
    double maxR = 0; ///< the largest support (m)
};

/// The leaves of the output grids built for one candidate leaf (null where nothing is active).
struct LeafOutput
{
    std::unique_ptr<FloatLeaf> density;
    std::unique_ptr<VecLeaf> vel;
    std::vector<std::unique_ptr<FloatLeaf>> channels;
};

openvdb::math::Transform::Ptr makeTransform(double voxelSize)
{
    return openvdb::math::Transform::createLinearTransform(voxelSize);
}

} // namespace

std::vector<openvdb::Coord> leavesNearParticles(const std::vector<sph::Vec3>& x,
                                                const std::vector<sph::Index>& order, double dx,
                                                double reach, const std::vector<sph::Real>* reaches)
{
    const std::size_t n = order.size();
    const std::size_t nBlocks = (n + LEAF_KEY_BLOCK - 1) / LEAF_KEY_BLOCK;
    std::vector<std::vector<openvdb::Coord>> perBlock(nBlocks);
    const double invDx = 1.0 / dx;
    const int mask = ~(LEAF_DIM - 1);
    parallel::forEach(
        0, nBlocks,
        [&](std::size_t b) {
        std::vector<openvdb::Coord>& keys = perBlock[b];
        // Leaves listed lately, by a hash of their origin: neighbouring particles (cell order)
        // share most of their leaves, so this drops most repeats before the sort.
        std::array<openvdb::Coord, 512> recent;
        recent.fill(openvdb::Coord(1, 1, 1)); // not a leaf origin
        const std::size_t end = std::min(n, (b + 1) * LEAF_KEY_BLOCK);
        for (std::size_t k = b * LEAF_KEY_BLOCK; k < end; ++k) {
            const sph::Vec3& p = x[order[k]];
            const double r = reaches ? double((*reaches)[order[k]]) : reach;
            int lo[3], hi[3];
            for (int d = 0; d < 3; ++d) {
                voxelRange(double(p[d]), r, invDx, lo[d], hi[d]);
                lo[d] &= mask;
                hi[d] &= mask;
            }
            for (int i = lo[0]; i <= hi[0]; i += LEAF_DIM) {
                for (int j = lo[1]; j <= hi[1]; j += LEAF_DIM) {
                    for (int l = lo[2]; l <= hi[2]; l += LEAF_DIM) {
                        const openvdb::Coord key(i, j, l);
                        const std::size_t slot =
                            (std::size_t(i >> 3) * 73856093u ^ std::size_t(j >> 3) * 19349663u
                             ^ std::size_t(l >> 3) * 83492791u)
                            & (recent.size() - 1);
                        if (recent[slot] == key) continue;
                        recent[slot] = key;
                        keys.push_back(key);
                    }
                }
            }
            if (keys.size() > 4 * LEAF_KEY_BLOCK) { // keep the block's list short
                std::sort(keys.begin(), keys.end());
                keys.erase(std::unique(keys.begin(), keys.end()), keys.end());
            }
        }
        std::sort(keys.begin(), keys.end());
        keys.erase(std::unique(keys.begin(), keys.end()), keys.end());
        },
        1);
    std::vector<openvdb::Coord> leaves;
    for (const auto& keys : perBlock) leaves.insert(leaves.end(), keys.begin(), keys.end());
    std::sort(leaves.begin(), leaves.end());
    leaves.erase(std::unique(leaves.begin(), leaves.end()), leaves.end());
    return leaves;
}

namespace {

/// The grids makeParticleGrids fills, empty until their leaves are attached.
struct OutputGrids
{
    openvdb::FloatGrid::Ptr density;
    openvdb::Vec3SGrid::Ptr vel;
    std::vector<openvdb::FloatGrid::Ptr> channels; ///< in the order asked

    /// The grids `options` asks for: "density", "vel", then the channels.
    openvdb::GridPtrVec asked(const VolumeOptions& options) const
    {
        openvdb::GridPtrVec out;
        if (options.density) out.push_back(density);
        if (options.velocity) out.push_back(vel);
        for (auto& g : channels) out.push_back(g);
        return out;
    }
};

/// Give `grid` the voxels of `xform` and the kernel support `R` (m) as metadata.
void placeGrid(openvdb::GridBase& grid, const openvdb::math::Transform& xform, double R)
{
    grid.setTransform(xform.copy());
    grid.insertMeta("kernel_support", openvdb::FloatMetadata(float(R)));
}

/// The background of channel `name`'s grid, which its voxels outside the particles keep: the
/// ambient temperature for "temperature" where `options` gives one, else 0.
float channelBackground(const VolumeOptions& options, const std::string& name)
{
    const bool ambient = name == "temperature" && !std::isnan(options.ambientTemperature);
    return ambient ? float(options.ambientTemperature) : 0.0f;
}

/// channelBackground() of every channel, in the order asked.
std::vector<float> channelBackgrounds(const VolumeOptions& options)
{
    std::vector<float> backgrounds;
    for (const std::string& name : options.scalarChannels)
        backgrounds.push_back(channelBackground(options, name));
    return backgrounds;
}

/// The empty output grids, named, described and placed (fog voxel size) as `options` asks.
OutputGrids makeOutputGrids(const VolumeOptions& options)
{
    const openvdb::math::Transform::Ptr xform = makeTransform(options.fogVoxelSize());
    const double R = options.kernelSupport;
    OutputGrids grids;
    grids.density = openvdb::FloatGrid::create(0.0f);
    openvdb::FloatGrid& density = *grids.density;
    density.setName("density");
    density.setGridClass(openvdb::GRID_FOG_VOLUME);
    density.insertMeta("rest_density", openvdb::FloatMetadata(float(options.restDensity)));
    density.insertMeta(
        "units", openvdb::StringMetadata("rho/rho0 (dimensionless); kg/m^3 = value * rest_density; "
                                         "mass (kg) = rest_density * sum(values) * voxel_size^3"));
    grids.vel = openvdb::Vec3SGrid::create(openvdb::Vec3s(0.0f));
    grids.vel->setName("vel");
    grids.vel->setVectorType(openvdb::VEC_CONTRAVARIANT_RELATIVE);
    grids.vel->insertMeta("units", openvdb::StringMetadata("m/s"));
    placeGrid(density, *xform, R);
    placeGrid(*grids.vel, *xform, R);
    for (const std::string& name : options.scalarChannels) {
        openvdb::FloatGrid::Ptr g = openvdb::FloatGrid::create(channelBackground(options, name));
        g->setName(name);
        if (name == "temperature" && !std::isnan(options.ambientTemperature)) {
            g->insertMeta(AMBIENT_TEMPERATURE_METADATA,
                          openvdb::FloatMetadata(float(options.ambientTemperature)));
        }
        g->setGridClass(openvdb::GRID_FOG_VOLUME);
        g->insertMeta(
            "normalisation",
            openvdb::StringMetadata(
                "Shepard: sum m a W / sum m W over the particles within the kernel support"));
        placeGrid(*g, *xform, R);
        grids.channels.push_back(g);
    }
    return grids;
}

/// Dense copies of what the asked grids need of the particles `selection` of `particles`.
Selected selectParticles(const sph::ParticleSet& particles,
                         const std::vector<sph::Index>& selection, const VolumeOptions& options)
{
    const bool wantVel = options.velocity;
    const std::size_t nChannels = options.scalarChannels.size();
    Selected sel;
    const std::size_t n = selection.size();
    sel.x.resize(n);
    sel.m.resize(n);
    if (wantVel) sel.v.resize(n);
    sel.a.resize(nChannels);
    const std::vector<sph::Real>* support =
        options.supportChannel.empty() ? nullptr : &particles.scalarChannel(options.supportChannel);
    const sph::Real R = sph::Real(options.kernelSupport);
    if (support) sel.R.resize(n);
    std::vector<const std::vector<sph::Real>*> source(nChannels);
    for (std::size_t c = 0; c < nChannels; ++c) {
        const std::string& name = options.scalarChannels[c];
        source[c] = name == "pressure" && !particles.hasScalarChannel(name)
                        ? &particles.pressures()
                        : &particles.scalarChannel(name);
        sel.a[c].resize(n);
    }
    parallel::forEach(
        0, n,
        [&](std::size_t k) {
        const sph::Index i = selection[k];
        sel.x[k] = particles.positions()[i];
        sel.m[k] = particles.masses()[i];
        if (wantVel) sel.v[k] = particles.velocities()[i];
        for (std::size_t c = 0; c < nChannels; ++c) sel.a[c][k] = (*source[c])[i];
        if (support) {
            sel.R[k] = std::clamp((*support)[i], R,
                                  sph::Real(VolumeOptions::MAX_SUPPORT_SCALE * options.kernelSupport));
        }
        },
        4096);
    sel.maxR = options.kernelSupport;
    for (sph::Real r : sel.R) sel.maxR = std::max(sel.maxR, double(r));
    return sel;
}

/// One leaf's sums over the particles, in double: a hundred-odd terms each, in a fixed order.
struct LeafSums
{
    std::vector<double> rho;        ///< sum m_j W per voxel
    std::vector<openvdb::Vec3d> mv; ///< sum m_j v_j W per voxel, if "vel" is asked
    std::vector<double> ma;         ///< sum m_j a_j W per channel and voxel
};

/// Step 2 of the file comment: the particles' sums on one candidate leaf, then its output leaves.
class DensityGather
{
public:
    /// Gather `sel` (neighbour grid `grid`, cells of the kernel support) as `options` asks.
    DensityGather(const Selected& sel, const sph::NeighborGrid& grid, const VolumeOptions& options)
        : mSel(sel)
        , mGrid(grid)
        , mKernel{sph::Real(options.kernelSupport)}
        , mDx(options.fogVoxelSize())
        , mInvDx(1.0 / mDx)
        , mR(options.kernelSupport)
        , mR2(mR * mR)
        , mRho0(options.restDensity)
        , mCutoff(options.densityCutoff)
        , mWantVel(options.velocity)
        , mChannels(options.scalarChannels.size())
        , mChannelBackgrounds(channelBackgrounds(options))
        , mSearchRadius(sph::Real(sel.maxR + leafHalfDiagonal(mDx)))
    {}

    /// The output leaves of the leaf at `origin`.
    LeafOutput operator()(const openvdb::Coord& origin) const
    {
        LeafSums sums;
        sums.rho.assign(LEAF_VOXELS, 0.0);
        sums.mv.assign(mWantVel ? LEAF_VOXELS : 0, openvdb::Vec3d(0.0));
        sums.ma.assign(mChannels * LEAF_VOXELS, 0.0);
        mGrid.forEachInRadius(leafCentre(origin, mDx), mSearchRadius,
                              [&](sph::Index j, const sph::Vec3&, sph::Real) {
            addParticle(j, origin, sums);
        });
        return keptVoxels(origin, sums);
    }

private:
    /// Add particle j's m_j W (and its velocity's and channels' shares) to the voxels of the
    /// leaf at `origin` inside its support: the rows of its support's box that meet its sphere.
    void addParticle(sph::Index j, const openvdb::Coord& origin, LeafSums& sums) const
    {
        const double xj[3] = {double(mSel.x[j][0]), double(mSel.x[j][1]), double(mSel.x[j][2])};
        const bool own = !mSel.R.empty();
        const double Rj = own ? double(mSel.R[j]) : mR;
        const double reach[3] = {Rj, Rj, Rj};
        int lo[3], hi[3];
        if (!boxInLeaf(xj, reach, mInvDx, origin, lo, hi)) return;
        const sph::CubicSplineKernel kernel = own ? sph::CubicSplineKernel(mSel.R[j]) : mKernel;
        const double R2 = own ? Rj * Rj : mR2;
        const double mj = double(mSel.m[j]);
        for (int a = lo[0]; a <= hi[0]; ++a) {
            const double dxa = (origin.x() + a) * mDx - xj[0];
            const double ra2 = dxa * dxa;
            for (int b = lo[1]; b <= hi[1]; ++b) {
                const double dyb = (origin.y() + b) * mDx - xj[1];
                const double rab2 = ra2 + dyb * dyb;
                if (rab2 >= R2) continue;
                addRow(j, kernel, origin, xj, mj, rab2, (a << 6) | (b << 3), lo[2], hi[2], sums);
            }
        }
    }

    /// Particle j's shares (its kernel `kernel`) on the voxels [clo, chi] of the leaf row at
    /// offset `row` (LeafNode::coordToOffset), `rab2` its squared distance (m^2) off the row's
    /// axis. The
    /// whole row of the support's box, weights first (a loop the compiler vectorises: W is
    /// branch-free and 0 outside the support, which adds nothing), then the sums. Cheaper than
    /// finding the row's z range inside the sphere (a square root and two roundings) when rows
    /// are a few voxels.
    void addRow(sph::Index j, const sph::CubicSplineKernel& kernel, const openvdb::Coord& origin,
                const double xj[3], double mj, double rab2, int row, int clo, int chi,
                LeafSums& sums) const
    {
        double w[LEAF_DIM];
        for (int c = clo; c <= chi; ++c) {
            const double dzc = (origin.z() + c) * mDx - xj[2];
            const double r = std::sqrt(rab2 + dzc * dzc);
            w[c] = mj * double(kernel.W(sph::Real(r)));
        }
        for (int c = clo; c <= chi; ++c) sums.rho[row | c] += w[c];
        if (mWantVel) {
            const openvdb::Vec3d vj(mSel.v[j][0], mSel.v[j][1], mSel.v[j][2]);
            for (int c = clo; c <= chi; ++c) sums.mv[row | c] += w[c] * vj;
        }
        for (std::size_t ch = 0; ch < mChannels; ++ch) {
            const double aj = double(mSel.a[ch][j]);
            double* channel = &sums.ma[ch * LEAF_VOXELS + row];
            for (int c = clo; c <= chi; ++c) channel[c] += w[c] * aj;
        }
    }

    /// Step 3 of the file comment: the voxels of `sums` whose density reaches the cutoff,
    /// normalised, as leaves at `origin` (none where no voxel is kept).
    LeafOutput keptVoxels(const openvdb::Coord& origin, const LeafSums& sums) const
    {
        LeafOutput res;
        for (int voxel = 0; voxel < LEAF_VOXELS; ++voxel) {
            const double ratio = sums.rho[voxel] / mRho0;
            if (!(ratio > 0.0) || ratio < mCutoff) continue;
            if (!res.density) {
                res.density = std::make_unique<FloatLeaf>(origin, 0.0f, false);
                if (mWantVel) {
                    res.vel = std::make_unique<VecLeaf>(origin, openvdb::Vec3s(0.0f), false);
                }
                res.channels.resize(mChannels);
                for (std::size_t ch = 0; ch < mChannels; ++ch) {
                    res.channels[ch] =
                        std::make_unique<FloatLeaf>(origin, mChannelBackgrounds[ch], false);
                }
            }
            const openvdb::Index offset = openvdb::Index(voxel);
            res.density->setValueOn(offset, float(ratio));
            const double invRho = 1.0 / sums.rho[voxel];
            if (mWantVel) res.vel->setValueOn(offset, openvdb::Vec3s(sums.mv[voxel] * invRho));
            for (std::size_t ch = 0; ch < mChannels; ++ch) {
                const double ma = sums.ma[ch * LEAF_VOXELS + voxel];
                res.channels[ch]->setValueOn(offset, float(ma * invRho));
            }
        }
        return res;
    }

    const Selected& mSel;
    const sph::NeighborGrid& mGrid;
    const sph::CubicSplineKernel mKernel;
    const double mDx, mInvDx;
    const double mR, mR2; ///< kernel support (m), its square
    const double mRho0, mCutoff;
    const bool mWantVel;
    const std::size_t mChannels;
    const std::vector<float> mChannelBackgrounds; ///< each channel's inactive value
    /// The kernel support plus a leaf's half-diagonal: the particles that may reach a leaf (m).
    const sph::Real mSearchRadius;
};

/// Attach the built leaves to `grids` in leaf order (serial: tree insertion is not
/// thread-safe); the density leaves only where "density" is asked.
void attachLeaves(std::vector<LeafOutput>& results, OutputGrids& grids,
                  const VolumeOptions& options)
{
    for (LeafOutput& res : results) {
        if (!res.density) continue;
        if (options.density) grids.density->tree().addLeaf(res.density.release());
        if (options.velocity) grids.vel->tree().addLeaf(res.vel.release());
        for (std::size_t ch = 0; ch < grids.channels.size(); ++ch) {
            grids.channels[ch]->tree().addLeaf(res.channels[ch].release());
        }
    }
}

} // namespace

openvdb::GridPtrVec makeParticleGrids(const sph::ParticleSet& particles,
                                      const std::vector<sph::Index>& selection,
                                      const VolumeOptions& options)
{
    OutputGrids grids = makeOutputGrids(options);
    const Selected sel = selectParticles(particles, selection, options);
    if (sel.x.empty()) return grids.asked(options);

    sph::NeighborGrid grid{sph::Real(sel.maxR)};
    grid.build(sel.x);
    const std::vector<openvdb::Coord> leaves =
        leavesNearParticles(sel.x, grid.order(), options.fogVoxelSize(), options.kernelSupport,
                            sel.R.empty() ? nullptr : &sel.R);
    std::vector<LeafOutput> results(leaves.size());
    const DensityGather gather(sel, grid, options);
    parallel::forEach(
        0, leaves.size(), [&](std::size_t L) { results[L] = gather(leaves[L]); }, 1);
    attachLeaves(results, grids, options);
    return grids.asked(options);
}

} // namespace detail
} // namespace vdbio
} // namespace ghostfx
