/// @file   DomainDecomposition.cc
/// @brief  Balanced slab and recursive-bisection trees of cuts (see the header).
#include "ghostfx/sph/DomainDecomposition.h"

#include "ghostfx/sph/Exceptions.h"

#include <algorithm>
#include <limits>

namespace ghostfx {
namespace sph {

namespace {

Aabb everywhere()
{
    Aabb b;
    b.min = Vec3(-std::numeric_limits<Real>::max());
    b.max = Vec3(std::numeric_limits<Real>::max());
    return b;
}

int longestAxis(const Vec3& extent)
{
    int axis = 0;
    for (int a = 1; a < 3; ++a) {
        if (extent[a] > extent[axis]) axis = a;
    }
    return axis;
}

} // namespace

DomainDecomposition::DomainDecomposition()
{
    mNodes.push_back(Node{0, 0, -1, -1, 0});
    mRegions.push_back(everywhere());
}

DomainDecomposition DomainDecomposition::balanced(const std::vector<Vec3>& points, int parts,
                                                  DecompositionScheme scheme)
{
    if (parts < 1) throw ValueError(msg("domain decomposition: ", parts, " parts: expected >= 1"));
    DomainDecomposition d;
    d.mNodes.clear();
    d.mRegions.assign(std::size_t(parts), Aabb());
    Aabb box;
    for (const Vec3& x : points) box.expand(x);
    std::vector<Vec3> work(points);
    d.build(work, 0, work.size(), everywhere(), parts, 0, scheme, longestAxis(box.extent()));
    return d;
}

int DomainDecomposition::build(std::vector<Vec3>& points, std::size_t lo, std::size_t hi,
                               const Aabb& region, int parts, int firstPart,
                               DecompositionScheme scheme, int slabAxis)
{
    const int index = int(mNodes.size());
    mNodes.emplace_back();
    if (parts == 1) {
        mNodes[std::size_t(index)].part = firstPart;
        mRegions[std::size_t(firstPart)] = region;
        return index;
    }
    // The axis: the slabs' one, or the longest of this subset's own particles.
    Aabb box;
    for (std::size_t k = lo; k < hi; ++k) box.expand(points[k]);
    const int axis = scheme == DecompositionScheme::Slabs ? slabAxis : longestAxis(box.extent());

    // The lower side takes parts / 2 parts and that share of the particles (k < hi, since
    // parts / 2 < parts). The cut lies
    // midway between the two sides' nearest particles; with no particle (an empty subset) it
    // halves what the region bounds of the particles' extent.
    const int lowerParts = parts / 2;
    const std::size_t n = hi - lo;
    const std::size_t k = lo + n * std::size_t(lowerParts) / std::size_t(parts);
    auto less = [axis](const Vec3& a, const Vec3& b) { return a[axis] < b[axis]; };
    Real cut = 0;
    if (n == 0) {
        const Real a = region.min[axis], b = region.max[axis];
        const bool bounded =
            a > -std::numeric_limits<Real>::max() && b < std::numeric_limits<Real>::max();
        cut = bounded                                 ? Real(0.5) * (a + b)
              : a > -std::numeric_limits<Real>::max() ? a + Real(1)
              : b < std::numeric_limits<Real>::max()  ? b - Real(1)
                                                      : Real(0);
    } else {
        std::nth_element(points.begin() + std::ptrdiff_t(lo), points.begin() + std::ptrdiff_t(k),
                         points.begin() + std::ptrdiff_t(hi), less);
        const Real upper = points[k][axis];
        if (k == lo) {
            cut = upper;
        } else {
            const Real lower = std::max_element(points.begin() + std::ptrdiff_t(lo),
                                                points.begin() + std::ptrdiff_t(k), less)
                                   ->
                                   operator[](axis);
            // Midway, but never above the upper side's first particle (which owns the cut).
            cut = std::min(upper, lower + Real(0.5) * (upper - lower));
        }
    }
    Aabb lowerRegion = region, upperRegion = region;
    lowerRegion.max[axis] = cut;
    upperRegion.min[axis] = cut;
    mNodes[std::size_t(index)].axis = axis;
    mNodes[std::size_t(index)].cut = cut;
    const int lower = build(points, lo, k, lowerRegion, lowerParts, firstPart, scheme, slabAxis);
    const int upper = build(points, k, hi, upperRegion, parts - lowerParts, firstPart + lowerParts,
                            scheme, slabAxis);
    mNodes[std::size_t(index)].lower = lower;
    mNodes[std::size_t(index)].upper = upper;
    return index;
}

std::vector<double> DomainDecomposition::save() const
{
    std::vector<double> out;
    for (const Node& n : mNodes) {
        out.insert(out.end(), {double(n.axis), double(n.cut), double(n.lower), double(n.upper),
                               double(n.part)});
    }
    return out;
}

DomainDecomposition DomainDecomposition::load(const std::vector<double>& numbers, int parts)
{
    auto bad = [&](const std::string& why) {
        return ValueError(msg("domain decomposition of ", parts, " parts: ", why));
    };
    if (numbers.empty() || numbers.size() % 5 != 0) throw bad("expected five numbers per node");
    DomainDecomposition d;
    d.mNodes.clear();
    const int nodes = int(numbers.size() / 5);
    for (int k = 0; k < nodes; ++k) {
        const double* v = &numbers[std::size_t(5 * k)];
        Node n;
        n.axis = int(v[0]);
        n.cut = Real(v[1]);
        n.lower = int(v[2]);
        n.upper = int(v[3]);
        n.part = int(v[4]);
        const bool leaf = n.part >= 0;
        if (n.axis < 0 || n.axis > 2 || n.part >= parts
            || (!leaf && (n.lower <= k || n.upper <= k || n.lower >= nodes || n.upper >= nodes)))
            throw bad(msg("node ", k, " is not a valid node"));
        d.mNodes.push_back(n);
    }
    // Regions, from the root down.
    d.mRegions.assign(std::size_t(parts), Aabb());
    std::vector<bool> seen(std::size_t(parts), false);
    std::vector<std::pair<int, Aabb>> stack = {{0, everywhere()}};
    while (!stack.empty()) {
        const auto [k, region] = stack.back();
        stack.pop_back();
        const Node& n = d.mNodes[std::size_t(k)];
        if (n.part >= 0) {
            if (seen[std::size_t(n.part)]) throw bad(msg("part ", n.part, " appears twice"));
            seen[std::size_t(n.part)] = true;
            d.mRegions[std::size_t(n.part)] = region;
            continue;
        }
        Aabb lower = region, upper = region;
        lower.max[n.axis] = n.cut;
        upper.min[n.axis] = n.cut;
        stack.push_back({n.lower, lower});
        stack.push_back({n.upper, upper});
    }
    if (std::count(seen.begin(), seen.end(), false) != 0) throw bad("a part has no region");
    return d;
}

int DomainDecomposition::owner(const Vec3& x) const
{
    int node = 0;
    for (;;) {
        const Node& n = mNodes[std::size_t(node)];
        if (n.part >= 0) return n.part;
        node = x[n.axis] < n.cut ? n.lower : n.upper;
    }
}

Real DomainDecomposition::distance2(const Vec3& x, int part) const
{
    const Aabb& b = region(part);
    Real d2 = 0;
    for (int a = 0; a < 3; ++a) {
        const Real d = x[a] < b.min[a] ? b.min[a] - x[a] : x[a] > b.max[a] ? x[a] - b.max[a] : 0;
        d2 += d * d;
    }
    return d2;
}

double DomainDecomposition::imbalance(const std::vector<std::size_t>& counts)
{
    if (counts.empty()) return 1;
    std::size_t total = 0, largest = 0;
    for (std::size_t c : counts) {
        total += c;
        largest = std::max(largest, c);
    }
    return total == 0 ? 1.0 : double(largest) * double(counts.size()) / double(total);
}

} // namespace sph
} // namespace ghostfx
