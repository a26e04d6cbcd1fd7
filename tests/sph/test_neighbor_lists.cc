/// @file   test_neighbor_lists.cc
/// @brief  The pieces of the one-search-per-step liquid step: NeighborLists against brute force
///         (sorted and unsorted targets, masks, radii, outliers), its determinism and its two
///         search paths; PairBatch sums against plain double sums; BoundaryBlock's order; the
///         ParticleSet operations the solid blocks use; LevelSet::pushOutside at box edges.
/// @details Brute force uses the lists' own arithmetic (x_i - x_j and its squared length below
///          R^2, in Real), so the neighbour sets must be equal exactly.
#include <ghostfx/sph/BoundaryBlock.h>
#include <ghostfx/sph/Exceptions.h>
#include <ghostfx/sph/Kernels.h>
#include <ghostfx/sph/LevelSetGrid.h>
#include <ghostfx/sph/NeighborGrid.h>
#include <ghostfx/sph/NeighborLists.h>
#include <ghostfx/sph/PairBatch.h>
#include <ghostfx/sph/Parallel.h>
#include <ghostfx/sph/ParticleSet.h>

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <random>
#include <vector>

namespace {

using namespace ghostfx::sph;
using ghostfx::ValueError;
namespace parallel = ghostfx::parallel;

std::vector<Vec3> randomPoints(std::size_t n, Real extent, unsigned seed)
{
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> u(0.0, double(extent));
    std::vector<Vec3> xs(n);
    for (auto& x : xs) x = Vec3(Real(u(rng)), Real(u(rng)), Real(u(rng)));
    return xs;
}

std::vector<Index> bruteForce(const Vec3& x, const std::vector<Vec3>& targets, Real radius)
{
    std::vector<Index> out;
    const Real r2 = radius * radius;
    for (std::size_t j = 0; j < targets.size(); ++j) {
        const Real dx = x[0] - targets[j][0], dy = x[1] - targets[j][1], dz = x[2] - targets[j][2];
        if (dx * dx + dy * dy + dz * dz < r2) out.push_back(Index(j));
    }
    return out;
}

std::vector<Index> sorted(NeighborLists::List list)
{
    std::vector<Index> v(list.begin(), list.end());
    std::sort(v.begin(), v.end());
    return v;
}

/// Lists of `queries` against a grid over `targets` equal brute force, for every query.
void expectListsMatchBruteForce(const std::vector<Vec3>& targets, const std::vector<Vec3>& queries,
                                Real cellSize, Real radius, const std::vector<std::uint8_t>& wanted)
{
    NeighborGrid grid(cellSize);
    grid.build(targets);
    NeighborLists lists;
    lists.build(grid, queries.data(), queries.size(), radius,
                wanted.empty() ? nullptr : wanted.data());
    ASSERT_EQ(lists.size(), queries.size());
    std::size_t pairs = 0;
    for (std::size_t q = 0; q < queries.size(); ++q) {
        const bool want = wanted.empty() || wanted[q];
        const std::vector<Index> expected =
            want ? bruteForce(queries[q], targets, radius) : std::vector<Index>{};
        ASSERT_EQ(sorted(lists[q]), expected) << "query " << q;
        pairs += expected.size();
    }
    EXPECT_EQ(lists.pairCount(), pairs);
    // What the storage must hold at least: a byte per pair (4 in a list of 32-bit indices).
    EXPECT_GE(lists.memoryBytes(), pairs);
}

} // namespace

TEST(NeighborLists, MatchBruteForceForUnsortedTargetsMasksAndSmallerRadii)
{
    const Real cell = Real(0.05);
    const std::vector<Vec3> targets = randomPoints(4000, Real(0.4), 1);
    std::vector<Vec3> queries = randomPoints(1500, Real(0.4), 2);
    queries.push_back(Vec3(Real(50), 0, 0)); // far from every target: an empty list
    std::vector<std::uint8_t> every2nd(queries.size());
    for (std::size_t q = 0; q < every2nd.size(); ++q) every2nd[q] = q % 2;
    for (Real radius : {cell, Real(0.7) * cell}) {
        SCOPED_TRACE(::testing::Message() << "radius " << radius);
        expectListsMatchBruteForce(targets, queries, cell, radius, {});
        expectListsMatchBruteForce(targets, queries, cell, radius, every2nd);
    }
}

