/// @file   LevelSetFlow.cc
/// @brief  NarrowBandFlow: OpenVDB's level-set filter arithmetic on padded leaf blocks.
/// @details Every pass is a Jacobi update: new values of a leaf's active voxels are computed
///          from the old values of the leaf and its rim (a 10^3 block), written to a side
///          buffer, and copied back once every leaf is done, as OpenVDB's LeafManager
///          buffer swap does. Inactive voxels keep their values (+-background in a level set),
///          and a neighbour leaf that does not exist reads as its tile's value, which is one
///          value for the whole 8^3 block. The expressions below keep OpenVDB 10's types and
///          order of operations (math::CurvatureStencil::meanCurvatureNormGrad, computed in
///          double from float differences; LevelSetTracker's Normalizer::eval with
///          ISGradientNormSqrd<FIRST_BIAS>, in float), so the results are equal bit for bit.
#include <ghostfx/vdbio/LevelSetFlow.h>
#include <ghostfx/vdbio/MaskDilation.h>

#include <openvdb/tools/Prune.h>
#include <openvdb/tree/LeafManager.h>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

namespace ghostfx {
namespace vdbio {

namespace {

using Tree = openvdb::FloatTree;
using Leaf = Tree::LeafNodeType;
using LeafManager = openvdb::tree::LeafManager<Tree>;

constexpr int DIM = int(Leaf::DIM);     // 8
constexpr int PAD = DIM + 2;            // 10: the leaf and a one-voxel rim
constexpr int SX = PAD * PAD, SY = PAD; // strides of x and y in the padded block (z: 1)
constexpr int PADDED_SIZE = PAD * PAD * PAD;

/// Index in the padded block of the leaf-local voxel (x, y, z), each in [-1, DIM].
constexpr int padded(int x, int y, int z) { return (x + 1) * SX + (y + 1) * SY + (z + 1); }

/// Fills `block` with the values of `leaf` and of the one-voxel rim around it (faces, edges
/// and corners, read from the 26 neighbouring leaves or their tiles).
void gatherPadded(const openvdb::tree::ValueAccessor<const Tree>& acc, const Leaf& leaf,
                  float* block)
{
    const openvdb::Coord origin = leaf.origin();
    for (int a = -1; a <= 1; ++a) {
        for (int b = -1; b <= 1; ++b) {
            for (int c = -1; c <= 1; ++c) {
                // Leaf-local range on each axis: the whole leaf, or its far face.
                const int x0 = a < 0 ? DIM - 1 : 0, x1 = a > 0 ? 0 : DIM - 1;
                const int y0 = b < 0 ? DIM - 1 : 0, y1 = b > 0 ? 0 : DIM - 1;
                const int z0 = c < 0 ? DIM - 1 : 0, z1 = c > 0 ? 0 : DIM - 1;
                const openvdb::Coord o = origin.offsetBy(a * DIM, b * DIM, c * DIM);
                const Leaf* source = (a | b | c) == 0 ? &leaf : acc.probeConstLeaf(o);
                if (source) {
                    const float* values = source->buffer().data();
                    for (int x = x0; x <= x1; ++x) {
                        for (int y = y0; y <= y1; ++y) {
                            for (int z = z0; z <= z1; ++z) {
                                block[padded(x + a * DIM, y + b * DIM, z + c * DIM)] =
                                    values[(x << 6) | (y << 3) | z];
                            }
                        }
                    }
                } else {
                    const float tile = acc.getValue(o);
                    for (int x = x0; x <= x1; ++x) {
                        for (int y = y0; y <= y1; ++y) {
                            for (int z = z0; z <= z1; ++z) {
                                block[padded(x + a * DIM, y + b * DIM, z + c * DIM)] = tile;
                            }
                        }
                    }
                }
            }
        }
    }
}

/// Calls fn(v) for each active voxel v of `leaf`, in order (the mask's words, lowest bit first).
template <typename Fn>
inline void forEachActive(const Leaf& leaf, Fn&& fn)
{
    const openvdb::util::NodeMask<3>& mask = leaf.getValueMask();
    for (int n = 0; n < DIM; ++n) {
        for (std::uint64_t w = mask.getWord<std::uint64_t>(n); w != 0; w &= w - 1) {
            fn((n << 6) | __builtin_ctzll(w));
        }
    }
}

/// One Jacobi pass: every active voxel v of every leaf gets op(block, padded index of v).
/// `scratch` holds the new values until every leaf has read its neighbours' old ones. The
/// ops are branch-free and a row of eight voxels along z is contiguous in the block (and so
/// are its neighbour rows), so each row with an active voxel is computed whole, eight lanes
/// at a time; only the active voxels' values are written back.
template <typename StencilOp>
void stencilPass(Tree& tree, const StencilOp& op, std::vector<float>& scratch)
{
    LeafManager leaves(tree);
    const std::size_t count = leaves.leafCount();
    if (scratch.size() < count * Leaf::SIZE) scratch.resize(count * Leaf::SIZE);
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, count, 4),
                      [&](const tbb::blocked_range<std::size_t>& range) {
        openvdb::tree::ValueAccessor<const Tree> acc(tree);
        float block[PADDED_SIZE];
        for (std::size_t n = range.begin(); n != range.end(); ++n) {
            const Leaf& leaf = leaves.leaf(n);
            gatherPadded(acc, leaf, block);
            float* out = &scratch[n * Leaf::SIZE];
            const openvdb::util::NodeMask<3>& mask = leaf.getValueMask();
            for (int x = 0; x < DIM; ++x) {
                const std::uint64_t word = mask.getWord<std::uint64_t>(x);
                for (int y = 0; y < DIM; ++y) {
                    if (((word >> (8 * y)) & 0xFFu) == 0) continue; // no active voxel
                    const int base = padded(x, y, 0);
                    float* row = out + (x << 6) + (y << 3);
                    for (int z = 0; z < DIM; ++z) row[z] = op(block, base + z);
                }
            }
        }
    });
    leaves.foreach ([&scratch](Leaf& leaf, std::size_t n) {
        const float* in = &scratch[n * Leaf::SIZE];
        float* values = leaf.buffer().data();
        forEachActive(leaf, [&](int v) { values[v] = in[v]; });
    });
}

/// phi + dt kappa |grad phi| (math::CurvatureStencil::meanCurvatureNormGrad, dt = dx^2 / 3).
struct CurvatureStep
{
    float dt;     // dx^2 / 3
    float invDx2; // 1 / dx^2, rounded as OpenVDB rounds it

