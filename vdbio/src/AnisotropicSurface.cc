/// @file   AnisotropicSurface.cc
/// @brief  Liquid surface level set from anisotropic kernels: Yu and Turk, "Reconstructing
///         surfaces of particle-based fluids using anisotropic kernels" (SCA 2010; ACM TOG
///         32(1), 2013).
/// @details A union of spheres has a bump per particle, which SurfaceGrid.cc closes and smooths
///          away, and rough thin sheets. Yu and Turk give each particle a kernel shaped like its
///          neighbourhood instead: flat where the particle sits on a surface or in a sheet, round
///          inside the liquid, and small when it is alone.
///          With r = `anisotropicNeighborhoodSpacings` h, h_k = `anisotropicKernelSpacings` h:
///          1. Weighted mean and covariance of the neighbours j of particle i within r (the
///             particle itself included), with the paper's weights w_ij = 1 - (|x_i - x_j| / r)^3:
///               xw_i = sum_j w_ij x_j / sum_j w_ij,
///               C_i  = sum_j w_ij (x_j - xw_i)(x_j - xw_i)^T / sum_j w_ij.
///          2. Laplacian smoothing of the kernel centres (the paper's answer to the particles'
///             irregular spacing on a surface):
///               xbar_i = (1 - lambda) x_i + lambda xw_i.
///          3. C_i = R diag(sigma_1 >= sigma_2 >= sigma_3) R^T (Jacobi rotations,
///             openvdb::math::diagonalizeSymmetricMatrix), the eigenvalues measured in units
///             of sigma_u = 0.15 r^2, the eigenvalue of a full uniform neighbourhood. The
///             kernel's semi-axes along R's columns are s_k h_k with
///               s_k = k_s max(sigma_k, sigma_1 / k_r)  if the particle has more than N_eps
///                                                     neighbours (itself not counted),
///               s_k = k_n                             otherwise,
///             so G_i = R diag(1 / s_k) R^T / h_k maps the ellipsoid to the unit ball.
///          4. The field, a volume fraction (1 inside a liquid at rest density):
///               phi(x) = sum_j V_j det(G_j) P(|G_j (x - xbar_j)|),  V_j = m_j / rho0,
///             with P the M4 spline of unit support (sph::CubicSplineKernel(1)),
///             so each particle adds exactly its volume V_j to the integral of phi, whatever
///             its shape. The paper's m_j / rho_j takes the simulation's density; rho0 is used
///             here because SPH densities run low at a free surface (half a neighbourhood) and
///             would inflate exactly the particles that place the surface.
///          5. The surface is phi = `anisotropicIsoValue`; OpenVDB's fast sweeping
///             (tools::fogToSdf, Zhao 2005) turns the narrow band around it into signed
///             distances, negative inside.
///
///          Sparse and deterministic, as ParticleGrids.cc: phi is gathered per 8^3 leaf near the
///          kernels' bounding boxes, each leaf summing the kernels near it nearest first, in an
///          order that does not depend on threads, over the rows of voxels that meet each
///          ellipsoid (splatKernel). Inside the liquid only the sign of phi - iso matters, so a
///          leaf stops once every voxel exceeds the iso-value (after about 100 of its 2500
///          kernels at the defaults) unless it touches the surface (gatherField); the level set
///          is bit-identical to that of full sums (checked on a 60k-particle block). The band is
///          the voxels within `surfaceHalfWidthVoxels` + 1 (Chebyshev) of a voxel whose face
///          neighbour lies across the iso-value; only those are swept. Fast sweeping updates the
///          voxels of one diagonal slice independently, so the level set is the same at any
///          thread count.
///
///          Calibration (tests/vdbio/test_surface_accuracy.cc, "[measured]" lines): see
///          VolumeOptions::anisotropicIsoValue. Cost (bench/bench_surface.cc, 1e5 particles):
///          about 3.5x the sphere method's, two thirds of it the field on the leaves at and
///          outside the surface, where no sum can stop early (bench/history/diary-2026-11.md).
#include "FrameGridsDetail.h"