TEST(NeighborLists, PairSupportsMatchBruteForceOnBothSearchPaths)
{
    // Particles with their own support radius (the gas's grown particles): particle q lists
    // particle t within their pair support (h_q + h_t) / 2. The lists may hold pairs up to 1e-4
    // of it beyond (their margin for float rounding, NeighborLists::build) and no others.
    const Real cell = Real(0.05);
    const std::vector<Vec3> x = randomPoints(4000, Real(0.4), 3);
    std::vector<Real> h(x.size());
    for (std::size_t q = 0; q < h.size(); ++q) {
        h[q] = cell * Real(0.1 + 0.9 * double(q % 13) / 12.0); // 0.1 to 1 cell
    }
    NeighborGrid grid(cell);
    grid.build(x); // unsorted: the lists map slots to particles
    std::size_t pairs = 0, wider = 0;
    for (bool wide : {false, true}) {
        SCOPED_TRACE(::testing::Message() << "AVX2 path " << wide);
        const bool before = NeighborLists::wideSimd();
        NeighborLists::setWideSimd(wide);
        NeighborLists lists;
        lists.build(grid, x.data(), x.size(), cell, nullptr, h.data());
        NeighborLists::setWideSimd(before);
        for (std::size_t q = 0; q < x.size(); ++q) {
            const std::vector<Index> listed = sorted(lists[q]);
            std::vector<Index> inside, margin;
            for (std::size_t t = 0; t < x.size(); ++t) {
                const Real R = Real(0.5) * (h[q] + h[t]);
                const Real r = (x[q] - x[t]).length();
                if (r < R) inside.push_back(Index(t));
                if (r < R * Real(1.0001)) margin.push_back(Index(t));
            }
            ASSERT_TRUE(std::includes(listed.begin(), listed.end(), inside.begin(), inside.end()))
                << "query " << q << " misses a pair within its pair support";
            ASSERT_TRUE(std::includes(margin.begin(), margin.end(), listed.begin(), listed.end()))
                << "query " << q << " lists a pair beyond its pair support";
            pairs += inside.size();
            wider += listed.size() - inside.size();
        }
    }
    std::printf("[measured] %zu pairs within their supports, %zu listed within the margin\n",
                pairs, wider);
}

TEST(NeighborLists, SortedSetAgainstItselfHoldsEachParticleAndIsTheSameOnBothSearchPaths)
{
    // As the solver uses them: a set sorted by the grid, queried with its own positions.
    ParticleSet set;
    set.addBatch(randomPoints(6000, Real(0.3), 3), Real(1), ParticleKind::Liquid);
    NeighborGrid grid(Real(0.03));
    grid.sortParticles(set);
    ASSERT_TRUE(grid.identityOrder());
    const auto& x = set.positions();
    const bool wide = NeighborLists::wideSimd();
    NeighborLists a, b;
    a.build(grid, x.data(), x.size(), Real(0.03));
    NeighborLists::setWideSimd(false);
    b.build(grid, x.data(), x.size(), Real(0.03));
    NeighborLists::setWideSimd(true);
    std::printf("[measured] %zu pairs, wide SIMD path %s\n", a.pairCount(),
                wide ? "available" : "absent");
    for (std::size_t i = 0; i < x.size(); ++i) {
        ASSERT_EQ(std::vector<Index>(a[i].begin(), a[i].end()),
                  std::vector<Index>(b[i].begin(), b[i].end()))
            << "particle " << i;
        ASSERT_TRUE(std::find(a[i].begin(), a[i].end(), Index(i)) != a[i].end())
            << "particle " << i;
        ASSERT_EQ(sorted(a[i]), bruteForce(x[i], x, Real(0.03))) << "particle " << i;
    }
}