    float operator()(const float* p, int i) const
    {
        const float v0 = p[i];
        const float xm = p[i - SX], xp = p[i + SX], ym = p[i - SY], yp = p[i + SY];
        const float zm = p[i - 1], zp = p[i + 1];
        const double Dx = 0.5 * (xp - xm), Dy = 0.5 * (yp - ym), Dz = 0.5 * (zp - zm);
        const double Dx2 = Dx * Dx, Dy2 = Dy * Dy, Dz2 = Dz * Dz, normGrad2 = Dx2 + Dy2 + Dz2;
        const double Dxx = xp - 2 * v0 + xm, Dyy = yp - 2 * v0 + ym, Dzz = zp - 2 * v0 + zm;
        const double Dxy =
            0.25 * (p[i + SX + SY] - p[i + SX - SY] + p[i - SX - SY] - p[i - SX + SY]);
        const double Dxz = 0.25 * (p[i + SX + 1] - p[i + SX - 1] + p[i - SX - 1] - p[i - SX + 1]);
        const double Dyz = 0.25 * (p[i + SY + 1] - p[i + SY - 1] + p[i - SY - 1] - p[i - SY + 1]);
        const double alpha = Dx2 * (Dyy + Dzz) + Dy2 * (Dxx + Dzz) + Dz2 * (Dxx + Dyy)
                             - 2 * (Dx * (Dy * Dxy + Dz * Dxz) + Dy * Dz * Dyz);
        const double normGrad = std::sqrt(normGrad2);
        // No flow where the gradient vanishes (selected, not branched, so rows vectorise).
        const bool flat = normGrad2 <= openvdb::math::Tolerance<double>::value();
        const float speed = flat ? 0.0f : float(alpha * invDx2 / (2 * (normGrad * normGrad)));
        return v0 + dt * speed;
    }
};

/// One Euler step of phi_t = S(phi) (1 - |grad phi|), Godunov's first-order upwind norm
/// (LevelSetTracker's Normalizer::eval with ISGradientNormSqrd<FIRST_BIAS>, dt = 0.3 dx).
struct RenormaliseStep
{
    float dt;    // 0.3 dx
    float invDx; // 1 / dx

