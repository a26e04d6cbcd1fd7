/// @file   test_mpi.cc
/// @brief  One simulation over MPI ranks: the particle exchange (migration, halo copies,
///         refresh, rebalancing, a rank left empty) and a dam break on several ranks against
///         the same dam break on one. Run by ctest under mpirun on 2 and 3 ranks.
/// @details Every rank builds the same particles from the same seed, so what a rank must hold
///          after an exchange can be computed on every rank by brute force and compared
///          exactly (ids, counts); sums over ranks are compared to the serial ones in double.
#include <ghostfx/dist/MpiExchange.h>
#include <ghostfx/ghost/GhostSolver.h>
#include <ghostfx/sph/LevelSetGrid.h>
#include <ghostfx/sph/Parallel.h>
#include <ghostfx/sph/Random.h>

#include "common/Shapes.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <memory>
#include <set>
#include <string>
#include <vector>

namespace {

using namespace ghostfx;
using namespace ghostfx::sph;
using ghostfx::ghost::GhostSettings;
using ghostfx::ghost::GhostSolver;

int worldRank()
{
    int r = 0;
    MPI_Comm_rank(MPI_COMM_WORLD, &r);
    return r;
}

int worldSize()
{
    int n = 1;
    MPI_Comm_size(MPI_COMM_WORLD, &n);
    return n;
}

/// The same N particles on every rank: positions in a 2 x 1 x 1 box, ids 0..N-1, a scalar and
/// a vector channel derived from the id.
ParticleSet sameParticles(std::size_t n)
{
    Rng rng(7);
    std::vector<Vec3> x(n);
    for (Vec3& p : x) p = Vec3(rng.uniform(0, 2), rng.uniform(0, 1), rng.uniform(0, 1));
    ParticleSet set;
    set.addBatch(x, Real(1), ParticleKind::Liquid);
    auto& tag = set.addScalarChannel("tag");
    auto& spin = set.addVectorChannel("spin");
    for (std::size_t i = 0; i < n; ++i) {
        tag[i] = Real(set.ids()[i]) * Real(0.5);
        spin[i] = Vec3(Real(set.ids()[i]), 1, 2);
        set.velocities()[i] = Vec3(Real(0.01) * Real(i % 7), Real(0.02), Real(-0.01));
        set.masses()[i] = Real(1) + Real(i % 3);
    }
    return set;
}

/// Every rank's (id -> position) of owned particles, gathered on every rank.
std::map<ParticleId, Vec3> gatherOwned(const ParticleSet& set)
{
    std::vector<double> mine;
    const auto* halo =
        set.hasScalarChannel(HALO_CHANNEL) ? &set.scalarChannel(HALO_CHANNEL) : nullptr;
    for (std::size_t i = 0; i < set.size(); ++i) {
        if (halo && (*halo)[i] != Real(0)) continue;
        mine.push_back(double(set.ids()[i]));
        for (int a = 0; a < 3; ++a) mine.push_back(double(set.positions()[i][a]));
    }
    const int ranks = worldSize();
    int n = int(mine.size());
    std::vector<int> counts(static_cast<std::size_t>(ranks)), displs(counts.size());
    MPI_Allgather(&n, 1, MPI_INT, counts.data(), 1, MPI_INT, MPI_COMM_WORLD);
    int total = 0;
    for (int q = 0; q < ranks; ++q) {
        displs[std::size_t(q)] = total;
        total += counts[std::size_t(q)];
    }
    std::vector<double> all(static_cast<std::size_t>(total));
    MPI_Allgatherv(mine.data(), n, MPI_DOUBLE, all.data(), counts.data(), displs.data(), MPI_DOUBLE,
                   MPI_COMM_WORLD);
    std::map<ParticleId, Vec3> out;
    for (std::size_t k = 0; k < all.size(); k += 4) {
        const ParticleId id = ParticleId(all[k]);
        EXPECT_EQ(out.count(id), 0u) << "particle " << id << " owned twice";
        out[id] = Vec3(Real(all[k + 1]), Real(all[k + 2]), Real(all[k + 3]));
    }
    return out;
}

double sumOver(double value)
{
    double out = 0;
    MPI_Allreduce(&value, &out, 1, MPI_DOUBLE, MPI_SUM, MPI_COMM_WORLD);
    return out;
}

} // namespace