TEST(NeighborLists, ListsOfASortedLiquidTakeUnderOneAndAHalfBytesPerNeighbour)
{
    // A liquid block as the solver sees it: a jittered lattice at spacing h, sorted by a grid
    // of cells 3 h wide, lists of radius 3 h ([SB12]'s support): about 100 neighbours each.
    const Real h = Real(0.01);
    std::vector<Vec3> xs;
    std::mt19937 rng(4);
    std::uniform_real_distribution<float> jitter(-0.1f, 0.1f);
    for (int i = 0; i < 48; ++i)
        for (int j = 0; j < 48; ++j)
            for (int k = 0; k < 48; ++k)
                xs.emplace_back(h * (Real(i) + jitter(rng)), h * (Real(j) + jitter(rng)),
                                h * (Real(k) + jitter(rng)));
    ParticleSet set;
    set.addBatch(xs, Real(1), ParticleKind::Liquid);
    NeighborGrid grid(Real(3) * h);
    grid.sortParticles(set);
    NeighborLists lists;
    lists.build(grid, set.positions().data(), set.size(), Real(3) * h);
    const double pairs = double(lists.pairCount());
    const double runsPerPair = double(lists.runCount()) / pairs;
    // Held (capacity) against the 4 bytes per neighbour of one 32-bit index each.
    const double bytesPerPair = double(lists.memoryBytes()) / pairs;
    std::printf("[measured] %.1f neighbours per query in %.2f runs, %.3f bytes per neighbour "
                "held\n",
                pairs / double(set.size()), runsPerPair * pairs / double(set.size()), bytesPerPair);
    EXPECT_GT(pairs / double(set.size()), 80.0);
    // A query's neighbours lie in the cells of its 3 x 3 x 3 block, each a range of the Morton
    // order; a window of 256 indices holds about nine cells of 27 particles, so the runs are
    // far fewer than the cells (measured: 9.0 per list of 100.7, 0.090 per neighbour).
    EXPECT_LT(runsPerPair, 0.1);
    EXPECT_EQ(lists.rawListCount(), 0u); // 110k targets: every list's windows within 16 bits
    // 1 byte per neighbour, 3 per run, 2 per list for its run count and 8 per query for its
    // end (0.10 per neighbour), a chunk fitted to its lists (within 1/64 and 128 bytes per 256
    // queries: 0.02): 1 + 3 x 0.1 + 0.1 + 0.02 = 1.42 at most (measured 1.37; 2.13 with 16-bit
    // offsets from one or two bases, 4.4 with 32-bit indices).
    EXPECT_LT(bytesPerPair, 1.42);
    // Every list reads back to the brute-force neighbours, through every reader: every 101st
    // list, and lists against the same targets unsorted (which are kept as 32-bit indices).
    PairBatch batch;
    auto check = [&](const NeighborLists::List& list, const std::vector<Vec3>& xt, std::size_t i) {
        const std::vector<Index> expected = bruteForce(xt[i], xt, Real(3) * h);
        ASSERT_EQ(sorted(list), expected) << "particle " << i;
        std::vector<Index> viaForEach, viaBatches;
        list.forEach([&](Index j) { viaForEach.push_back(j); });
        batch.forEachBatch(xt[i], xt.data(), list, [&](PairBatch& b) {
            viaBatches.insert(viaBatches.end(), b.j, b.j + b.n);
            for (int k = 0; k < b.n; ++k) ASSERT_EQ(b.dx[k], xt[i][0] - xt[b.j[k]][0]);
        });
        ASSERT_EQ(viaForEach, std::vector<Index>(list.begin(), list.end())) << "particle " << i;
        ASSERT_EQ(viaBatches, viaForEach) << "particle " << i;
        ASSERT_EQ(list.size(), viaForEach.size());
    };
    std::size_t checkedLong = 0, checkedRaw = 0;
    for (std::size_t i = 0; i < set.size(); i += 101) {
        checkedLong += lists[i].size() > std::size_t(PairBatch::SIZE);
        check(lists[i], set.positions(), i);
    }
    std::vector<Vec3> shuffled = set.positions();
    std::shuffle(shuffled.begin(), shuffled.end(), rng);
    NeighborGrid unsorted(Real(3) * h);
    unsorted.build(shuffled);
    NeighborLists rawLists;
    rawLists.build(unsorted, shuffled.data(), shuffled.size(), Real(3) * h);
    for (std::size_t i = 0; i < shuffled.size(); i += 1009) {
        checkedRaw += rawLists[i].raw() != nullptr;
        check(rawLists[i], shuffled, i);
    }
    std::printf("[measured] lists checked against brute force: %zu longer than a batch, %zu of "
                "32-bit indices\n",
                checkedLong, checkedRaw);
    EXPECT_GT(checkedLong, 0u); // every kind was read
    EXPECT_GT(checkedRaw, 0u);
}