#include <ghostfx/sph/Kernels.h>
#include <ghostfx/sph/NeighborGrid.h>
#include <ghostfx/sph/Parallel.h>
#include <ghostfx/vdbio/MaskDilation.h>

#include <openvdb/math/Mat3.h>
#include <openvdb/tools/ChangeBackground.h>
#include <openvdb/tools/FastSweeping.h>
#include <openvdb/tools/Prune.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>

namespace ghostfx {
namespace vdbio {
namespace detail {

namespace {

using MaskLeaf = openvdb::MaskTree::LeafNodeType;

/// Covariance eigenvalue of a full uniform neighbourhood per r^2, for the weights
/// w = 1 - (d / r)^3: int_0^r w d^4 dd / (3 int_0^r w d^2 dd) = (3 r^5 / 40) / (r^3 / 2) = 0.15.
constexpr double UNIFORM_EIGENVALUE_PER_R2 = 0.15;
/// Largest eigenvalue (units of the uniform one) below which a neighbourhood counts as
/// degenerate (all neighbours on the particle) and gets the isolated particle's round kernel.
constexpr double DEGENERATE_EIGENVALUE = 1e-6;

/// The anisotropy settings in metres.
struct Params
{
    double kernelRadius;       ///< h_k (m)
    double neighborhoodRadius; ///< r (m)
    double lambda;             ///< centre smoothing
    double maxStretch;         ///< k_r
    int minNeighbors;          ///< N_eps
    double scale;              ///< k_s (units of the uniform eigenvalue)
    double isolatedScale;      ///< k_n
};

/// One particle's anisotropic kernel.
struct Kernel
{
    openvdb::Vec3d centre;     ///< xbar (m)
    openvdb::Mat3d G;          ///< u = G (x - xbar): the ellipsoid is |u| < 1 (1/m)
    openvdb::Vec3d halfExtent; ///< half extents of the ellipsoid's axis-aligned box (m)
    double reach;              ///< largest semi-axis (m)
    double weight;             ///< V det(G) (dimensionless)
};

/// Kernel of one particle from its neighbourhood (steps 1 - 3 of the file comment).
Kernel makeKernel(const sph::NeighborGrid& grid, sph::Index i, const sph::Vec3& xi, double volume,
                  const Params& p)
{
    // Sums relative to x_i, in double: offsets of a few h, no cancellation.
    double sumW = 0.0;
    openvdb::Vec3d sumD(0.0);
    openvdb::Mat3d sumDD = openvdb::Mat3d::zero();
    int neighbors = 0;
    const double invR = 1.0 / p.neighborhoodRadius;
    grid.forEachNeighbor(i, [&](sph::Index j, const sph::Vec3& xij, sph::Real rij) {
        const double q = double(rij) * invR;
        const double w = 1.0 - q * q * q;
        const openvdb::Vec3d d(-double(xij[0]), -double(xij[1]), -double(xij[2])); // x_j - x_i
        sumW += w;
        sumD += w * d;
        for (int a = 0; a < 3; ++a)
            for (int b = 0; b < 3; ++b) sumDD(a, b) += w * d[a] * d[b];
        neighbors += int(j != i);
    });
    const openvdb::Vec3d mean = sumD / sumW; // xw_i - x_i
    const double sigmaU = UNIFORM_EIGENVALUE_PER_R2 * p.neighborhoodRadius * p.neighborhoodRadius;
    openvdb::Mat3d C;
    for (int a = 0; a < 3; ++a)
        for (int b = 0; b < 3; ++b) C(a, b) = (sumDD(a, b) / sumW - mean[a] * mean[b]) / sigmaU;

    Kernel k;
    k.centre = openvdb::Vec3d(xi[0], xi[1], xi[2]) + p.lambda * mean; // Laplacian smoothing
    openvdb::Mat3d R = openvdb::Mat3d::identity();
    openvdb::Vec3d stretch(p.isolatedScale);
    if (neighbors > p.minNeighbors) {
        openvdb::Vec3d sigma;
        openvdb::math::diagonalizeSymmetricMatrix(C, R, sigma); // C = R diag(sigma) R^T
        const double sigma1 = std::max({sigma[0], sigma[1], sigma[2]});
        if (sigma1 > DEGENERATE_EIGENVALUE) {
            for (int a = 0; a < 3; ++a) {
                stretch[a] = p.scale * std::max(sigma[a], sigma1 / p.maxStretch);
            }
        } else {
            R = openvdb::Mat3d::identity();
        }
    }
    // G = R diag(1 / (s h_k)) R^T; box half extent along axis a: |row a of G^-1|.
    for (int a = 0; a < 3; ++a) {
        double extent2 = 0.0;
        for (int b = 0; b < 3; ++b) {
            double g = 0.0;
            for (int m = 0; m < 3; ++m) g += R(a, m) * R(b, m) / (stretch[m] * p.kernelRadius);
            k.G(a, b) = g;
            extent2 += openvdb::math::Pow2(R(a, b) * stretch[b] * p.kernelRadius);
        }
        k.halfExtent[a] = std::sqrt(extent2);
    }
    k.reach = p.kernelRadius * std::max({stretch[0], stretch[1], stretch[2]});
    k.weight =
        volume / (stretch[0] * stretch[1] * stretch[2] * openvdb::math::Pow3(p.kernelRadius));
    return k;
}

/// Kernels of every particle, in particle order; `grid` holds `x` with cells of size r.
std::vector<Kernel> makeKernels(const sph::NeighborGrid& grid, const std::vector<sph::Vec3>& x,
                                const std::vector<double>& volume, const Params& p)
{
    std::vector<Kernel> kernels(x.size());
    parallel::forEach(
        0, x.size(),
        [&](std::size_t i) { kernels[i] = makeKernel(grid, sph::Index(i), x[i], volume[i], p); },
        64);
    return kernels;
}

/// Origins of the leaves that meet the bounding box of the kernels of some cell of `grid` (the
/// particles' neighbour grid), sorted and unique: a few more leaves than the kernels' own boxes
/// meet (those leaves sum to phi = 0 and are dropped), at a fiftieth of the keys to sort.
std::vector<openvdb::Coord> candidateLeaves(const std::vector<Kernel>& kernels,
                                            const sph::NeighborGrid& grid, double dx)
{
    const std::size_t nCells = grid.cellCount();
    std::vector<std::vector<openvdb::Coord>> perCell(nCells);
    const double invDx = 1.0 / dx;
    const int mask = ~(LEAF_DIM - 1);
    parallel::forEach(
        0, nCells,
        [&](std::size_t c) {
        openvdb::Vec3d lo(std::numeric_limits<double>::max()), hi(-lo);
        const sph::NeighborGrid::SlotRange slots = grid.cellSlotsAt(c);
        for (std::uint32_t s = slots.begin; s < slots.end; ++s) {
            const Kernel& k = kernels[grid.particleAt(s)];
            lo = openvdb::math::minComponent(lo, k.centre - k.halfExtent);
            hi = openvdb::math::maxComponent(hi, k.centre + k.halfExtent);
        }
        int first[3], last[3];
        for (int d = 0; d < 3; ++d) {
            first[d] = int(std::ceil(lo[d] * invDx)) & mask;
            last[d] = int(std::floor(hi[d] * invDx)) & mask;
        }
        std::vector<openvdb::Coord>& keys = perCell[c];
        for (int i = first[0]; i <= last[0]; i += LEAF_DIM)
            for (int j = first[1]; j <= last[1]; j += LEAF_DIM)
                for (int l = first[2]; l <= last[2]; l += LEAF_DIM) keys.emplace_back(i, j, l);
        },
        16);
    std::vector<openvdb::Coord> leaves;
    for (const auto& keys : perCell) leaves.insert(leaves.end(), keys.begin(), keys.end());
    std::sort(leaves.begin(), leaves.end());
    leaves.erase(std::unique(leaves.begin(), leaves.end()), leaves.end());
    return leaves;
}

/// Add kernel k's contribution V det(G) P(|G (x - xbar)|) to the voxels of the leaf at `origin`
/// (accumulators `phi`, indexed as LeafNode::coordToOffset).
/// @details Per voxel row along z inside the kernel's box: skipped if the line misses the
///          ellipsoid (min over t of |u0 + t gz|^2 >= 1), else summed over the whole row without
///          branches (the spline is 0 from q = 1 on) in float, so the loop vectorises. Exact
///          per-row z ranges (the roots of the quadratic) cost more than they save on rows of at
///          most 8 voxels (measured: 2.4x slower at 1e5 particles).
void splatKernel(const Kernel& k, const openvdb::Coord& origin, double dx,
                 const sph::CubicSplineKernel& unit, float* phi)
{
    const double invDx = 1.0 / dx;
    int lo[3], hi[3];
    if (!boxInLeaf(k.centre.asPointer(), k.halfExtent.asPointer(), invDx, origin, lo, hi)) return;
    const openvdb::Vec3d gz = k.G.col(2); // u changes by gz per metre along z
    const double invGzz = 1.0 / gz.dot(gz);
    const float gzx = float(gz[0]), gzy = float(gz[1]), gzz = float(gz[2]);
    const float z0 = float(origin.z() * dx - k.centre[2]); // z offset of the leaf's voxel 0
    const float step = float(dx), weight = float(k.weight);
    for (int a = lo[0]; a <= hi[0]; ++a) {
        const double dxa = (origin.x() + a) * dx - k.centre[0];
        for (int b = lo[1]; b <= hi[1]; ++b) {
            const double dyb = (origin.y() + b) * dx - k.centre[1];
            const openvdb::Vec3d u0 = k.G * openvdb::Vec3d(dxa, dyb, 0.0); // u at z offset 0
            const double along = u0.dot(gz);
            if (u0.dot(u0) - along * along * invGzz >= 1.0) continue; // the row misses
            const float ux = float(u0[0]), uy = float(u0[1]), uz = float(u0[2]);
            float* row = phi + ((a << 6) | (b << 3));
            for (int c = lo[2]; c <= hi[2]; ++c) {
                const float t = z0 + float(c) * step;
                const float vx = ux + t * gzx, vy = uy + t * gzy, vz = uz + t * gzz;
                row[c] += weight * unit.W(std::sqrt(vx * vx + vy * vy + vz * vz));
            }
        }
    }
}

/// Gathers phi (step 4) on one leaf from the kernels near it.
class LeafGather
{
public:
    LeafGather(const std::vector<Kernel>& kernels, double dx)
        : mKernels(kernels)
        , mDx(dx)
        , mGrid(sph::Real(largestReach(kernels)))
    {
        // Neighbour grid over the kernel centres, cells as large as the largest kernel.
        std::vector<sph::Vec3> centres(kernels.size());
        for (std::size_t j = 0; j < kernels.size(); ++j) {
            const openvdb::Vec3d& c = kernels[j].centre;
            centres[j] = sph::Vec3(sph::Real(c[0]), sph::Real(c[1]), sph::Real(c[2]));
        }
        mGrid.build(centres);
        // Half-diagonal of a leaf between its outermost voxel centres, plus float rounding of
        // the centres (m).
        mSearchRadius = sph::Real((largestReach(kernels) + leafHalfDiagonal(dx)) * (1.0 + 1e-5));
    }