TEST(MpiExchange, MigrationKeepsEveryParticleItsChannelsMassAndMomentum)
{
    const std::size_t n = 4000;
    ParticleSet set = sameParticles(n);
    dist::MpiExchange ex(MPI_COMM_WORLD, set.positions());
    ex.setRebalanceThreshold(1e9); // this test moves particles without rebalancing
    std::vector<std::uint8_t> remove(set.size());
    for (std::size_t i = 0; i < set.size(); ++i) remove[i] = !ex.owns(set.positions()[i]);
    set.removeIf(remove);
    double mass0 = 0, px0 = 0;
    for (std::size_t i = 0; i < n; ++i) {
        mass0 += 1.0 + double(i % 3);
        px0 += (1.0 + double(i % 3)) * double(Real(0.01) * Real(i % 7));
    }
    // Every step each particle moves by a displacement fixed by its id (so the expected
    // positions are known everywhere), crossing the cuts back and forth.
    for (int step = 0; step < 12; ++step) {
        for (std::size_t i = 0; i < set.size(); ++i) {
            const ParticleId id = set.ids()[i];
            const Real dx = Real(0.3) * std::sin(Real(id) + Real(step));
            set.positions()[i][0] += dx;
        }
        ex.exchange(set, Real(0.05));
        ex.dropHalo(set);
        // Owned by the rank whose region holds it, channels intact.
        for (std::size_t i = 0; i < set.size(); ++i) {
            ASSERT_TRUE(ex.owns(set.positions()[i]));
            const ParticleId id = set.ids()[i];
            ASSERT_EQ(set.scalarChannel("tag")[i], Real(id) * Real(0.5));
            ASSERT_EQ(set.vectorChannel("spin")[i], Vec3(Real(id), 1, 2));
        }
    }
    const std::map<ParticleId, Vec3> all = gatherOwned(set);
    ASSERT_EQ(all.size(), n);
    double mass = 0, px = 0;
    for (std::size_t i = 0; i < set.size(); ++i) {
        mass += double(set.masses()[i]);
        px += double(set.masses()[i]) * double(set.velocities()[i][0]);
    }
    // The same values summed in another order: equal to double round-off.
    EXPECT_NEAR(sumOver(mass), mass0, 1e-9 * mass0);
    EXPECT_NEAR(sumOver(px), px0, 1e-9 * std::abs(px0) + 1e-12);
    // The positions are the serial ones exactly (the same float additions, wherever done).
    ParticleSet serial = sameParticles(n);
    for (int step = 0; step < 12; ++step) {
        for (std::size_t i = 0; i < serial.size(); ++i) {
            serial.positions()[i][0] += Real(0.3) * std::sin(Real(serial.ids()[i]) + Real(step));
        }
    }
    for (std::size_t i = 0; i < serial.size(); ++i)
        EXPECT_EQ(all.at(serial.ids()[i]), serial.positions()[i]);
    if (worldSize() > 1) {
        EXPECT_GT(ex.migrated(), 0u);
    }
}

TEST(MpiExchange, HaloHoldsTheOtherRanksParticlesWithinTheWidthAndRefreshes)
{
    const std::size_t n = 3000;
    ParticleSet set = sameParticles(n);
    const ParticleSet everything = set;
    dist::MpiExchange ex(MPI_COMM_WORLD, set.positions());
    std::vector<std::uint8_t> remove(set.size());
    for (std::size_t i = 0; i < set.size(); ++i) remove[i] = !ex.owns(set.positions()[i]);
    set.removeIf(remove);
    const Real width = Real(0.1);
    ex.exchange(set, width);

    // Brute force: the particles of other ranks within `width` of this rank's region.
    std::set<ParticleId> expected, copies;
    for (std::size_t i = 0; i < everything.size(); ++i) {
        const Vec3& x = everything.positions()[i];
        if (ex.owns(x)) continue;
        if (ex.decomposition().distance2(x, ex.rank()) < width * width)
            expected.insert(everything.ids()[i]);
    }
    const auto& halo = set.scalarChannel(HALO_CHANNEL);
    for (std::size_t i = 0; i < set.size(); ++i) {
        if (halo[i] != Real(0)) copies.insert(set.ids()[i]);
    }
    EXPECT_EQ(copies, expected);
    if (worldSize() > 1) {
        EXPECT_FALSE(copies.empty());
    }

    // Owners write a value; refresh brings it to the copies (after a reorder, as the solver's
    // sort does).
    for (std::size_t i = 0; i < set.size(); ++i) {
        if (halo[i] == Real(0)) {
            set.densities()[i] = Real(2) * Real(set.ids()[i]);
            set.vectorChannel("spin")[i] = Vec3(Real(ex.rank()), 0, 0);
        } else {
            set.densities()[i] = -1;
        }
    }
    std::vector<Index> order(set.size());
    for (std::size_t k = 0; k < order.size(); ++k) order[k] = Index(order.size() - 1 - k);
    set.reorder(order);
    ex.refresh(set, {"density", "spin"});
    const auto& flag = set.scalarChannel(HALO_CHANNEL);
    for (std::size_t i = 0; i < set.size(); ++i) {
        EXPECT_EQ(set.densities()[i], Real(2) * Real(set.ids()[i]));
        if (flag[i] != Real(0)) {
            // From its owner, the rank whose region holds it.
            EXPECT_NE(set.vectorChannel("spin")[i][0], Real(ex.rank()));
        }
    }
    ex.dropHalo(set);
    for (Real f : set.scalarChannel(HALO_CHANNEL)) EXPECT_EQ(f, Real(0));
}