TEST(NeighborLists, IdenticalForOneThreadAndAllThreads)
{
    const std::vector<Vec3> xs = randomPoints(20000, Real(0.5), 4);
    NeighborGrid grid(Real(0.04));
    grid.build(xs);
    NeighborLists all, one;
    all.build(grid, xs.data(), xs.size(), Real(0.04));
    parallel::setSerial(true);
    one.build(grid, xs.data(), xs.size(), Real(0.04));
    parallel::setSerial(false);
    for (std::size_t i = 0; i < xs.size(); ++i) {
        ASSERT_EQ(std::vector<Index>(all[i].begin(), all[i].end()),
                  std::vector<Index>(one[i].begin(), one[i].end()))
            << "query " << i;
    }
}

TEST(NeighborLists, NoTargetsGiveEmptyListsAndHoldNothingPerQuery)
{
    // A solid block without particles: the solver still asks for the lists of every liquid
    // particle, and they must cost nothing.
    NeighborGrid grid(Real(0.03));
    grid.build(std::vector<Vec3>{});
    const std::vector<Vec3> queries = randomPoints(5000, Real(0.3), 8);
    NeighborLists lists;
    lists.build(grid, queries.data(), queries.size(), Real(0.03));
    ASSERT_EQ(lists.size(), queries.size());
    for (std::size_t q = 0; q < queries.size(); q += 499) EXPECT_TRUE(lists[q].empty());
    EXPECT_EQ(lists.pairCount(), 0u);
    EXPECT_LT(lists.memoryBytes(), 1024u);
    // And a later build with targets fills them again.
    NeighborGrid full(Real(0.03));
    full.build(queries);
    lists.build(full, queries.data(), queries.size(), Real(0.03));
    EXPECT_EQ(sorted(lists[7]), bruteForce(queries[7], queries, Real(0.03)));
}

TEST(NeighborLists, ChunksWhoseListsAreAllEmptyHoldNothing)
{
    // Lists from liquid into a solid: most liquid particles are far from it. A chunk of queries
    // without a single neighbour holds neither entries nor ends, so lists with ten such chunks
    // before one chunk of near queries take exactly the memory of that chunk alone.
    const Real cell = Real(0.04);
    const std::vector<Vec3> targets = randomPoints(3000, Real(0.3), 11);
    NeighborGrid grid(cell);
    grid.build(targets);
    const std::vector<Vec3> near = randomPoints(NeighborLists::CHUNK, Real(0.3), 12);
    std::vector<Vec3> farThenNear(10 * NeighborLists::CHUNK, Vec3(Real(5), Real(5), Real(5)));
    for (std::size_t q = 0; q < farThenNear.size(); ++q) farThenNear[q][0] += Real(q) * cell;
    const std::vector<Vec3> far = farThenNear;
    farThenNear.insert(farThenNear.end(), near.begin(), near.end());

    NeighborLists alone, after;
    alone.build(grid, near.data(), near.size(), cell);
    after.build(grid, farThenNear.data(), farThenNear.size(), cell);
    ASSERT_GT(alone.pairCount(), 0u);
    EXPECT_EQ(after.memoryBytes(), alone.memoryBytes());
    for (std::size_t q = 0; q < farThenNear.size(); ++q) {
        ASSERT_EQ(sorted(after[q]), bruteForce(farThenNear[q], targets, cell)) << "query " << q;
    }
    // Rebuilt with the far queries only, every chunk gives its memory back; rebuilt with
    // fewer queries than before, the lists are those of the new queries.
    after.build(grid, far.data(), far.size(), cell);
    EXPECT_EQ(after.memoryBytes(), 0u);
    EXPECT_EQ(after.pairCount(), 0u);
    after.build(grid, near.data(), 100, cell);
    ASSERT_EQ(after.size(), 100u);
    for (std::size_t q = 0; q < 100; ++q) {
        ASSERT_EQ(sorted(after[q]), bruteForce(near[q], targets, cell)) << "query " << q;
    }
}

