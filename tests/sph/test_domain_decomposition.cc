/// @file   test_domain_decomposition.cc
/// @brief  DomainDecomposition: balanced counts, slabs along the longest axis, compact bisection
///         parts, owners against regions, halo parts against brute force, empty and tiny inputs.
/// @details Points are drawn with Rng (uniform floats: ties have probability ~0), so a balanced
///          cut must give counts that differ by at most one.
#include <ghostfx/sph/DomainDecomposition.h>
#include <ghostfx/sph/Exceptions.h>
#include <ghostfx/sph/Random.h>

#include <gtest/gtest.h>

#include <algorithm>
#include <limits>
#include <set>
#include <vector>

namespace {

using namespace ghostfx::sph;

std::vector<Vec3> boxPoints(std::size_t n, const Vec3& extent, std::uint64_t seed)
{
    Rng rng(seed);
    std::vector<Vec3> x(n);
    for (Vec3& p : x) {
        p = Vec3(rng.uniform(0, extent[0]), rng.uniform(0, extent[1]), rng.uniform(0, extent[2]));
    }
    return x;
}

std::vector<std::size_t> counts(const DomainDecomposition& d, const std::vector<Vec3>& x)
{
    std::vector<std::size_t> c(std::size_t(d.parts()), 0);
    for (const Vec3& p : x) ++c[std::size_t(d.owner(p))];
    return c;
}

constexpr Real BIG = std::numeric_limits<Real>::max();

} // namespace

TEST(DomainDecomposition, SlabsCutTheLongestAxisIntoEqualCounts)
{
    const std::vector<Vec3> x = boxPoints(10000, Vec3(1, 4, 1), 1); // longest: y
    for (int parts : {1, 2, 3, 5, 7, 16}) {
        const DomainDecomposition d =
            DomainDecomposition::balanced(x, parts, DecompositionScheme::Slabs);
        ASSERT_EQ(d.parts(), parts);
        const std::vector<std::size_t> c = counts(d, x);
        const auto [lo, hi] = std::minmax_element(c.begin(), c.end());
        EXPECT_LE(*hi - *lo, 1u) << parts << " parts";
        EXPECT_LE(DomainDecomposition::imbalance(c), 1.0 + double(parts) / 10000.0);
        for (int p = 0; p < parts; ++p) {
            // A slab is bounded along y only, and the slabs follow one another along it.
            const Aabb& r = d.region(p);
            EXPECT_EQ(r.min[0], -BIG);
            EXPECT_EQ(r.max[2], BIG);
            EXPECT_EQ(r.min[1] == -BIG, p == 0);
            EXPECT_EQ(r.max[1] == BIG, p == parts - 1);
            if (p > 0) {
                EXPECT_EQ(r.min[1], d.region(p - 1).max[1]);
            }
        }
        // Every point lies in its owner's region.
        for (std::size_t k = 0; k < x.size(); k += 97) {
            const Aabb& r = d.region(d.owner(x[k]));
            EXPECT_TRUE(x[k][1] >= r.min[1] && x[k][1] < r.max[1]);
        }
    }
}

TEST(DomainDecomposition, BisectionPartsAreCompactAndNeedLessHaloThanSlabs)
{
    // A cube of particles in 8 parts: bisection cuts each axis once (octants); slabs make eight
    // slices an eighth thick. The halo width is a tenth of the side.
    const std::vector<Vec3> x = boxPoints(40000, Vec3(1, 1, 1), 2);
    const Real width = Real(0.1);
    std::size_t halo[2] = {0, 0};
    for (DecompositionScheme scheme :
         {DecompositionScheme::Slabs, DecompositionScheme::Bisection}) {
        const DomainDecomposition d = DomainDecomposition::balanced(x, 8, scheme);
        const std::vector<std::size_t> c = counts(d, x);
        const auto [lo, hi] = std::minmax_element(c.begin(), c.end());
        EXPECT_LE(*hi - *lo, 1u);
        std::size_t h = 0;
        for (const Vec3& p : x) d.forEachHaloPart(p, width, [&](int) { ++h; });
        halo[scheme == DecompositionScheme::Bisection] = h;
        if (scheme == DecompositionScheme::Bisection) {
            for (int p = 0; p < 8; ++p) {
                // Each octant's region is bounded by one cut per axis, near the middle.
                const Aabb& r = d.region(p);
                for (int a = 0; a < 3; ++a) {
                    const Real cut = r.min[a] == -BIG ? r.max[a] : r.min[a];
                    EXPECT_NEAR(cut, 0.5, 0.02) << "part " << p << " axis " << a;
                }
            }
        }
    }
    // Slabs: 7 inner cuts x 2 sides x 0.1 = 1.4 cube volumes of halo = 56,000 particles.
    // Octants: the points within w of an octant of side s = 0.5 and outside it, inside the
    // cube: 3 face slabs s^2 w, 3 edge quarter-cylinders s pi w^2 / 4, a corner eighth of a
    // ball pi w^3 / 6, in all 0.0873 per octant, 0.698 cube volumes = 27,930 particles.
    // To 3 % (the Poisson noise of 40k uniform points is under 1 %).
    EXPECT_NEAR(double(halo[0]), 56000, 0.03 * 56000);
    EXPECT_NEAR(double(halo[1]), 27930, 0.03 * 27930);
    EXPECT_LT(halo[1], halo[0] / 2);
}