TEST(MpiExchange, RanksLeftWithoutParticlesStillExchangeThenRebalance)
{
    // Everything moves into rank 0's region: the other ranks own nothing for a step, the
    // exchanges go on, and the next exchange rebalances (imbalance = ranks > 1.1).
    const std::size_t n = 2000;
    ParticleSet set = sameParticles(n);
    dist::MpiExchange ex(MPI_COMM_WORLD, set.positions());
    std::vector<std::uint8_t> remove(set.size());
    for (std::size_t i = 0; i < set.size(); ++i) remove[i] = !ex.owns(set.positions()[i]);
    set.removeIf(remove);
    ex.setRebalanceThreshold(1e9);
    // Rank 0's region holds the lowest x (slabs along x, the longest axis): squeeze everything
    // into the first tenth of the box.
    for (Vec3& x : set.positions()) x[0] = Real(0.05) * x[0];
    ex.exchange(set, Real(0.02));
    ex.dropHalo(set);
    const double owned = double(set.size());
    if (worldRank() == 0) EXPECT_EQ(owned, double(n));
    else EXPECT_EQ(owned, 0.0);
    EXPECT_EQ(gatherOwned(set).size(), n);

    ex.setRebalanceThreshold(DomainDecomposition::REBALANCE_IMBALANCE);
    ex.exchange(set, Real(0.02));
    ex.dropHalo(set);
    EXPECT_EQ(ex.rebalances(), worldSize() > 1 ? 1u : 0u);
    const double share = double(set.size()) / double(n);
    EXPECT_NEAR(share, 1.0 / worldSize(), 0.01) << "rank " << worldRank();
    EXPECT_EQ(gatherOwned(set).size(), n);
}