TEST(NeighborLists, BuildForATagEqualsBuildWithTheMaskOfThatTag)
{
    // A solver picks the liquid of a liquid-and-air set by its kind channel: the lists must be
    // those of a 0/1 mask of the same queries.
    const Real cell = Real(0.05);
    const std::vector<Vec3> targets = randomPoints(3000, Real(0.4), 13);
    const std::vector<Vec3> queries = randomPoints(2000, Real(0.4), 14);
    std::vector<std::uint8_t> tags(queries.size()), mask(queries.size());
    for (std::size_t q = 0; q < tags.size(); ++q) {
        tags[q] = std::uint8_t(q % 3); // kinds 0, 1, 2
        mask[q] = tags[q] == 1;
    }
    NeighborGrid grid(cell);
    grid.build(targets);
    NeighborLists byTag, byMask;
    byTag.buildFor(grid, queries.data(), queries.size(), cell, tags.data(), 1);
    byMask.build(grid, queries.data(), queries.size(), cell, mask.data());
    ASSERT_GT(byMask.pairCount(), 0u);
    EXPECT_EQ(byTag.pairCount(), byMask.pairCount());
    for (std::size_t q = 0; q < queries.size(); ++q) {
        ASSERT_EQ(std::vector<Index>(byTag[q].begin(), byTag[q].end()),
                  std::vector<Index>(byMask[q].begin(), byMask[q].end()))
            << "query " << q;
        if (tags[q] != 1) {
            ASSERT_TRUE(byTag[q].empty()) << "query " << q;
        }
    }
}

TEST(NeighborLists, RadiusBeyondTheCellSizeIsRefused)
{
    NeighborGrid grid(Real(0.1));
    grid.build(randomPoints(10, Real(1), 5));
    const Vec3 q(0);
    NeighborLists lists;
    EXPECT_THROW(lists.build(grid, &q, 1, Real(0.2)), ValueError);
    EXPECT_THROW(lists.build(grid, &q, 1, Real(0)), ValueError);
}

TEST(PairBatch, SumsEqualPlainSumsOverLongLists)
{
    // 150 neighbours: three batches, one of them partial.
    const std::vector<Vec3> xs = randomPoints(150, Real(0.1), 6);
    std::vector<Index> list(xs.size());
    for (std::size_t k = 0; k < list.size(); ++k) list[k] = Index(k);
    std::vector<Vec3> values(xs.size());
    for (std::size_t k = 0; k < values.size(); ++k)
        values[k] = Vec3(Real(k), Real(0.5) * Real(k), -Real(k));
    const Vec3 xi(Real(0.05)), vi(1, 2, 3);
    const CubicSplineKernel kernel(Real(0.2));
    double w = 0;
    Vec3d offsets(0), differences(0);
    for (Index j : list) {
        const Vec3 xij = xi - xs[j];
        const double f = double(kernel.W(xij.length()));
        w += f;
        offsets += f * Vec3d(xij);
        differences += f * (Vec3d(values[j]) - Vec3d(vi));
    }
    PairBatch batch;
    double bw = 0;
    Vec3d bOffsets(0), bDifferences(0);
    int batches = 0;
    batch.forEachBatch(xi, xs.data(), list, [&](PairBatch& b) {
        ++batches;
        for (int k = 0; k < b.n; ++k) b.f[k] = kernel.W(b.r[k]);
        bw += b.sum(b.f);
        bOffsets += Vec3d(b.sumScaledOffsets(b.f));
        bDifferences += Vec3d(b.sumScaledDifferences(b.f, values.data(), vi));
    });
    EXPECT_EQ(batches, 3);
    // Float sums of 150 terms in another order: about 1e-6 relative.
    EXPECT_NEAR(bw, w, 1e-5 * w);
    EXPECT_NEAR((bOffsets - offsets).length(), 0.0, 1e-5 * offsets.length() + 1e-9);
    EXPECT_NEAR((bDifferences - differences).length(), 0.0, 1e-5 * differences.length());
}