    float operator()(const float* p, int i) const
    {
        const float c = p[i];
        // One-sided differences in index space: down = c - phi[-1], up = phi[+1] - c.
        const float xm = c - p[i - SX], xp = p[i + SX] - c;
        const float ym = c - p[i - SY], yp = p[i + SY] - c;
        const float zm = c - p[i - 1], zp = p[i + 1] - c;
        const float zero = 0.0f;
        auto sq = [](float s) { return s * s; };
        // Both sides' upwind norms, then a select (no branch, so rows vectorise).
        float outside = std::max(sq(std::max(xm, zero)), sq(std::min(xp, zero)));
        outside += std::max(sq(std::max(ym, zero)), sq(std::min(yp, zero)));
        outside += std::max(sq(std::max(zm, zero)), sq(std::min(zp, zero)));
        float inside = std::max(sq(std::min(xm, zero)), sq(std::max(xp, zero)));
        inside += std::max(sq(std::min(ym, zero)), sq(std::max(yp, zero)));
        inside += std::max(sq(std::min(zm, zero)), sq(std::max(zp, zero)));
        const float norm2 = c > 0 ? outside : inside;
        float s = c / (std::sqrt(sq(c) + norm2) + openvdb::math::Tolerance<float>::value());
        return c - dt * s * (std::sqrt(norm2) * invDx - 1.0f);
    }
};

} // namespace

NarrowBandFlow::NarrowBandFlow(openvdb::FloatGrid& grid, int sweeps)
    : mGrid(grid)
    , mDx(float(grid.voxelSize()[0]))
    , mSweeps(sweeps)
{
    if (!grid.hasUniformVoxels()) {
        OPENVDB_THROW(openvdb::ValueError,
                      "NarrowBandFlow: grid '" + grid.getName() + "' has non-uniform voxels");
    }
    if (grid.getGridClass() != openvdb::GRID_LEVEL_SET) {
        OPENVDB_THROW(openvdb::ValueError,
                      "NarrowBandFlow: grid '" + grid.getName() + "' is of class '"
                          + openvdb::GridBase::gridClassToString(grid.getGridClass())
                          + "', expected a level set");
    }
    if (sweeps < 1) {
        OPENVDB_THROW(openvdb::ValueError, "NarrowBandFlow: sweeps = " + std::to_string(sweeps)
                                               + ", expected at least 1");
    }
}

void NarrowBandFlow::meanCurvature()
{
    const double inv2Dx = float(0.5 / mDx); // OpenVDB's CurvatureStencil rounds 1 / (2 dx)
    const CurvatureStep step{mDx * mDx / 3.0f, float(4.0 * inv2Dx * inv2Dx)};
    stencilPass(mGrid.tree(), step, mScratch);
    track();
}

void NarrowBandFlow::offset(float distance)
{
    const float cfl = 0.5f * mDx, total = std::abs(distance);
    float done = 0.0f;
    while (total - done > 0.001f * cfl) {
        const float delta = std::min(total - done, cfl);
        done += delta;
        const float shift = std::copysign(delta, distance);
        LeafManager leaves(mGrid.tree());
        leaves.foreach ([shift](Leaf& leaf, std::size_t) {
            float* values = leaf.buffer().data();
            forEachActive(leaf, [&](int v) { values[v] += shift; });
        });
        track();
    }
}

void NarrowBandFlow::renormalise()
{
    const RenormaliseStep step{mDx * 0.3f, 1.0f / mDx};
    for (int n = 0; n < mSweeps; ++n) stencilPass(mGrid.tree(), step, mScratch);
}

void NarrowBandFlow::track()
{
    Tree& tree = mGrid.tree();
    // Grow the band by its face neighbours (LevelSetTracker::track's NN_FACE dilation): new
    // voxels keep their inactive values, and leaves added over a tile take the tile's value.
    dilateFaces(tree);
    renormalise();
    // Voxels that left the band become inactive at +-background, as LevelSetTracker trims.
    const float gamma = mGrid.background();
    LeafManager leaves(tree);
    leaves.foreach ([gamma](Leaf& leaf, std::size_t) {
        const float* values = leaf.buffer().data();
        // forEachActive walks a copy of each mask word, so turning voxels off is safe.
        forEachActive(leaf, [&](int v) {
            const float value = values[v];
            if (value <= -gamma) {
                leaf.setValueOff(openvdb::Index(v), -gamma);
            } else if (value >= gamma) {
                leaf.setValueOff(openvdb::Index(v), gamma);
            }
        });
    });
    openvdb::tools::pruneLevelSet(tree);
}

} // namespace vdbio
} // namespace ghostfx