namespace {

/// Liquid position differences between a shared run (gathered over the ranks) and a serial one.
struct Difference
{
    std::size_t liquid = 0, matched = 0;
    double rms = 0, worst = 0, com = 0; ///< m
    Vec3 worstAt{0};                    ///< where the worst one is (the single process's)
};

Difference compareLiquid(const std::map<ParticleId, Vec3>& shared, const ParticleSet& alone)
{
    Difference d;
    double sum2 = 0, a[3] = {0, 0, 0}, b[3] = {0, 0, 0};
    for (std::size_t i = 0; i < alone.size(); ++i) {
        if (alone.kinds()[i] != ParticleKind::Liquid) continue;
        ++d.liquid;
        const auto it = shared.find(alone.ids()[i]);
        if (it == shared.end()) continue;
        ++d.matched;
        const double e = double((it->second - alone.positions()[i]).length());
        if (e > d.worst) {
            d.worst = e;
            d.worstAt = alone.positions()[i];
        }
        sum2 += e * e;
        for (int k = 0; k < 3; ++k) {
            a[k] += double(it->second[k]);
            b[k] += double(alone.positions()[i][k]);
        }
    }
    d.rms = std::sqrt(sum2 / double(std::max<std::size_t>(1, d.matched)));
    for (int k = 0; k < 3; ++k) d.com += std::pow((a[k] - b[k]) / double(d.matched), 2);
    d.com = std::sqrt(d.com);
    return d;
}

/// What the dam-break comparisons print of the shared run against one rank alone: the
/// differences after 2 steps and after `steps` steps (time `t`, s), at spacing `h` (m).
std::string differencesText(const Difference& early, const Difference& late, int steps, double t,
                            Real h)
{
    char text[256];
    std::snprintf(text, sizeof(text),
                  "after 2 steps rms %.2e m, worst %.2e m; after %d steps (t = %.3f s) rms %.2e m "
                  "(%.3f h), worst %.2e m, centre of mass %.2e m",
                  early.rms, early.worst, steps, t, late.rms, late.rms / h, late.worst, late.com);
    return text;
}

std::map<ParticleId, Vec3> liquidOf(const ParticleSet& p)
{
    std::vector<std::uint8_t> keep(p.size());
    for (std::size_t i = 0; i < p.size(); ++i) keep[i] = p.kinds()[i] == ParticleKind::Liquid;
    return gatherOwned(p.select(keep));
}

/// The closed 0.3 x 0.2 x 0.1 m tank of the distributed runs below, and their settings.
LevelSet smallTank(Real h)
{
    return makeLevelSet(ghostfx::testing::closedTankGrid(
                            Vec3(0), Vec3(Real(0.3), Real(0.2), Real(0.1)), 4 * h, h / 2),
                        "tank");
}

GhostSettings smallTankSettings(Real h, std::uint64_t seed)
{
    GhostSettings settings;
    settings.spacing = h;
    settings.seed = seed;
    settings.substeps = 0;
    return settings;
}

/// A water block 0.1 x 0.15 x 0.1 m in the small closed tank, the same on every rank.
struct DamBreak
{
    explicit DamBreak(const GhostSettings& s)
        : settings(s)
        , tank(smallTank(s.spacing))
        , water(makeLevelSet(
              makeBoxLevelSet(Vec3(0), Vec3(Real(0.1), Real(0.15), Real(0.1)), s.spacing / 2),
              "water"))
    {}
    std::unique_ptr<GhostSolver> build() const
    {
        auto solver = std::make_unique<GhostSolver>(settings);
        solver->addSolid(tank);
        solver->addLiquid(water);
        solver->prepare();
        return solver;
    }
    GhostSettings settings;
    LevelSet tank, water;
};

} // namespace

TEST(DistributedGhost, DamBreakOnSeveralRanksFollowsOneRank)
{
    // A water block collapsing in a closed tank (about 1,000 liquid particles at h = 1 cm), on
    // all ranks together, on each rank alone, and alone again with every liquid particle moved
    // by 1e-8 m: with the same time steps (the shared run's, the same on every rank).
    const Real h = Real(0.01);
    const DamBreak dam(smallTankSettings(h, 5));
    std::unique_ptr<GhostSolver> shared = dam.build(), alone = dam.build(), nudged = dam.build();
    for (std::size_t i = 0; i < nudged->particles().size(); ++i) {
        if (nudged->particles().kinds()[i] == ParticleKind::Liquid)
            nudged->particles().positions()[i][0] += Real(1e-8) * Real(int(i % 3) - 1);
    }
    dist::MpiExchange ex(MPI_COMM_WORLD, shared->particles().positions());
    shared->setExchange(&ex);

    const int steps = 150;
    Difference early, late, perturbed;
    for (int s = 1; s <= steps; ++s) {
        const Real dt = shared->stableTimeStep();
        shared->step(dt);
        alone->step(dt);
        nudged->step(dt);
        if (s == 2) early = compareLiquid(liquidOf(shared->particles()), alone->particles());
    }
    late = compareLiquid(liquidOf(shared->particles()), alone->particles());
    {
        std::map<ParticleId, Vec3> n;
        const ParticleSet& p = nudged->particles();
        for (std::size_t i = 0; i < p.size(); ++i)
            if (p.kinds()[i] == ParticleKind::Liquid) n[p.ids()[i]] = p.positions()[i];
        perturbed = compareLiquid(n, alone->particles());
    }
    if (worldRank() == 0) {
        std::printf("[measured] %d ranks, %zu liquid: %s; serial nudged by 1e-8 m: rms %.2e m; "
                    "%llu migrated, %llu halo copies received by rank 0\n",
                    worldSize(), late.liquid,
                    differencesText(early, late, steps, shared->time(), h).c_str(), perturbed.rms,
                    static_cast<unsigned long long>(ex.migrated()),
                    static_cast<unsigned long long>(ex.haloReceived()));
    }
    // The same liquid ids: none lost, none duplicated (gatherOwned checks), none added.
    EXPECT_EQ(late.matched, late.liquid);
    EXPECT_EQ(liquidOf(shared->particles()).size(), late.liquid);
    // Summation order: after 2 steps the ranks' sums over their neighbour lists (halo copies
    // in another order) differ from one process's in the last bits only. Measured: worst 9e-8
    // m on 2 ranks, 3.4e-7 m on 3, i.e. 3 and 10 float ulps at the tank's 0.3 m; bound 30 ulps
    // (1.1e-6 m, a ten-thousandth of a spacing).
    EXPECT_LT(early.worst, 30 * 0.3 * std::numeric_limits<float>::epsilon());
    // Later the ghost air differs: each rank samples the air of its own region from its own
    // seeds, so the new air (from step 2 on, faded in over 10 steps) is not the single
    // process's. The flow itself hardly amplifies round-off here: the serial run moved by
    // 1e-8 m stays within 4e-7 m rms over the same steps (bound 1e-5 m, a thousandth of a
    // spacing). Measured after 150 steps (0.13 s, the block half collapsed), 2 / 3 ranks: rms
    // 0.13 / 0.15 h, worst 0.94 / 0.86 h, centre of mass 0.02 / 0.06 h; bounds 0.3 h, 2 h and
    // 0.1 h.
    EXPECT_LT(perturbed.rms, 1e-5);
    EXPECT_LT(late.rms, 0.3 * h);
    EXPECT_LT(late.worst, 2 * h);
    EXPECT_LT(late.com, 0.1 * h);
}