TEST(PairBatch, SumsAddInLaneOrderBitForBitAtEveryBatchSize)
{
    // PairBatch's sums are defined by their order: term k goes to partial sum k mod LANES, and
    // the partial sums are added in lane order from zero (the SIMD versions under AVX2 must
    // give the scalar loops' results bit for bit, or runs would change with the build). Each
    // sum is checked against that order written out here, at every batch size from 1 to SIZE
    // (full lane groups and every partial last group), with gathered values.
    std::mt19937 rng(17);
    std::uniform_real_distribution<float> u(-1, 1);
    constexpr int L = PairBatch::LANES;
    std::vector<Vec3> values(300);
    for (Vec3& v : values) v = Vec3(Real(u(rng)), Real(u(rng)), Real(u(rng)));
    const Vec3 vi(Real(0.3), Real(-0.2), Real(0.7));
    PairBatch b;
    Real x[PairBatch::SIZE], y[PairBatch::SIZE], z[PairBatch::SIZE];
    for (int n = 1; n <= PairBatch::SIZE; ++n) {
        b.n = n;
        for (int k = 0; k < n; ++k) {
            b.j[k] = Index(std::uniform_int_distribution<int>(0, 299)(rng));
            b.f[k] = Real(u(rng));
            b.dx[k] = Real(u(rng));
            b.dy[k] = Real(u(rng));
            b.dz[k] = Real(u(rng));
            x[k] = Real(u(rng));
            y[k] = Real(u(rng));
            z[k] = Real(u(rng));
        }
        // term(k) into lane k mod L, then the lanes from zero in order.
        auto ordered = [&](auto term) {
            Real lane[L] = {};
            for (int k = 0; k < n; ++k) lane[k % L] += term(k);
            Real total = 0;
            for (int l = 0; l < L; ++l) total += lane[l];
            return total;
        };
        auto gathered = [&](int k) { return values[b.j[k]]; };
        EXPECT_EQ(b.sum(b.f), ordered([&](int k) { return b.f[k]; })) << n;
        const Vec3 scaled = b.sumScaled(b.f, x, y, z);
        EXPECT_EQ(scaled[0], ordered([&](int k) { return b.f[k] * x[k]; })) << n;
        EXPECT_EQ(scaled[1], ordered([&](int k) { return b.f[k] * y[k]; })) << n;
        EXPECT_EQ(scaled[2], ordered([&](int k) { return b.f[k] * z[k]; })) << n;
        const Vec3 differences = b.sumScaledDifferences(b.f, values.data(), vi);
        for (int c = 0; c < 3; ++c) {
            EXPECT_EQ(differences[c], ordered(
                                          [&](int k) {
                return b.f[k] * (gathered(k)[c] - vi[c]);
            })) << n;
        }
        EXPECT_EQ(b.sumApproach(values.data(), vi, x, y, z), ordered(
                                                                 [&](int k) {
            const Vec3 v = gathered(k);
            return (vi[0] - v[0]) * x[k] + (vi[1] - v[1]) * y[k] + (vi[2] - v[2]) * z[k];
        })) << n;
        EXPECT_EQ(b.sumScaledApproach(b.f, values.data(), vi), ordered(
                                                                   [&](int k) {
            const Vec3 v = gathered(k);
            return b.f[k]
                   * ((vi[0] - v[0]) * b.dx[k] + (vi[1] - v[1]) * b.dy[k]
                      + (vi[2] - v[2]) * b.dz[k]);
        })) << n;
    }
}

TEST(PairBatch, ListsLongerThanItsBufferGiveTheSameBatches)
{
    // A dense sorted block and a radius that reaches about 3,000 neighbours: lists past
    // PairBatch::CAPACITY are decoded batch by batch, shorter ones at once; both must give the
    // neighbours of forEach in the same batches of SIZE.
    std::vector<Vec3> xs;
    for (int i = 0; i < 24; ++i)
        for (int j = 0; j < 24; ++j)
            for (int k = 0; k < 24; ++k) xs.emplace_back(Real(i), Real(j), Real(k));
    ParticleSet set;
    set.addBatch(xs, Real(1), ParticleKind::Liquid);
    NeighborGrid grid(Real(9));
    grid.sortParticles(set);
    NeighborLists lists;
    lists.build(grid, set.positions().data(), set.size(), Real(9));
    PairBatch batch;
    std::size_t longLists = 0, shortLists = 0;
    for (std::size_t i = 0; i < set.size(); i += 37) {
        const NeighborLists::List list = lists[i];
        ASSERT_EQ(list.raw(), nullptr);
        longLists += list.size() > std::size_t(PairBatch::CAPACITY);
        shortLists += list.size() <= std::size_t(PairBatch::CAPACITY);
        std::vector<Index> viaForEach, viaBatches;
        list.forEach([&](Index j) { viaForEach.push_back(j); });
        std::size_t batches = 0;
        batch.forEachBatch(set.positions()[i], set.positions().data(), list, [&](PairBatch& b) {
            ++batches;
            ASSERT_TRUE(b.n == PairBatch::SIZE || viaBatches.size() + b.n == viaForEach.size());
            viaBatches.insert(viaBatches.end(), b.j, b.j + b.n);
            for (int k = 0; k < b.n; ++k) {
                ASSERT_EQ(b.r[k], (set.positions()[i] - set.positions()[b.j[k]]).length());
            }
        });
        ASSERT_EQ(viaBatches, viaForEach) << "particle " << i;
        EXPECT_EQ(batches, (viaForEach.size() + PairBatch::SIZE - 1) / PairBatch::SIZE);
    }
    EXPECT_GT(longLists, 0u);
    EXPECT_GT(shortLists, 0u);
}