TEST(DomainDecomposition, HaloPartsAreThoseWithinTheWidthExactly)
{
    const std::vector<Vec3> x = boxPoints(3000, Vec3(2, 1, 1), 3);
    const std::vector<Vec3> probes = boxPoints(2000, Vec3(2.2f, 1.2f, 1.2f), 4);
    for (DecompositionScheme scheme :
         {DecompositionScheme::Slabs, DecompositionScheme::Bisection}) {
        for (int parts : {2, 6, 13}) {
            const DomainDecomposition d = DomainDecomposition::balanced(x, parts, scheme);
            for (Real width : {Real(0.05), Real(0.3)}) {
                for (const Vec3& q : probes) {
                    const Vec3 p = q - Vec3(Real(0.1));
                    std::set<int> found, expected;
                    d.forEachHaloPart(p, width, [&](int part) {
                        EXPECT_TRUE(found.insert(part).second) << "part " << part << " twice";
                    });
                    const int own = d.owner(p);
                    EXPECT_EQ(d.distance2(p, own), 0);
                    for (int k = 0; k < parts; ++k) {
                        if (k != own && d.distance2(p, k) < width * width) expected.insert(k);
                    }
                    EXPECT_EQ(found, expected);
                }
            }
        }
    }
}

TEST(DomainDecomposition, EmptyAndTinyInputsStillCoverSpace)
{
    // No particles at all: every point still has exactly one owner among the parts.
    const DomainDecomposition none =
        DomainDecomposition::balanced({}, 4, DecompositionScheme::Bisection);
    EXPECT_EQ(none.parts(), 4);
    for (const Vec3& p : boxPoints(200, Vec3(10, 10, 10), 5)) {
        const int own = none.owner(p - Vec3(5));
        EXPECT_GE(own, 0);
        EXPECT_LT(own, 4);
        EXPECT_EQ(none.distance2(p - Vec3(5), own), 0);
    }
    // Three particles in eight parts: five parts own nothing, none owns more than one.
    const std::vector<Vec3> three = {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(2, 0, 0)};
    const DomainDecomposition d =
        DomainDecomposition::balanced(three, 8, DecompositionScheme::Slabs);
    const std::vector<std::size_t> c = counts(d, three);
    EXPECT_EQ(std::count(c.begin(), c.end(), 0u), 5);
    EXPECT_EQ(*std::max_element(c.begin(), c.end()), 1u);
    EXPECT_DOUBLE_EQ(DomainDecomposition::imbalance(c), 8.0 / 3.0);

    EXPECT_DOUBLE_EQ(DomainDecomposition::imbalance({10, 10, 10, 10}), 1.0);
    EXPECT_DOUBLE_EQ(DomainDecomposition::imbalance({20, 10, 10, 0}), 2.0);
    EXPECT_DOUBLE_EQ(DomainDecomposition::imbalance({0, 0}), 1.0);
    EXPECT_THROW(DomainDecomposition::balanced(three, 0, DecompositionScheme::Slabs),
                 ghostfx::ValueError);
}

TEST(DomainDecomposition, SavedAndLoadedItOwnsAsBefore)
{
    const std::vector<Vec3> x = boxPoints(5000, Vec3(2, 1, 1), 6);
    for (DecompositionScheme scheme :
         {DecompositionScheme::Slabs, DecompositionScheme::Bisection}) {
        const DomainDecomposition d = DomainDecomposition::balanced(x, 7, scheme);
        const DomainDecomposition e = DomainDecomposition::load(d.save(), 7);
        ASSERT_EQ(e.parts(), 7);
        for (const Vec3& p : boxPoints(2000, Vec3(3, 2, 2), 7)) {
            const Vec3 q = p - Vec3(Real(0.5));
            EXPECT_EQ(e.owner(q), d.owner(q));
        }
        for (int k = 0; k < 7; ++k) {
            EXPECT_EQ(e.region(k).min, d.region(k).min);
            EXPECT_EQ(e.region(k).max, d.region(k).max);
        }
        EXPECT_THROW(DomainDecomposition::load(d.save(), 6), ghostfx::ValueError);
        std::vector<double> broken = d.save();
        broken[2] = 0; // the root's lower child is the root itself
        EXPECT_THROW(DomainDecomposition::load(broken, 7), ghostfx::ValueError);
        EXPECT_THROW(DomainDecomposition::load({1, 2, 3}, 7), ghostfx::ValueError);
    }
}
