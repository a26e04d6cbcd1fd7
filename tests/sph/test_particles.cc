/// @file   test_particles.cc
/// @brief  ParticleSet contracts: stable ids, removal and reordering that keep every channel
///         (built-in and named) aligned, id counter validation, channel errors.
/// @details Every channel of particle i is filled with a known function of its id, so after any
///          removal or permutation each row can be checked against its own id.
#include <ghostfx/sph/Exceptions.h>
#include <ghostfx/sph/ParticleSet.h>

#include "common/Expect.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <numeric>
#include <random>
#include <vector>

namespace {

using namespace ghostfx::sph;
using ::testing::HasSubstr;

// Channel contents as functions of the id. All are exact in float (small integers and halves).
Vec3 positionOf(ParticleId id) { return Vec3(Real(id), Real(-id), Real(0.5) * Real(id)); }
Vec3 velocityOf(ParticleId id) { return Vec3(Real(1), Real(id % 7), Real(-2 * (id % 5))); }
Real densityOf(ParticleId id) { return Real(1000 + id % 100); }
Real pressureOf(ParticleId id) { return Real(id % 37) - Real(3); }
Real temperatureOf(ParticleId id) { return Real(0.5) * Real(id % 1000); }
Vec3 vorticityOf(ParticleId id) { return Vec3(Real(id % 11), Real(id % 13), Real(id % 17)); }
/// Runs of 7 equal kinds, so the batches below hold several particles.
ParticleKind kindOf(ParticleId id) { return ParticleKind((id / 7) % 5); }
Real massOf(ParticleKind kind) { return Real(1) + Real(int(kind)); }

/// A set of n particles added one by one (first half) and in batches (second half), with every
/// built-in channel and two named channels filled from the id.
ParticleSet makeFilledSet(std::size_t n)
{
    ParticleSet set;
    set.addScalarChannel("temperature");
    set.addVectorChannel("vorticity");
    for (std::size_t i = 0; i < n / 2; ++i) {
        const auto id = ParticleId(i);
        set.add(positionOf(id), velocityOf(id), massOf(kindOf(id)), kindOf(id));
    }
    // One batch per run of equal kinds.
    std::size_t i = n / 2;
    while (i < n) {
        const ParticleKind kind = kindOf(ParticleId(i));
        std::vector<Vec3> xs;
        std::size_t j = i;
        for (; j < n && kindOf(ParticleId(j)) == kind; ++j) xs.push_back(positionOf(ParticleId(j)));
        set.addBatch(xs, massOf(kind), kind);
        i = j;
    }
    auto& temperature = set.scalarChannel("temperature");
    auto& vorticity = set.vectorChannel("vorticity");
    for (std::size_t k = 0; k < set.size(); ++k) {
        const ParticleId id = set.ids()[k];
        set.velocities()[k] = velocityOf(id);
        set.densities()[k] = densityOf(id);
        set.pressures()[k] = pressureOf(id);
        temperature[k] = temperatureOf(id);
        vorticity[k] = vorticityOf(id);
    }
    return set;
}

/// Every channel has size() entries and each row matches its id. Reports the first bad row.
void expectRowsMatchIds(const ParticleSet& set)
{
    const std::size_t n = set.size();
    ASSERT_EQ(set.positions().size(), n);
    ASSERT_EQ(set.velocities().size(), n);
    ASSERT_EQ(set.masses().size(), n);
    ASSERT_EQ(set.densities().size(), n);
    ASSERT_EQ(set.pressures().size(), n);
    ASSERT_EQ(set.kinds().size(), n);
    ASSERT_EQ(set.ids().size(), n);
    ASSERT_EQ(set.scalarChannel("temperature").size(), n);
    ASSERT_EQ(set.vectorChannel("vorticity").size(), n);
    for (std::size_t k = 0; k < n; ++k) {
        const ParticleId id = set.ids()[k];
        const bool ok =
            set.positions()[k] == positionOf(id) && set.velocities()[k] == velocityOf(id)
            && set.kinds()[k] == kindOf(id) && set.masses()[k] == massOf(kindOf(id))
            && set.densities()[k] == densityOf(id) && set.pressures()[k] == pressureOf(id)
            && set.scalarChannel("temperature")[k] == temperatureOf(id)
            && set.vectorChannel("vorticity")[k] == vorticityOf(id);
        ASSERT_TRUE(ok) << "row " << k << " (id " << id << ") has channels of another particle";
    }
}

TEST(ParticleSet, AddAndAddBatchAssignConsecutiveIds)
{
    ParticleSet set;
    EXPECT_TRUE(set.empty());
    EXPECT_EQ(set.nextId(), 0);
    EXPECT_EQ(set.add(Vec3(1, 2, 3), Vec3(4, 5, 6), Real(0.5), ParticleKind::Gas), 0u);
    EXPECT_EQ(set.add(Vec3(0), Vec3(0), Real(1), ParticleKind::Liquid), 1u);
    const std::vector<Vec3> xs = {Vec3(1), Vec3(2), Vec3(3)};
    EXPECT_EQ(set.addBatch(xs, Real(2), ParticleKind::Boundary), 2u);
    EXPECT_EQ(set.addBatch({}, Real(2), ParticleKind::Boundary), 5u); // empty batch: no ids used
    EXPECT_EQ(set.add(Vec3(9), Vec3(0), Real(1), ParticleKind::GhostAir), 5u);

    ASSERT_EQ(set.size(), 6u);
    EXPECT_EQ(set.ids(), (std::vector<ParticleId>{0, 1, 2, 3, 4, 5}));
    EXPECT_EQ(set.nextId(), 6);
    EXPECT_EQ(set.positions()[0], Vec3(1, 2, 3));
    EXPECT_EQ(set.velocities()[0], Vec3(4, 5, 6));
    EXPECT_EQ(set.masses()[0], Real(0.5));
    EXPECT_EQ(set.kinds()[0], ParticleKind::Gas);
    for (std::size_t k = 2; k < 5; ++k) {
        EXPECT_EQ(set.positions()[k], xs[k - 2]);
        EXPECT_EQ(set.velocities()[k], Vec3(0)); // batches start at rest
        EXPECT_EQ(set.masses()[k], Real(2));
        EXPECT_EQ(set.kinds()[k], ParticleKind::Boundary);
        EXPECT_EQ(set.densities()[k], Real(0));
        EXPECT_EQ(set.pressures()[k], Real(0));
    }
}

TEST(ParticleSet, IdSequenceWithAStrideKeepsProcessesApart)
{
    // Three processes of one simulation: each takes ids congruent to its rank modulo 3 above
    // the shared ones, so what they add never collides, appends included.
    std::vector<ParticleSet> sets(3);
    for (int r = 0; r < 3; ++r) {
        sets[std::size_t(r)].addBatch(std::vector<Vec3>(5, Vec3(0)), 1, ParticleKind::Liquid);
        sets[std::size_t(r)].setIdSequence(6 + r, 3);
        sets[std::size_t(r)].addBatch(std::vector<Vec3>(4, Vec3(0)), 1, ParticleKind::GhostAir);
    }
    std::vector<ParticleId> fresh;
    for (int r = 0; r < 3; ++r) {
        const auto& ids = sets[std::size_t(r)].ids();
        for (std::size_t k = 5; k < ids.size(); ++k) {
            EXPECT_EQ(ids[k] % 3, r);
            fresh.push_back(ids[k]);
        }
    }
    std::sort(fresh.begin(), fresh.end());
    EXPECT_EQ(std::adjacent_find(fresh.begin(), fresh.end()), fresh.end());
    // Appending another rank's particles (with a larger counter) keeps this rank's residue.
    sets[0].append(sets[2]);
    EXPECT_EQ(sets[0].nextId() % 3, 0);
    EXPECT_GE(sets[0].nextId(), sets[2].nextId());
    EXPECT_EQ(sets[0].idStride(), 3);
    EXPECT_THROW(sets[1].setIdSequence(100, 0), ghostfx::ValueError);
    EXPECT_THROW(sets[1].setIdSequence(3, 2), ghostfx::ValueError); // below an id in the set
}

TEST(ParticleSet, NamedChannelsGetTheirDefaultForNewParticles)
{
    ParticleSet set;
    set.addBatch({Vec3(0), Vec3(1)}, Real(1), ParticleKind::Liquid);
    // A channel added later covers the existing particles with its value...
    auto& phi = set.addScalarChannel("phi", Real(-2));
    EXPECT_EQ(phi, (std::vector<Real>{Real(-2), Real(-2)}));
    set.addVectorChannel("normal", Vec3(0, 1, 0));
    phi[0] = Real(7);
    // ... and new particles get the default, not a copy of a neighbour.
    set.add(Vec3(5), Vec3(0), Real(1), ParticleKind::Liquid);
    set.addBatch({Vec3(6), Vec3(7)}, Real(1), ParticleKind::Gas);
    EXPECT_EQ(set.scalarChannel("phi"),
              (std::vector<Real>{Real(7), Real(-2), Real(-2), Real(-2), Real(-2)}));
    EXPECT_EQ(set.vectorChannel("normal"), std::vector<Vec3>(5, Vec3(0, 1, 0)));
    // Adding an existing channel returns it unchanged (no refill).
    EXPECT_EQ(set.addScalarChannel("phi", Real(100))[0], Real(7));
    EXPECT_EQ(set.scalarChannelNames(), (std::vector<std::string>{"phi"}));
    EXPECT_EQ(set.vectorChannelNames(), (std::vector<std::string>{"normal"}));
    EXPECT_TRUE(set.hasScalarChannel("phi"));
    EXPECT_FALSE(set.hasScalarChannel("normal")); // scalar and vector names are separate
    EXPECT_TRUE(set.hasVectorChannel("normal"));
}

TEST(ParticleSet, RemoveIfKeepsSurvivorsInOrderWithTheirChannels)
{
    const std::size_t n = 5000;
    ParticleSet set = makeFilledSet(n);
    expectRowsMatchIds(set);

    std::mt19937 rng(42);
    std::bernoulli_distribution coin(0.3);
    std::vector<std::uint8_t> remove(n);
    std::vector<ParticleId> expectedIds;
    for (std::size_t k = 0; k < n; ++k) {
        remove[k] = coin(rng) ? 1 : 0;
        if (!remove[k]) expectedIds.push_back(set.ids()[k]);
    }
    const std::size_t removed = set.removeIf(remove);
    EXPECT_EQ(removed, n - expectedIds.size());
    EXPECT_EQ(set.size(), expectedIds.size());
    EXPECT_EQ(set.ids(), expectedIds); // survivors keep their ids and their relative order
    expectRowsMatchIds(set);

    // Removing nothing and removing everything.
    EXPECT_EQ(set.removeIf(std::vector<std::uint8_t>(set.size(), 0)), 0u);
    EXPECT_EQ(set.ids(), expectedIds);
    EXPECT_EQ(set.removeIf(std::vector<std::uint8_t>(set.size(), 1)), expectedIds.size());
    EXPECT_TRUE(set.empty());
    EXPECT_TRUE(set.scalarChannel("temperature").empty());
    EXPECT_TRUE(set.vectorChannel("vorticity").empty());
}

TEST(ParticleSet, RemoveIfRejectsMaskOfWrongSize)
{
    ParticleSet set = makeFilledSet(10);
    try {
        set.removeIf(std::vector<std::uint8_t>(9, 0));
        ADD_FAILURE() << "a 9-entry mask for 10 particles was accepted";
    } catch (const ghostfx::ValueError& e) {
        EXPECT_THAT(e.what(), HasSubstr("9 entries"));
        EXPECT_THAT(e.what(), HasSubstr("(10)"));
    }
    EXPECT_EQ(set.size(), 10u);
}

TEST(ParticleSet, ReorderKeepsEveryChannelAlignedById)
{
    const std::size_t n = 5000;
    ParticleSet set = makeFilledSet(n);
    const std::vector<ParticleId> idsBefore = set.ids();
    std::vector<Index> order(n);
    std::iota(order.begin(), order.end(), Index(0));
    std::shuffle(order.begin(), order.end(), std::mt19937(7));
    set.reorder(order);
    ASSERT_EQ(set.size(), n);
    for (std::size_t k = 0; k < n; ++k) ASSERT_EQ(set.ids()[k], idsBefore[order[k]]) << k;
    expectRowsMatchIds(set);
    EXPECT_EQ(set.nextId(), ParticleId(n)); // reordering allocates no ids

    // The inverse permutation restores the original order.
    std::vector<Index> inverse(n);
    for (std::size_t k = 0; k < n; ++k) inverse[order[k]] = Index(k);
    set.reorder(inverse);
    EXPECT_EQ(set.ids(), idsBefore);
    expectRowsMatchIds(set);
}

TEST(ParticleSet, ReorderRejectsOrderOfWrongSize)
{
    ParticleSet set = makeFilledSet(10);
    try {
        set.reorder(std::vector<Index>{0, 1, 2});
        ADD_FAILURE() << "a 3-entry order for 10 particles was accepted";
    } catch (const ghostfx::ValueError& e) {
        EXPECT_THAT(e.what(), HasSubstr("3 entries"));
        EXPECT_THAT(e.what(), HasSubstr("10 particles"));
    }
}

TEST(ParticleSet, ReorderRejectsARepeatedIndex)
{
    // A repeated index would duplicate one particle's id and drop another particle silently.
    ParticleSet set = makeFilledSet(4);
    const std::vector<ParticleId> idsBefore = set.ids();
    try {
        set.reorder(std::vector<Index>{0, 1, 1, 3});
        ADD_FAILURE() << "a non-permutation was accepted";
    } catch (const ghostfx::ValueError& e) {
        EXPECT_THAT(e.what(), HasSubstr("entry 2 = 1"));
        EXPECT_THAT(e.what(), HasSubstr("permutation"));
    }
    EXPECT_EQ(set.ids(), idsBefore); // nothing changed
}

TEST(ParticleSet, IdsAreNeverReusedAfterRemovalOrClear)
{
    ParticleSet set = makeFilledSet(100);
    // Remove the particles with the highest ids: a counter derived from max(id) + 1 would hand
    // them out again.
    std::vector<std::uint8_t> remove(100, 0);
    for (std::size_t k = 50; k < 100; ++k) remove[k] = 1;
    set.removeIf(remove);
    EXPECT_EQ(set.add(Vec3(0), Vec3(0), Real(1), ParticleKind::Liquid), 50u);
    EXPECT_EQ(set.ids().back(), 100);
    EXPECT_EQ(set.addBatch({Vec3(1), Vec3(2)}, Real(1), ParticleKind::Gas), 51u);
    EXPECT_EQ(set.ids()[51], 101);
    EXPECT_EQ(set.ids()[52], 102);
    set.clear();
    EXPECT_TRUE(set.empty());
    EXPECT_TRUE(set.scalarChannel("temperature").empty()); // channels stay, emptied
    set.add(Vec3(0), Vec3(0), Real(1), ParticleKind::Liquid);
    EXPECT_EQ(set.ids()[0], 103);
    EXPECT_EQ(set.nextId(), 104);
}

TEST(ParticleSet, MissingChannelErrorNamesTheChannelAndTheExistingOnes)
{
    ParticleSet set = makeFilledSet(3);
    const ParticleSet& constSet = set;
    using ghostfx::testing::errorOf;
    const std::string scalar =
        errorOf<ghostfx::ValueError>([&] { set.scalarChannel("pressure_old"); });
    EXPECT_THAT(scalar, HasSubstr("'pressure_old' (scalar)"));
    EXPECT_THAT(scalar, HasSubstr("scalar channels: temperature"));
    // "temperature" exists, but as a scalar.
    const std::string vector =
        errorOf<ghostfx::ValueError>([&] { constSet.vectorChannel("temperature"); });
    EXPECT_THAT(vector, HasSubstr("'temperature' (vector)"));
    EXPECT_THAT(vector, HasSubstr("vector channels: vorticity"));
    ParticleSet bare;
    const std::string none = errorOf<ghostfx::ValueError>([&] { bare.vectorChannel("normal"); });
    EXPECT_THAT(none, HasSubstr("'normal'"));
    EXPECT_THAT(none, HasSubstr("vector channels: none"));
}

TEST(ParticleSet, SetNextIdMustExceedEveryId)
{
    ParticleSet set = makeFilledSet(10); // ids 0..9
    for (ParticleId bad : {ParticleId(9), ParticleId(0), ParticleId(-5)}) {
        try {
            set.setNextId(bad);
            ADD_FAILURE() << "setNextId(" << bad << ") accepted with largest id 9";
        } catch (const ghostfx::ValueError& e) {
            EXPECT_THAT(e.what(), HasSubstr("setNextId(" + std::to_string(bad) + ")"));
            EXPECT_THAT(e.what(), HasSubstr("largest id in the set (9)"));
        }
    }
    EXPECT_EQ(set.nextId(), 10); // unchanged by the failed calls
    // The largest id need not be last: after a reorder the check still sees it.
    std::vector<Index> reversed(10);
    std::iota(reversed.rbegin(), reversed.rend(), Index(0));
    set.reorder(reversed);
    EXPECT_THROW(set.setNextId(9), ghostfx::ValueError);
    set.setNextId(1000); // resume after a checkpoint whose counter was 1000
    EXPECT_EQ(set.add(Vec3(0), Vec3(0), Real(1), ParticleKind::Liquid), 10u);
    EXPECT_EQ(set.ids().back(), 1000);
    EXPECT_EQ(set.nextId(), 1001);
    ParticleSet empty;
    EXPECT_NO_THROW(empty.setNextId(0));
    EXPECT_THROW(empty.setNextId(-1), ghostfx::ValueError);
}

TEST(ParticleSet, CountByKind)
{
    ParticleSet small;
    small.addBatch(std::vector<Vec3>(3, Vec3(0)), Real(1), ParticleKind::Gas);
    small.add(Vec3(0), Vec3(0), Real(1), ParticleKind::Liquid);
    small.addBatch(std::vector<Vec3>(2, Vec3(0)), Real(1), ParticleKind::Gas);
    EXPECT_EQ(small.count(ParticleKind::Gas), 5u);
    EXPECT_EQ(small.count(ParticleKind::Liquid), 1u);
    EXPECT_EQ(small.count(ParticleKind::Boundary), 0u);

    const std::size_t n = 1003;
    ParticleSet set = makeFilledSet(n);
    std::size_t expected[5] = {0, 0, 0, 0, 0};
    for (std::size_t id = 0; id < n; ++id) ++expected[int(kindOf(ParticleId(id)))];
    for (int k = 0; k < 5; ++k) EXPECT_EQ(set.count(ParticleKind(k)), expected[k]) << k;
    std::vector<std::uint8_t> remove(set.size());
    for (std::size_t k = 0; k < set.size(); ++k) {
        remove[k] = set.kinds()[k] == ParticleKind::Gas ? 1 : 0;
    }
    set.removeIf(remove);
    EXPECT_EQ(set.count(ParticleKind::Gas), 0u);
    EXPECT_EQ(set.count(ParticleKind::Liquid), expected[0]);
    EXPECT_EQ(set.size(), n - expected[int(ParticleKind::Gas)]);
}

TEST(ParticleSet, KindNames)
{
    EXPECT_STREQ(kindName(ParticleKind::Liquid), "liquid");
    EXPECT_STREQ(kindName(ParticleKind::GhostAir), "ghost_air");
    EXPECT_STREQ(kindName(ParticleKind::GhostSolid), "ghost_solid");
    EXPECT_STREQ(kindName(ParticleKind::Gas), "gas");
    EXPECT_STREQ(kindName(ParticleKind::Boundary), "boundary");
}

TEST(ParticleSet, ReserveKeepsContents)
{
    ParticleSet set = makeFilledSet(20);
    set.reserve(10000);
    EXPECT_EQ(set.size(), 20u);
    EXPECT_GE(set.positions().capacity(), 10000u);
    EXPECT_GE(set.scalarChannel("temperature").capacity(), 10000u);
    expectRowsMatchIds(set);
}

} // namespace