    /// Add to `phi` the kernels near the leaf at `origin` in order of distance from the leaf's
    /// centre (nearestFirst: the same order at any thread count), from the `next`-th on; on
    /// return `next` is where the sum stopped. With `stopAbove` >= 0 the sum stops as soon as
    /// every voxel exceeds it, and returns true: the leaf is then known to lie inside, and
    /// calling again with the same `phi` and `next` and no stop completes the same sum.
    bool gather(const openvdb::Coord& origin, float stopAbove, float* phi, std::size_t& next) const
    {
        const std::vector<sph::Index> near = nearestFirst(leafCentre(origin, mDx));
        for (; next < near.size(); ++next) {
            splatKernel(mKernels[near[next]], origin, mDx, mUnit, phi);
            if (stopAbove >= 0.0f && next % SATURATION_CHECK == SATURATION_CHECK - 1
                && *std::min_element(phi, phi + LEAF_VOXELS) > stopAbove) {
                ++next;
                return true;
            }
        }
        return false;
    }

private:
    /// The kernels within the search radius of `centre`, nearest first by shells of
    /// 1 / DISTANCE_BINS of the radius; within a shell in the grid's order (a stable counting
    /// sort: cheaper than sorting, and as good for stopping early).
    std::vector<sph::Index> nearestFirst(const sph::Vec3& centre) const
    {
        std::vector<std::pair<int, sph::Index>> found;
        const sph::Real toBin = sph::Real(DISTANCE_BINS) / mSearchRadius;
        mGrid.forEachInRadius(centre, mSearchRadius,
                              [&](sph::Index j, const sph::Vec3&, sph::Real r) {
            found.emplace_back(std::min(int(r * toBin), DISTANCE_BINS - 1), j);
        });
        std::size_t start[DISTANCE_BINS + 1] = {};
        for (const auto& f : found) ++start[f.first + 1];
        for (int b = 0; b < DISTANCE_BINS; ++b) start[b + 1] += start[b];
        std::vector<sph::Index> order(found.size());
        for (const auto& f : found) order[start[f.first]++] = f.second;
        return order;
    }

