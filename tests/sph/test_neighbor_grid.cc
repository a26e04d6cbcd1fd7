/// @file   test_neighbor_grid.cc
/// @brief  NeighborGrid against brute force: uniform, clustered and far-outlier particle sets,
///         radius and nearest-particle queries, sorting the particle set, memory, determinism
///         and error reporting.
/// @details Brute force uses the grid's own arithmetic, xij = x_i - x_j and
///          xij.lengthSqr() < R^2 in Real, so the neighbour sets must be equal exactly (points
///          are random, so a pair at exactly r = R has probability zero).
#include <ghostfx/sph/Exceptions.h>
#include <ghostfx/sph/NeighborGrid.h>
#include <ghostfx/sph/Parallel.h>
#include <ghostfx/sph/ParticleSet.h>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <map>
#include <random>
#include <set>
#include <vector>

namespace {

using namespace ghostfx::sph;
using ::testing::HasSubstr;

using NeighborLists = std::vector<std::vector<Index>>;

// Particle sets ------------------------------------------------------------------------------

std::vector<Vec3> uniformPoints(std::size_t n, const Vec3& lo, const Vec3& hi, unsigned seed)
{
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    std::vector<Vec3> xs(n);
    for (auto& x : xs) {
        for (int a = 0; a < 3; ++a) x[a] = Real(lo[a] + (hi[a] - lo[a]) * u(rng));
    }
    return xs;
}

/// `clusters` Gaussian blobs of `perCluster` points, standard deviation `sigma` (m), centres
/// uniform in [-1, 1]^3 m.
std::vector<Vec3> clusteredPoints(int clusters, std::size_t perCluster, double sigma, unsigned seed)
{
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    std::normal_distribution<double> g(0.0, sigma);
    std::vector<Vec3> xs;
    for (int c = 0; c < clusters; ++c) {
        const Vec3d centre(u(rng), u(rng), u(rng));
        for (std::size_t k = 0; k < perCluster; ++k) {
            xs.push_back(toVec3(centre + Vec3d(g(rng), g(rng), g(rng))));
        }
    }
    return xs;
}

// Brute force ---------------------------------------------------------------------------------

/// Indices j with |x - x_j| < radius, compared as the grid does: (x - x_j).lengthSqr() < radius^2.
std::vector<Index> bruteInRadius(const std::vector<Vec3>& xs, const Vec3& x, Real radius)
{
    const Real radius2 = radius * radius;
    std::vector<Index> found;
    for (std::size_t j = 0; j < xs.size(); ++j) {
        const Vec3 xij = x - xs[j];
        if (xij.lengthSqr() < radius2) found.push_back(Index(j));
    }
    return found;
}

/// Nearest j with pred(j) and |x - x_j| < maxRadius, or INVALID_INDEX.
template <typename Pred>
Index bruteNearest(const std::vector<Vec3>& xs, const Vec3& x, Real maxRadius, Pred pred,
                   Real* distance)
{
    Index best = INVALID_INDEX;
    Real best2 = maxRadius * maxRadius;
    for (std::size_t j = 0; j < xs.size(); ++j) {
        const Real r2 = (x - xs[j]).lengthSqr();
        if (r2 < best2 && pred(Index(j))) {
            best2 = r2;
            best = Index(j);
        }
    }
    *distance = best == INVALID_INDEX ? Real(-1) : std::sqrt(best2);
    return best;
}

/// Neighbour lists of every particle from the grid, sorted; also checks the (j, xij, rij)
/// arguments the callback receives.
NeighborLists gridNeighbors(const NeighborGrid& grid, const std::vector<Vec3>& xs)
{
    NeighborLists lists(xs.size());
    std::size_t badArgs = 0;
    for (std::size_t i = 0; i < xs.size(); ++i) {
        grid.forEachNeighbor(Index(i), [&](Index j, const Vec3& xij, Real rij) {
            lists[i].push_back(j);
            if (j >= xs.size() || xij != xs[i] - xs[j] || rij != std::sqrt(xij.lengthSqr())) {
                ++badArgs;
            }
        });
        std::sort(lists[i].begin(), lists[i].end());
    }
    EXPECT_EQ(badArgs, 0u) << "callbacks received an xij or rij other than x_i - x_j, |x_i - x_j|";
    return lists;
}

/// Every particle's neighbour list equals brute force with radius cellSize; returns the mean
/// list length so callers can check the test was not trivially sparse.
double expectNeighborsMatchBruteForce(const NeighborGrid& grid, const std::vector<Vec3>& xs)
{
    const NeighborLists lists = gridNeighbors(grid, xs);
    std::size_t mismatches = 0, total = 0;
    for (std::size_t i = 0; i < xs.size(); ++i) {
        const std::vector<Index> expected = bruteInRadius(xs, xs[i], grid.cellSize());
        total += expected.size();
        if (lists[i] != expected && ++mismatches <= 3) {
            ADD_FAILURE() << "particle " << i << " at " << xs[i] << ": grid found "
                          << lists[i].size() << " neighbours, brute force " << expected.size();
        }
    }
    EXPECT_EQ(mismatches, 0u);
    return double(total) / double(xs.size());
}

// ---------------------------------------------------------------------------------------------

TEST(NeighborGrid, UniformPointsMatchBruteForce)
{
    // Box straddling the origin, so negative cell coordinates (floor, not truncation) are used.
    const std::vector<Vec3> xs = uniformPoints(4000, Vec3(-0.2f), Vec3(0.2f), 1);
    NeighborGrid grid(Real(0.05));
    grid.build(xs);
    EXPECT_EQ(grid.size(), xs.size());
    const double mean = expectNeighborsMatchBruteForce(grid, xs);
    // 4000 / 0.064 m^3 x 4/3 pi 0.05^3 m^3 = 33 expected neighbours (including self).
    EXPECT_GT(mean, 20.0);
    EXPECT_LT(mean, 40.0);
    // 512 occupied cells of about 8 particles: the lookup merges 8 sort buckets (a 2 x 2 x 2
    // block of cells) and still finds every neighbour above.
    EXPECT_EQ(grid.bucketCount(), 8192u);
    EXPECT_EQ(grid.lookupBucketCount(), 1024u);
}

TEST(NeighborGrid, ClusteredPointsMatchBruteForce)
{
    // Five dense blobs (sigma = 0.8 cell): up to about 90 particles per cell, and a third of
    // all particles within 1 sigma of a centre.
    const std::vector<Vec3> xs = clusteredPoints(5, 800, 0.025, 2);
    NeighborGrid grid(Real(0.03));
    grid.build(xs);
    const double mean = expectNeighborsMatchBruteForce(grid, xs);
    EXPECT_GT(mean, 50.0); // dense enough to exercise long cells
}

TEST(NeighborGrid, FarOutliersMatchBruteForceAndKeepMemoryProportionalToN)
{
    const Real cellSize = Real(0.05);
    const std::size_t n = 3000;
    std::vector<Vec3> compact = uniformPoints(n, Vec3(0), Vec3(0.4f), 3);
    NeighborGrid compactGrid(cellSize);
    compactGrid.build(compact);
    for (Real distance : {Real(1000), Real(10000)}) {
        SCOPED_TRACE(testing::Message() << "outliers at " << distance << " m");
        std::vector<Vec3> xs = compact;
        // A lone particle, and a close pair (neighbours of each other only), far away.
        xs.push_back(Vec3(distance, Real(0.1), Real(-0.2)));
        xs.push_back(Vec3(Real(-3), distance, Real(2)));
        xs.push_back(Vec3(Real(-3), distance, Real(2.02)));
        NeighborGrid grid(cellSize);
        grid.build(xs);
        expectNeighborsMatchBruteForce(grid, xs);
        const NeighborLists lists = gridNeighbors(grid, xs);
        EXPECT_EQ(lists[n], std::vector<Index>{Index(n)});
        EXPECT_EQ(lists[n + 1], (std::vector<Index>{Index(n + 1), Index(n + 2)}));

        // Hash table: smallest power of two >= 2N (at least 64).
        const std::size_t buckets = grid.bucketCount();
        EXPECT_EQ(buckets & (buckets - 1), 0u) << buckets << " is not a power of two";
        EXPECT_GE(buckets, 2 * xs.size());
        EXPECT_LT(buckets, 4 * xs.size());
        // O(N) memory: the arrays hold 4 bytes per bucket (<= 16 per particle) and 28 (float) or
        // 40 (double) bytes per particle, so < 60 bytes per particle. A dense box reaching the
        // outlier would need 10^10 cells or more.
        EXPECT_LT(grid.memoryBytes(), 200 * xs.size() + 4096);
        // Three outliers cost what three particles anywhere cost, plus at most one step of the
        // lookup table: their three cells may halve its merging (the compact box has 512 cells,
        // just at the limit of two lookup buckets per cell), 4 bytes per added bucket.
        ASSERT_GE(grid.lookupBucketCount(), compactGrid.lookupBucketCount());
        const std::size_t lookupStep =
            4 * (grid.lookupBucketCount() - compactGrid.lookupBucketCount());
        EXPECT_LE(grid.lookupBucketCount(), 2 * compactGrid.lookupBucketCount());
        EXPECT_LE(grid.memoryBytes(), compactGrid.memoryBytes() + 3 * 60 + lookupStep);
    }
}

TEST(NeighborGrid, BucketCountForSmallAndEmptySets)
{
    NeighborGrid grid(Real(1));
    grid.build(std::vector<Vec3>{});
    EXPECT_EQ(grid.size(), 0u);
    EXPECT_EQ(grid.bucketCount(), 64u);
    int calls = 0;
    grid.forEachInRadius(Vec3(0), Real(10), [&](Index, const Vec3&, Real) { ++calls; });
    EXPECT_EQ(calls, 0);
    Real distance = 0;
    EXPECT_EQ(grid.nearest(
                  Vec3(0), Real(5), [](Index) { return true; }, &distance),
              INVALID_INDEX);
    EXPECT_LT(distance, Real(0));
    grid.build(uniformPoints(33, Vec3(0), Vec3(1), 4));
    EXPECT_EQ(grid.bucketCount(), 128u); // smallest power of two >= 66
    // All 33 in one cell: the lookup merges eight sort buckets (the most it merges).
    EXPECT_EQ(grid.lookupBucketCount(), 16u);
}

TEST(NeighborGrid, RebuildWithFewerParticlesForgetsTheOldOnes)
{
    NeighborGrid grid(Real(0.1));
    grid.build(uniformPoints(3000, Vec3(0), Vec3(1), 5));
    const std::vector<Vec3> xs = uniformPoints(200, Vec3(0), Vec3(0.3f), 6);
    grid.build(xs);
    EXPECT_EQ(grid.size(), 200u);
    expectNeighborsMatchBruteForce(grid, xs);
}

TEST(NeighborGrid, ForEachInRadiusMatchesBruteForceForSmallAndLargeRadii)
{
    const Real cellSize = Real(0.05);
    const std::vector<Vec3> xs = uniformPoints(3000, Vec3(-0.2f), Vec3(0.2f), 7);
    NeighborGrid grid(cellSize);
    grid.build(xs);
    // Query points are not particles, and some lie outside the cloud.
    const std::vector<Vec3> queries = uniformPoints(300, Vec3(-0.3f), Vec3(0.3f), 8);
    for (Real radius :
         {Real(0.3) * cellSize, cellSize, Real(1.7) * cellSize, Real(2.5) * cellSize}) {
        std::size_t mismatches = 0, found = 0;
        for (const Vec3& x : queries) {
            std::vector<Index> got;
            bool argsOk = true;
            grid.forEachInRadius(x, radius, [&](Index j, const Vec3& xij, Real rij) {
                got.push_back(j);
                argsOk = argsOk && xij == x - xs[j] && rij == std::sqrt(xij.lengthSqr());
            });
            EXPECT_TRUE(argsOk);
            std::sort(got.begin(), got.end());
            const std::vector<Index> expected = bruteInRadius(xs, x, radius);
            found += expected.size();
            if (got != expected && ++mismatches <= 3) {
                ADD_FAILURE() << "radius " << radius << " at " << x << ": grid " << got.size()
                              << ", brute force " << expected.size();
            }
        }
        EXPECT_EQ(mismatches, 0u) << "radius " << radius;
        EXPECT_GT(found, 20u) << "radius " << radius << ": too sparse to test";
    }
}

// A box query visits exactly the particles inside the box, whether it walks the box's cells
// (a small box) or sweeps the whole set (a box with more cells than the set occupies); with a
// cell filter it visits the particles of the wanted cells only, in the order of the unfiltered
// query (the air resampling's obstacles rely on this: GhostAir.cc).
TEST(NeighborGrid, ForEachInBoxVisitsTheBoxAndAFilterKeepsItsCellsInOrder)
{
    const Real cellSize = Real(0.05);
    const std::vector<Vec3> xs = uniformPoints(4000, Vec3(-0.2f), Vec3(0.2f), 11);
    NeighborGrid grid(cellSize);
    grid.build(xs);
    auto wanted = [](const NeighborGrid::Cell& c) { return ((c.i + 2 * c.j + 3 * c.k) & 3) == 0; };
    const Aabb boxes[2] = {Aabb{Vec3(-0.12f, -0.1f, -0.05f), Vec3(0.1f, 0.12f, 0.1f)},
                           Aabb{Vec3(-5.0f), Vec3(5.0f)}};
    for (const Aabb& box : boxes) {
        std::vector<Index> all, filtered;
        grid.forEachInBox(box, [&](Index j, const Vec3& x) {
            EXPECT_EQ(x, xs[j]);
            all.push_back(j);
        });
        grid.forEachInBox(box, wanted, [&](Index j, const Vec3&) { filtered.push_back(j); });
        std::vector<Index> expected, expectedFiltered;
        for (Index j = 0; j < Index(xs.size()); ++j) {
            if (!box.contains(xs[j])) continue;
            expected.push_back(j);
            if (wanted(grid.cellOf(xs[j]))) expectedFiltered.push_back(j);
        }
        std::vector<Index> inOrder;
        for (Index j : all) {
            if (wanted(grid.cellOf(xs[j]))) inOrder.push_back(j);
        }
        EXPECT_EQ(filtered, inOrder) << "box " << box.min << " - " << box.max;
        std::sort(all.begin(), all.end());
        std::sort(filtered.begin(), filtered.end());
        EXPECT_EQ(all, expected) << "box " << box.min << " - " << box.max;
        EXPECT_EQ(filtered, expectedFiltered) << "box " << box.min << " - " << box.max;
        // Enough to mean something, and the filter removed most but not all of them.
        EXPECT_GT(expected.size(), 100u);
        EXPECT_GT(expectedFiltered.size(), expected.size() / 8);
        EXPECT_LT(expectedFiltered.size(), expected.size() / 2);
    }
}

namespace {

/// 400 query points: half near particles of `xs` (5 cm normal offsets), half anywhere in a box
/// around the clusters.
std::vector<Vec3> queriesNearAndAround(const std::vector<Vec3>& xs, unsigned seed)
{
    std::vector<Vec3> queries = uniformPoints(400, Vec3(-1.2f), Vec3(1.2f), seed);
    std::mt19937 rng(seed);
    std::normal_distribution<double> offset(0.0, 0.05);
    for (std::size_t q = 0; q < queries.size(); q += 2) {
        queries[q] =
            xs[rng() % xs.size()] + Vec3(Real(offset(rng)), Real(offset(rng)), Real(offset(rng)));
    }
    return queries;
}

/// The nearest-neighbour tests' scene: 4 clusters of 500 points (5 cm spread) in a grid of
/// 5 cm cells, and 400 queries near and around them (queriesNearAndAround).
struct ClusterQueries
{
    /// `seed` places the clusters, `seed + 1` the queries.
    explicit ClusterQueries(unsigned seed) : xs(clusteredPoints(4, 500, 0.05, seed)), grid(cellSize)
    {
        grid.build(xs);
        queries = queriesNearAndAround(xs, seed + 1);
    }

