/// @file   DomainDecomposition.h
/// @brief  Space cut into parts balanced by particle count, for one simulation spread over
///         several processes (MPI ranks): which part owns a point, and which other parts need
///         it in their halo (the copies of neighbours within a support radius of their region).
/// @details Two schemes, both a binary tree of axis-aligned cuts:
///          - slabs: every cut along the longest axis of the particles' bounding box. A part's
///            halo is its two faces times the support radius, so the halo per part stays the
///            same as parts are added while the particles per part shrink: slabs stop paying
///            once a slab is a few support radii thick;
///          - bisection (recursive coordinate bisection): each subset is cut along the longest
///            axis of its own particles, so parts tend to cubes and a part's halo shrinks with
///            its volume^(2/3).
///          Each cut splits its particles in proportion to the parts on either side (the
///          parts' counts then differ by at most one particle, ties aside). Regions are
///          unbounded on their outer sides, so every point of space has an owner; a part may
///          hold no particle (more parts than particles, or all of them moved away).
///          No I/O and no MPI here: a distributed run builds the same tree from the particles
///          its ranks gather (or from a histogram), and the halo measurement in bench/ uses it
///          on one process.
#pragma once

#include "ghostfx/sph/Types.h"

#include <cstdint>
#include <vector>

namespace ghostfx {
namespace sph {

enum class DecompositionScheme { Slabs, Bisection };

class DomainDecomposition
{
public:
    /// Parts whose counts differ by more than this factor (largest over mean) should be
    /// rebalanced: at 1.1 the slowest rank idles the others for at most a tenth of a step.
    static constexpr double REBALANCE_IMBALANCE = 1.1;

    /// One part, owning everything.
    DomainDecomposition();

    /// `parts` (>= 1) parts balanced by the count of `points`.
    static DomainDecomposition balanced(const std::vector<Vec3>& points, int parts,
                                        DecompositionScheme scheme);

    int parts() const { return int(mRegions.size()); }

    /// The tree of cuts as numbers (five per node), for a checkpoint; load() rebuilds it.
    std::vector<double> save() const;
    /// The decomposition save() described; a ValueError when the numbers are not one (or not
    /// one of `parts` parts).
    static DomainDecomposition load(const std::vector<double>& numbers, int parts);

    /// The part whose region holds x (points on a cut belong to the upper side).
    int owner(const Vec3& x) const;

    /// Region of a part: a box, unbounded (+-max Real) on the sides no cut closes.
    const Aabb& region(int part) const { return mRegions.at(std::size_t(part)); }

    /// Call fn(part) for every part other than owner(x) whose region lies closer than `width`
    /// to x: the parts that need x in their halo.
    template <typename Fn>
    void forEachHaloPart(const Vec3& x, Real width, Fn&& fn) const
    {
        if (mNodes.empty()) return;
        const int own = owner(x);
        visitNear(0, x, width, own, fn);
    }

    /// Squared distance from x to a part's region (0 inside).
    Real distance2(const Vec3& x, int part) const;

    /// Largest count over the mean count (1: perfectly balanced; 1 for no particles at all).
    static double imbalance(const std::vector<std::size_t>& counts);

private:
    struct Node
    {
        int axis = 0;
        Real cut = 0;
        int lower = -1, upper = -1; ///< child nodes (an inner node)
        int part = -1;              ///< the part (a leaf)
    };

    int build(std::vector<Vec3>& points, std::size_t lo, std::size_t hi, const Aabb& region,
              int parts, int firstPart, DecompositionScheme scheme, int slabAxis);

    template <typename Fn>
    void visitNear(int node, const Vec3& x, Real width, int own, Fn& fn) const
    {
        const Node& n = mNodes[std::size_t(node)];
        if (n.part >= 0) {
            if (n.part != own && distance2(x, n.part) < width * width) fn(n.part);
            return;
        }
        if (x[n.axis] - width < n.cut) visitNear(n.lower, x, width, own, fn);
        if (x[n.axis] + width >= n.cut) visitNear(n.upper, x, width, own, fn);
    }

    std::vector<Node> mNodes; ///< node 0 is the root
    std::vector<Aabb> mRegions;
};

} // namespace sph
} // namespace ghostfx