    static double largestReach(const std::vector<Kernel>& kernels)
    {
        double reach = 0.0;
        for (const Kernel& k : kernels) reach = std::max(reach, k.reach);
        return reach;
    }

    /// Kernels summed between two checks for saturation.
    static constexpr std::size_t SATURATION_CHECK = 16;
    /// Distance shells of the nearest-first order.
    static constexpr int DISTANCE_BINS = 32;

    const std::vector<Kernel>& mKernels;
    double mDx;
    sph::NeighborGrid mGrid;                          ///< kernel centres
    sph::Real mSearchRadius;                          ///< (m)
    const sph::CubicSplineKernel mUnit{sph::Real(1)}; // P: the M4 spline of unit support
};

/// Whether a leaf whose phi is only known to exceed `iso` everywhere ("saturated") touches a
/// voxel at or below `iso` across one of its faces: then its values take part in placing the
/// surface (fast sweeping interpolates phi between such neighbours) and must be exact.
/// `leaves` is sorted; `phi` and `saturated` are indexed like it; a missing leaf holds 0.
bool touchesOutside(std::size_t L, const std::vector<openvdb::Coord>& leaves,
                    const std::vector<std::unique_ptr<FloatLeaf>>& phi,
                    const std::vector<std::uint8_t>& saturated, float iso)
{
    for (int axis = 0; axis < 3; ++axis) {
        for (int side : {-1, 1}) {
            openvdb::Coord origin = leaves[L];
            origin[axis] += side * LEAF_DIM;
            const auto it = std::lower_bound(leaves.begin(), leaves.end(), origin);
            if (it == leaves.end() || *it != origin) return true;
            const std::size_t M = std::size_t(it - leaves.begin());
            if (!phi[M]) return true; // phi = 0 there
            if (saturated[M]) continue;
            // The neighbour's layer of voxels against this leaf.
            const int layer = side > 0 ? 0 : LEAF_DIM - 1;
            for (int a = 0; a < LEAF_DIM; ++a) {
                for (int b = 0; b < LEAF_DIM; ++b) {
                    openvdb::Coord ijk;
                    ijk[axis] = layer;
                    ijk[(axis + 1) % 3] = a;
                    ijk[(axis + 2) % 3] = b;
                    if (phi[M]->getValue(FloatLeaf::coordToOffset(ijk)) <= iso) return true;
                }
            }
        }
    }
    return false;
}

/// phi (step 4) on every candidate leaf, as inactive values of a fog tree (background 0).
/// @details Inside the liquid only the sign of phi - iso matters (fast sweeping reads phi only
///          where it crosses the iso-value between face neighbours), so a leaf stops summing
///          once all its voxels exceed the iso-value; the kernels come nearest first, so a leaf
///          inside the liquid stops after a fraction of them. Such a leaf that touches a voxel
///          at or below the iso-value across a face then completes its sum. Both passes are
///          deterministic, so the result is the same at any thread count.
openvdb::FloatTree::Ptr gatherField(const std::vector<Kernel>& kernels,
                                    const std::vector<openvdb::Coord>& leaves, double dx, float iso)
{
    const LeafGather gather(kernels, dx);
    std::vector<std::unique_ptr<FloatLeaf>> results(leaves.size());
    std::vector<std::uint8_t> saturated(leaves.size(), 0);
    std::vector<std::size_t> next(leaves.size(), 0); // where each leaf's sum stopped
    auto sumLeaf = [&](std::size_t L, float stopAbove) {
        float phi[LEAF_VOXELS] = {};                       // float: summed in a fixed order
        if (const FloatLeaf* partial = results[L].get()) { // resume a saturated leaf
            std::copy(partial->buffer().data(), partial->buffer().data() + LEAF_VOXELS, phi);
        }
        saturated[L] = gather.gather(leaves[L], stopAbove, phi, next[L]);
        results[L].reset();
        if (std::none_of(phi, phi + LEAF_VOXELS, [](float v) { return v > 0.0f; })) return;
        auto leaf = std::make_unique<FloatLeaf>(leaves[L], 0.0f, false);
        for (int v = 0; v < LEAF_VOXELS; ++v) leaf->setValueOnly(openvdb::Index(v), phi[v]);
        results[L] = std::move(leaf);
    };
    parallel::forEach(
        0, leaves.size(), [&](std::size_t L) { sumLeaf(L, iso); }, 1);

    // Complete the saturated leaves whose values place the surface (their sums resume).
    std::vector<std::uint8_t> redo(leaves.size(), 0);
    parallel::forEach(
        0, leaves.size(),
        [&](std::size_t L) {
        redo[L] = saturated[L] && touchesOutside(L, leaves, results, saturated, iso);
        },
        16);
    std::vector<std::size_t> again;
    for (std::size_t L = 0; L < leaves.size(); ++L) {
        if (redo[L]) again.push_back(L);
    }
    parallel::forEach(
        0, again.size(), [&](std::size_t n) { sumLeaf(again[n], -1.0f); }, 1);

    auto tree = std::make_shared<openvdb::FloatTree>(0.0f);
    for (auto& leaf : results) { // serial, in leaf order: tree insertion is not thread-safe
        if (leaf) tree->addLeaf(leaf.release());
    }
    return tree;
}

/// Voxels of `phi` with a face neighbour on the other side of `iso` (inside: phi > iso),
/// dilated by `halfWidthVoxels` + 1 in the 26-neighbourhood: every voxel within the band's
/// half width of the iso-surface.
openvdb::MaskTree bandMask(const openvdb::FloatTree& phi, float iso, int halfWidthVoxels)
{
    std::vector<const FloatLeaf*> leaves;
    leaves.reserve(phi.leafCount());
    for (auto it = phi.cbeginLeaf(); it; ++it) leaves.push_back(it.getLeaf());
    std::vector<std::unique_ptr<MaskLeaf>> crossings(leaves.size());
    parallel::forEach(
        0, leaves.size(),
        [&](std::size_t L) {
        const FloatLeaf& leaf = *leaves[L];
        openvdb::tree::ValueAccessor<const openvdb::FloatTree> acc(phi);
        std::unique_ptr<MaskLeaf> mask;
        for (auto it = leaf.cbeginValueAll(); it; ++it) {
            const bool inside = *it > iso;
            const openvdb::Coord ijk = it.getCoord();
            bool crossing = false;
            for (int axis = 0; axis < 3 && !crossing; ++axis) {
                for (int step : {-1, 1}) {
                    openvdb::Coord n = ijk;
                    n[axis] += step;
                    if ((acc.getValue(n) > iso) != inside) {
                        crossing = true;
                        break;
                    }
                }
            }
            if (!crossing) continue;
            if (!mask) mask = std::make_unique<MaskLeaf>(leaf.origin(), false);
            mask->setValueOn(it.pos());
        }
        crossings[L] = std::move(mask);
        },
        4);
    openvdb::MaskTree band(false);
    for (auto& leaf : crossings) {
        if (leaf) band.addLeaf(leaf.release());
    }
    dilateMaxNorm(band, halfWidthVoxels + 1);
    return band;
}

/// Make exactly the voxels of `band` active in `phi`, adding leaves (phi = 0: no kernel reaches
/// them) where the band leaves the candidate leaves. Values are kept.
void activateBand(openvdb::FloatTree& phi, const openvdb::MaskTree& band)
{
    for (auto it = band.cbeginLeaf(); it; ++it) phi.touchLeaf(it->origin());
    std::vector<FloatLeaf*> leaves;
    leaves.reserve(phi.leafCount());
    for (auto it = phi.beginLeaf(); it; ++it) leaves.push_back(it.getLeaf());
    parallel::forEach(
        0, leaves.size(),
        [&](std::size_t L) {
        FloatLeaf& leaf = *leaves[L];
        const MaskLeaf* mask = band.probeConstLeaf(leaf.origin());
        leaf.setValueMask(mask ? mask->getValueMask() : FloatLeaf::NodeMaskType());
        },
        16);
}

/// Narrow-band level set of `phi` = iso (inside: phi > iso), background `background` (m).
openvdb::FloatTree::Ptr isoSurfaceToLevelSet(openvdb::FloatGrid& fog, float iso, float background)
{
    openvdb::FloatGrid::Ptr sdf = openvdb::tools::fogToSdf(fog, iso, /*nIter=*/1);
    openvdb::FloatTree& tree = sdf->tree();
    // Voxels beyond the half width become inactive (their sign kept); then every inactive value
    // and tile becomes +-background.
    openvdb::tree::LeafManager<openvdb::FloatTree> leaves(tree);
    leaves.foreach ([background](FloatLeaf& leaf, std::size_t) {
        for (auto it = leaf.beginValueOn(); it; ++it) {
            if (std::abs(*it) >= background) it.setValueOff();
        }
    });
    openvdb::tools::changeLevelSetBackground(tree, background);
    openvdb::tools::pruneLevelSet(tree);
    return sdf->treePtr();
}

} // namespace

openvdb::FloatGrid::Ptr makeAnisotropicSurfaceGrid(const sph::ParticleSet& particles,
                                                   const std::vector<sph::Index>& selection,
                                                   const VolumeOptions& options)
{
    const double dx = options.voxelSize;
    const double h = options.particleSpacing;
    openvdb::FloatGrid::Ptr grid = makeEmptySurfaceGrid(options);
    grid->insertMeta("surface_method", openvdb::StringMetadata("anisotropic"));
    if (selection.empty()) return grid;

    const Params params{
        options.anisotropicKernelSpacings * h, options.anisotropicNeighborhoodSpacings * h,
        options.anisotropicSmoothing,          options.anisotropicMaxStretch,
        options.anisotropicMinNeighbors,       options.anisotropicScale,
        options.anisotropicIsolatedScale};
    const std::size_t n = selection.size();
    std::vector<sph::Vec3> x(n);
    std::vector<double> volume(n);
    for (std::size_t k = 0; k < n; ++k) {
        x[k] = particles.positions()[selection[k]];
        volume[k] = double(particles.masses()[selection[k]]) / options.restDensity;
    }
    sph::NeighborGrid neighbors{sph::Real(params.neighborhoodRadius)};
    neighbors.build(x);
    const std::vector<Kernel> kernels = makeKernels(neighbors, x, volume, params);
    const std::vector<openvdb::Coord> leaves = candidateLeaves(kernels, neighbors, dx);

    const float iso = float(options.anisotropicIsoValue);
    openvdb::FloatGrid::Ptr fog = openvdb::FloatGrid::create(gatherField(kernels, leaves, dx, iso));
    fog->setTransform(grid->transform().copy());
    activateBand(fog->tree(), bandMask(fog->tree(), iso, options.surfaceHalfWidthVoxels));
    if (fog->tree().activeVoxelCount() == 0) return grid; // phi never reaches the iso-value
    grid->setTree(isoSurfaceToLevelSet(*fog, iso, grid->background()));
    return grid;
}

} // namespace detail
} // namespace vdbio
} // namespace ghostfx