    const Real cellSize = Real(0.05);
    std::vector<Vec3> xs;
    NeighborGrid grid;
    std::vector<Vec3> queries;
};

} // namespace

TEST(NeighborGrid, NearestMatchesBruteForce)
{
    const ClusterQueries scene(9);
    const Real cellSize = scene.cellSize;
    const std::vector<Vec3>& xs = scene.xs;
    const NeighborGrid& grid = scene.grid;
    const std::vector<Vec3>& queries = scene.queries;
    const auto any = [](Index) { return true; };
    std::size_t foundCount = 0, noneCount = 0;
    for (Real maxRadius :
         {Real(0.5) * cellSize, cellSize, Real(3) * cellSize, Real(10) * cellSize}) {
        for (const Vec3& x : queries) {
            Real d = 0, dBrute = 0;
            const Index j = grid.nearest(x, maxRadius, any, &d);
            const Index jBrute = bruteNearest(xs, x, maxRadius, any, &dBrute);
            ASSERT_EQ(j, jBrute) << "query " << x << ", maxRadius " << maxRadius;
            EXPECT_EQ(d, dBrute);
            if (j == INVALID_INDEX) {
                ++noneCount;
                EXPECT_LT(d, Real(0));
            } else {
                ++foundCount;
                EXPECT_LT(d, maxRadius);
            }
            EXPECT_EQ(grid.nearest(x, maxRadius, any), j); // distance output is optional
        }
    }
    // Both outcomes occurred, so both paths were compared.
    EXPECT_GT(foundCount, 100u);
    EXPECT_GT(noneCount, 100u);
    // Far from everything: none within maxRadius.
    Real d = 0;
    EXPECT_EQ(grid.nearest(Vec3(5, 5, 5), Real(0.5), any, &d), INVALID_INDEX);
    EXPECT_LT(d, Real(0));
}

TEST(NeighborGrid, AnyInRadiusAnswersAsNearestDoes)
{
    // anyInRadius(x, R, pred) must be exactly nearest(x, R, pred) != INVALID_INDEX (the air
    // resampling swapped one for the other and keeps the same samples), for a predicate that
    // rejects most particles and at radii below, at and above the cell size.
    const ClusterQueries scene(11);
    const Real cellSize = scene.cellSize;
    const NeighborGrid& grid = scene.grid;
    const auto some = [](Index j) { return j % 7 == 3; };
    std::size_t yes = 0, no = 0;
    for (Real maxRadius : {Real(0.5) * cellSize, cellSize, Real(2.5) * cellSize}) {
        for (const Vec3& x : scene.queries) {
            const bool any = grid.anyInRadius(x, maxRadius, some);
            ASSERT_EQ(any, grid.nearest(x, maxRadius, some) != INVALID_INDEX)
                << "query " << x << ", maxRadius " << maxRadius;
            ++(any ? yes : no);
        }
    }
    EXPECT_GT(yes, 100u); // both answers were compared
    EXPECT_GT(no, 100u);
    EXPECT_FALSE(grid.anyInRadius(Vec3(5, 5, 5), Real(0.5), some));
    EXPECT_FALSE(NeighborGrid(cellSize).anyInRadius(Vec3(0), cellSize, some)); // empty grid
}

TEST(NeighborGrid, NearestOfKindMatchesBruteForce)
{
    const Real cellSize = Real(0.04);
    const std::vector<Vec3> xs = uniformPoints(3000, Vec3(0), Vec3(0.5f), 11);
    std::vector<ParticleKind> kinds(xs.size(), ParticleKind::GhostAir);
    std::mt19937 rng(12);
    std::bernoulli_distribution liquid(0.05); // sparse: the search must go past closer ghosts
    for (auto& k : kinds) {
        if (liquid(rng)) k = ParticleKind::Liquid;
    }
    NeighborGrid grid(cellSize);
    grid.build(xs);
    const std::vector<Vec3> queries = uniformPoints(500, Vec3(-0.1f), Vec3(0.6f), 13);
    std::size_t found = 0;
    for (const Vec3& x : queries) {
        for (Real maxRadius : {cellSize, Real(4) * cellSize}) {
            Real d = 0, dBrute = 0;
            const Index j = grid.nearestOfKind(x, kinds, ParticleKind::Liquid, maxRadius, &d);
            const Index jBrute = bruteNearest(
                xs, x, maxRadius, [&](Index i) { return kinds[i] == ParticleKind::Liquid; },
                &dBrute);
            ASSERT_EQ(j, jBrute) << "query " << x << ", maxRadius " << maxRadius;
            EXPECT_EQ(d, dBrute);
            if (j != INVALID_INDEX) {
                ++found;
                EXPECT_EQ(kinds[j], ParticleKind::Liquid);
            }
        }
    }
    EXPECT_GT(found, 200u);
    // A kind that is absent: nothing, however close the other particles are.
    EXPECT_EQ(grid.nearestOfKind(xs[0], kinds, ParticleKind::Gas, Real(3) * cellSize),
              INVALID_INDEX);
}

TEST(NeighborGrid, SortParticlesReordersTheSetConsistently)
{
    const Real cellSize = Real(0.05);
    // A compact block of 8 x 8 x 8 cells (about 16 particles each): narrower than the table's
    // 25 cells per axis (16384 buckets), so no two of its cells share a bucket.
    const std::vector<Vec3> xs = uniformPoints(8000, Vec3(0.001f), Vec3(0.399f), 14);
    ParticleSet set;
    set.addBatch(xs, Real(1), ParticleKind::Liquid);
    auto& tag = set.addScalarChannel("tag");
    for (std::size_t k = 0; k < set.size(); ++k) {
        tag[k] = Real(3 * set.ids()[k] + 1);
        set.velocities()[k] = Vec3(Real(set.ids()[k]));
    }

    NeighborGrid grid(cellSize);
    grid.sortParticles(set);
    ASSERT_EQ(set.size(), xs.size());
    // Ids follow positions, and every other channel follows its id.
    std::set<ParticleId> seen;
    for (std::size_t k = 0; k < set.size(); ++k) {
        const ParticleId id = set.ids()[k];
        ASSERT_TRUE(id >= 0 && std::size_t(id) < xs.size());
        EXPECT_TRUE(seen.insert(id).second) << "id " << id << " twice";
        EXPECT_EQ(set.positions()[k], xs[std::size_t(id)]);
        EXPECT_EQ(set.scalarChannel("tag")[k], Real(3 * id + 1));
        EXPECT_EQ(set.velocities()[k], Vec3(Real(id)));
    }
    // The set is now in grid order: slot k holds particle k, the grid keeps no index arrays
    // for it, and neighbour indices are indices into the reordered set.
    ASSERT_TRUE(grid.identityOrder());
    EXPECT_TRUE(grid.order().empty());
    ASSERT_EQ(grid.size(), xs.size());
    for (std::size_t k = 0; k < grid.size(); ++k) {
        ASSERT_EQ(grid.particleAt(std::uint32_t(k)), Index(k));
        ASSERT_EQ(grid.slotOf(Index(k)), std::uint32_t(k));
        ASSERT_EQ(grid.sortedPosition(std::uint32_t(k)), set.positions()[k]);
    }
    // Without the two index arrays it holds 8 bytes per particle less than a grid built over
    // the same (now sorted) positions without sorting them.
    NeighborGrid unsorted(cellSize);
    unsorted.build(set.positions());
    EXPECT_LE(grid.memoryBytes() + 8 * xs.size(), unsorted.memoryBytes());
    expectNeighborsMatchBruteForce(grid, set.positions());
    // Particles of one cell are contiguous after the sort (each cell is one run).
    std::map<std::array<int, 3>, int> runs;
    std::array<int, 3> previous{-1, -1, -1};
    for (const Vec3& x : set.positions()) {
        const std::array<int, 3> cell = {int(std::floor(x[0] / cellSize)),
                                         int(std::floor(x[1] / cellSize)),
                                         int(std::floor(x[2] / cellSize))};
        if (cell != previous) ++runs[cell];
        previous = cell;
    }
    EXPECT_EQ(runs.size(), 512u);
    for (const auto& [cell, count] : runs) EXPECT_EQ(count, 1) << "cell split into runs";
}

TEST(NeighborGrid, OrderIsIdenticalForOneThreadAndAllThreads)
{
    // Clustered points in random order: many particles per bucket, coming from every part of
    // the index range, so the scatter order inside a bucket depends on which thread gets there
    // first until the per-bucket sort.
    std::vector<Vec3> xs = clusteredPoints(6, 3000, 0.05, 15);
    std::shuffle(xs.begin(), xs.end(), std::mt19937(15));
    std::vector<Index> oneThread;
    {
        ghostfx::parallel::ThreadLimit limit(1);
        NeighborGrid grid(Real(0.02));
        grid.build(xs);
        oneThread = grid.order();
    }
    const bool wasSerial = ghostfx::parallel::isSerial();
    ghostfx::parallel::setSerial(false);
    for (int repeat = 0; repeat < 5; ++repeat) {
        NeighborGrid grid(Real(0.02));
        grid.build(xs);
        EXPECT_EQ(grid.order(), oneThread) << "repeat " << repeat;
    }
    ghostfx::parallel::setSerial(wasSerial);
    // order() is a permutation.
    std::vector<Index> sorted = oneThread;
    std::sort(sorted.begin(), sorted.end());
    for (std::size_t k = 0; k < sorted.size(); ++k) ASSERT_EQ(sorted[k], Index(k));
}

TEST(NeighborGrid, NonFinitePositionThrowsNumericalErrorNamingTheFirstBadParticle)
{
    std::vector<Vec3> xs = uniformPoints(5000, Vec3(0), Vec3(1), 16);
    const Real nan = std::numeric_limits<Real>::quiet_NaN();
    xs[4321][1] = nan;
    xs[1234][0] = nan;
    xs[2000][2] = std::numeric_limits<Real>::infinity();
    NeighborGrid grid(Real(0.1));
    try {
        grid.build(xs);
        ADD_FAILURE() << "NaN position accepted";
    } catch (const ghostfx::NumericalError& e) {
        EXPECT_THAT(e.what(), HasSubstr("particle 1234 "));
        EXPECT_THAT(e.what(), HasSubstr("non-finite"));
    }
}

TEST(NeighborGrid, PositionBeyondTheCellRangeThrowsValueError)
{
    const Real cellSize = Real(0.05);
    const Real limit = Real(NeighborGrid::MAX_CELL_COORD) * cellSize; // about 52 km
    std::vector<Vec3> xs = uniformPoints(100, Vec3(0), Vec3(1), 17);
    xs.push_back(Vec3(Real(0.99) * limit, Real(0), Real(0))); // inside the range: accepted
    xs.push_back(Vec3(Real(0), Real(-0.99) * limit, Real(0)));
    NeighborGrid grid(cellSize);
    ASSERT_NO_THROW(grid.build(xs));
    expectNeighborsMatchBruteForce(grid, xs);

    xs[57] = Vec3(Real(0), Real(0), Real(-1.001) * limit);
    try {
        grid.build(xs);
        ADD_FAILURE() << "position beyond " << limit << " m accepted";
    } catch (const ghostfx::ValueError& e) {
        EXPECT_THAT(e.what(), HasSubstr("particle 57 "));
        EXPECT_THAT(e.what(), HasSubstr("beyond the grid range"));
    }
}

TEST(NeighborGrid, RejectsNonPositiveOrNonFiniteCellSize)
{
    for (Real bad : {Real(0), Real(-0.1), std::numeric_limits<Real>::quiet_NaN(),
                     std::numeric_limits<Real>::infinity()}) {
        try {
            NeighborGrid grid(bad);
            ADD_FAILURE() << "cell size " << bad << " accepted";
        } catch (const ghostfx::ValueError& e) {
            EXPECT_THAT(e.what(), HasSubstr("cell size = "));
            EXPECT_THAT(e.what(), HasSubstr("expected a finite value > 0"));
        }
    }
}

} // namespace