TEST(DistributedGhost, DfsphDamBreakOnSeveralRanksFollowsOneRank)
{
    // The dam break above with the implicit pressure (settings.pressure dfsph): each rank
    // solves for its own particles, refreshing the halo copies' values before every pass.
    const Real h = Real(0.01);
    GhostSettings settings = smallTankSettings(h, 5);
    settings.pressure = ghost::PressureModel::Dfsph;
    const DamBreak dam(settings);
    std::unique_ptr<GhostSolver> shared = dam.build(), alone = dam.build();
    dist::MpiExchange ex(MPI_COMM_WORLD, shared->particles().positions());
    shared->setExchange(&ex);

    const int steps = 60;
    Difference early, late;
    for (int s = 1; s <= steps; ++s) {
        const Real dt = shared->stableTimeStep();
        shared->step(dt);
        alone->step(dt);
        if (s == 2) early = compareLiquid(liquidOf(shared->particles()), alone->particles());
    }
    late = compareLiquid(liquidOf(shared->particles()), alone->particles());
    const auto& a = shared->pressureSolveStats();
    const auto& b = alone->pressureSolveStats();
    if (worldRank() == 0) {
        std::printf("[measured] dfsph, %d ranks, %zu liquid: %s; density iterations %llu / %llu "
                    "(shared / alone), unconverged %llu / %llu\n",
                    worldSize(), late.liquid,
                    differencesText(early, late, steps, shared->time(), h).c_str(),
                    static_cast<unsigned long long>(a.densityIterations),
                    static_cast<unsigned long long>(b.densityIterations),
                    static_cast<unsigned long long>(a.unconverged),
                    static_cast<unsigned long long>(b.unconverged));
    }
    EXPECT_EQ(late.matched, late.liquid);
    EXPECT_EQ(liquidOf(shared->particles()).size(), late.liquid);
    // The tolerances of the Tait test above, for the same reasons. Measured, 2 / 3 ranks:
    // after 2 steps worst 1.5e-8 / 5.7e-8 m (the solves stop at the same iteration: every
    // decision is on sums over all ranks); after 60 steps (0.17 s) rms 0.16 / 0.19 h, worst
    // 0.95 / 1.1 h, centre of mass 0.002 / 0.003 h. Without the halo copies' search
    // direction from their owners: 1.8e-4 m after 2 steps and 274 iterations against 158.
    EXPECT_LT(early.worst, 30 * 0.3 * std::numeric_limits<float>::epsilon());
    EXPECT_LT(late.rms, 0.3 * h);
    EXPECT_LT(late.worst, 2 * h);
    EXPECT_LT(late.com, 0.1 * h);
    EXPECT_EQ(a.unconverged, 0u);
}