TEST(BoundaryBlock, OrderDependsOnIdsAndCellsNotOnInsertionOrder)
{
    const std::vector<Vec3> xs = randomPoints(3000, Real(0.2), 7);
    BoundaryBlock a(Real(0.02)), b(Real(0.02));
    a.particles().addBatch(xs, Real(1), ParticleKind::GhostSolid);
    b.particles().addBatch(xs, Real(1), ParticleKind::GhostSolid);
    // b holds the same particles (same ids) in reverse order.
    std::vector<Index> reverse(xs.size());
    for (std::size_t k = 0; k < reverse.size(); ++k) reverse[k] = Index(xs.size() - 1 - k);
    b.particles().reorder(reverse);
    a.rebuild();
    b.rebuild();
    EXPECT_FALSE(a.stale());
    EXPECT_EQ(a.particles().ids(), b.particles().ids());
    EXPECT_TRUE(a.particles().positions() == b.particles().positions());
    EXPECT_TRUE(a.grid().identityOrder());
    a.touch();
    EXPECT_TRUE(a.stale());
}

TEST(ParticleSet, AppendSelectAndRemoveChannelKeepIdsAndDefaults)
{
    ParticleSet liquid, solid;
    liquid.addVectorChannel("vstar");
    liquid.addBatch({Vec3(0), Vec3(1)}, Real(1), ParticleKind::Liquid);
    solid.setNextId(10);
    solid.addScalarChannel("solid_index", Real(-1));
    solid.addBatch({Vec3(2)}, Real(1), ParticleKind::GhostSolid);
    ParticleSet all = liquid;
    all.append(solid);
    ASSERT_EQ(all.size(), 3u);
    EXPECT_EQ(all.ids(), (std::vector<ParticleId>{0, 1, 10}));
    EXPECT_EQ(all.nextId(), 11);
    EXPECT_EQ(all.scalarChannel("solid_index"), (std::vector<Real>{-1, -1, -1}));
    EXPECT_EQ(all.vectorChannel("vstar").size(), 3u);
    const ParticleSet back = all.select({0, 0, 1});
    EXPECT_EQ(back.ids(), (std::vector<ParticleId>{10}));
    EXPECT_EQ(back.kinds()[0], ParticleKind::GhostSolid);
    EXPECT_EQ(back.nextId(), 11);
    all.removeChannel("vstar");
    EXPECT_FALSE(all.hasVectorChannel("vstar"));
    EXPECT_THROW(all.select({1}), ValueError);
}

TEST(LevelSet, PushOutsideLeavesEdgesAndCornersOfABox)
{
    // Where Newton projection with the trilinear gradient oscillates (at the box's edges and
    // corners the gradient jumps between cells), pushOutside still ends just outside.
    const Real h = Real(0.01);
    const LevelSet box = makeLevelSet(
        makeBoxLevelSet(Vec3(-0.08f, -0.1f, -0.08f), Vec3(0.08f, -0.04f, 0.08f), h / 2), "box");
    const Vec3 points[] = {Vec3(-0.0793571f, -0.0408085f, -0.0113048f), // an edge (seen in a run)
                           Vec3(0.0797f, -0.0403f, 0.0796f),            // a corner
                           Vec3(0, -0.0405f, 0)};                       // a face
    for (const Vec3& x : points) {
        ASSERT_LT(box.phi(x), Real(0));
        const SurfaceProjection out = box.pushOutside(x);
        EXPECT_TRUE(out.converged) << x;
        EXPECT_GE(box.phi(out.point), Real(0)) << x;
        // It moves about as far as the point was inside, not more than a voxel.
        EXPECT_LT((out.point - x).length(), h / 2) << x;
    }
    // Beyond the band there is no direction to the surface.
    EXPECT_FALSE(box.pushOutside(Vec3(0, -0.08f, 0)).converged);
}