TEST(NeighborGrid, HugeRadiiAndFarQueryPointsMatchBruteForceWithoutScanningEmptyCells)
{
    // A search wider than the particle count in cells sweeps the particles instead of walking
    // (2 reach + 1)^3 mostly empty cells; a query point far outside the representable range
    // must not overflow the cell coordinates. Both must agree with brute force.
    const Real R = 0.03f;
    const std::vector<Vec3> xs = uniformPoints(500, Vec3(0), Vec3(0.3f), 5);
    NeighborGrid grid(R);
    grid.build(xs);

    const Vec3 queries[] = {Vec3(0.1f, 0.2f, 0.15f), Vec3(5e4f, -3e4f, 1e5f), Vec3(-1e9f, 0, 0)};
    const Real radii[] = {Real(10), Real(1e5), Real(1e10)}; // 333 to 3e11 cells wide
    for (const Vec3& x : queries) {
        for (const Real radius : radii) {
            std::vector<Index> found;
            grid.forEachInRadius(x, radius,
                                 [&](Index j, const Vec3&, Real) { found.push_back(j); });
            std::sort(found.begin(), found.end());
            EXPECT_EQ(found, bruteInRadius(xs, x, radius)) << "radius " << radius;

            Real d = 0, dBrute = 0;
            const Index j = grid.nearest(
                x, radius, [](Index) { return true; }, &d);
            const Index jBrute = bruteNearest(
                xs, x, radius, [](Index) { return true; }, &dBrute);
            EXPECT_EQ(j, jBrute) << "radius " << radius;
            EXPECT_EQ(d, dBrute) << "radius " << radius;
        }
    }
    // A non-finite query finds nothing (and does not crash).
    std::size_t visits = 0;
    grid.forEachInRadius(Vec3(std::nanf(""), 0, 0), R, [&](Index, const Vec3&, Real) { ++visits; });
    EXPECT_EQ(visits, 0u);
    EXPECT_EQ(grid.nearest(Vec3(INFINITY, 0, 0), R, [](Index) { return true; }), INVALID_INDEX);
}