TEST(DistributedGhost, MovingAndReshapedSolidsOnSeveralRanksFollowOneRank)
{
    // A paddle sliding through a water block in a closed tank, on all ranks together and on
    // each rank alone with the same time steps; half way the paddle changes shape (a solid
    // sequence's next frame, thicker on its back), which resamples its ghost particles mid-run.
    // Solids are whole on every rank: the resampled particles must take the same ids
    // everywhere, above every liquid and air id any rank has given.
    const Real h = Real(0.01);
    const GhostSettings settings = smallTankSettings(h, 9);
    const LevelSet tank = smallTank(h);
    const LevelSet water = makeLevelSet(
        makeBoxLevelSet(Vec3(0), Vec3(Real(0.2), Real(0.08), Real(0.1)), h / 2), "water");
    const LevelSet paddle =
        makeLevelSet(makeBoxLevelSet(Vec3(Real(0.22), Real(0.02), 0),
                                     Vec3(Real(0.24), Real(0.15), Real(0.1)), h / 2),
                     "paddle");
    const LevelSet thicker =
        makeLevelSet(makeBoxLevelSet(Vec3(Real(0.22), Real(0.02), 0),
                                     Vec3(Real(0.25), Real(0.15), Real(0.1)), h / 2),
                     "paddle");
    auto build = [&]() {
        auto solver = std::make_unique<GhostSolver>(settings);
        solver->addSolid(tank);
        solver->addSolid(paddle, Vec3(Real(-0.2), 0, 0));
        solver->addLiquid(water);
        solver->prepare();
        return solver;
    };
    std::unique_ptr<GhostSolver> shared = build(), alone = build();
    dist::MpiExchange ex(MPI_COMM_WORLD, shared->particles().positions());
    shared->setExchange(&ex);

    const int steps = 120;
    ParticleId highestSolid = 0, highestFluid = 0;
    for (int s = 1; s <= steps; ++s) {
        const Real dt = shared->stableTimeStep();
        shared->step(dt);
        alone->step(dt);
        if (s == steps / 2) {
            shared->setSolidShape(1, thicker);
            alone->setSolidShape(1, thicker);
            const ParticleSet all = shared->allParticles();
            for (std::size_t i = 0; i < all.size(); ++i) {
                const ParticleId id = all.ids()[i];
                if (all.kinds()[i] == ParticleKind::GhostSolid)
                    highestSolid = std::max(highestSolid, id);
                else highestFluid = std::max(highestFluid, id);
            }
        }
    }
    // The paddle's new particles: the same ids on every rank, above every liquid and air id
    // of every rank at that moment.
    const auto agree = [&](ParticleId id) {
        return ex.maxOf(double(id)) == double(id) && ex.minOf(double(id)) == double(id);
    };
    EXPECT_TRUE(agree(highestSolid));
    EXPECT_GT(double(highestSolid), ex.maxOf(double(highestFluid)));
    const Difference late = compareLiquid(liquidOf(shared->particles()), alone->particles());
    if (worldRank() == 0) {
        std::printf("[measured] %d ranks, %zu liquid, paddle moved %.3f m: after %d steps rms "
                    "%.2e m (%.3f h), worst %.2e m at (%.3f %.3f %.3f), centre of mass %.2e m; "
                    "highest paddle id %lld\n",
                    worldSize(), late.liquid, 0.2 * shared->time(), steps, late.rms, late.rms / h,
                    late.worst, late.worstAt[0], late.worstAt[1], late.worstAt[2], late.com,
                    static_cast<long long>(highestSolid));
    }
    EXPECT_EQ(late.matched, late.liquid);
    EXPECT_EQ(liquidOf(shared->particles()).size(), late.liquid);
    // As the dam break above: each rank's own ghost air, not round-off; the same bounds for
    // the rms and the centre of mass. Measured, 2 / 3 ranks: rms 0.10 / 0.11 h, worst 0.65 /
    // 0.55 h, centre of mass 0.01 h. The worst particle is often one squeezed through the
    // two-spacing gap under the moving paddle, where which way it goes is a coin toss: over
    // 12 sample realisations at 2 ranks (the seed salted, both volume relaxations; bench/history/
    // diary-2026-11.md, "Tests that hold over sample realisations") rms 0.04-0.12 h, worst
    // 0.18-2.47 h (above 1 h only at the floor beside the paddle). Bound for the worst: 3 h.
    EXPECT_LT(late.rms, 0.3 * h);
    EXPECT_LT(late.worst, 3 * h);
    EXPECT_LT(late.com, 0.1 * h);
}
