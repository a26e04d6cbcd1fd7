/// @file   test_sample_cache.cc
/// @brief  The sample cache (vdbio::SampleCache, sph::sampleVolumeStored): a shape sampled again
///         comes from the cache, bit for bit; another shape, other settings or a damaged file
///         are sampled afresh; a liquid solver set up through the cache steps exactly as one
///         set up without; and a folder with a size limit drops its least recently used shapes.
#include <ghostfx/ghost/GhostSolver.h>
#include <ghostfx/sph/LevelSetGrid.h>
#include <ghostfx/vdbio/SampleCache.h>

#include "common/Expect.h"
#include "common/Shapes.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <fstream>

namespace fs = std::filesystem;
using namespace ghostfx;
using namespace ghostfx::sph;

namespace {

constexpr Real H = Real(0.02);

LevelSet sphere(Real radius)
{
    return makeLevelSet(makeSphereLevelSet(Vec3(0), radius, H / 2, 3), "sphere");
}

bool sameSamples(const SampleSet& a, const SampleSet& b)
{
    if (a.size() != b.size() || a.onSurface != b.onSurface) return false;
    for (std::size_t i = 0; i < a.size(); ++i)
        if (a.positions[i] != b.positions[i]) return false; // bit for bit
    return true;
}

} // namespace

TEST(SampleCache, TheSameShapeAndSettingsComeFromTheCacheBitForBit)
{
    const fs::path dir = ghostfx::testing::freshDir("sample_cache");
    vdbio::SampleCache cache(dir.string());
    const PoissonSettings settings = PoissonSettings::forSpacing(H);
    const LevelSet ball = sphere(Real(0.1));
    const SampleSet fresh = PoissonDiskSampler(settings).sampleVolume(ball);

    const SampleSet first = sampleVolumeStored(settings, ball, &cache);
    EXPECT_EQ(cache.stored(), 1u);
    EXPECT_EQ(cache.hits(), 0u);
    EXPECT_TRUE(sameSamples(first, fresh));
    const SampleSet again = sampleVolumeStored(settings, ball, &cache);
    EXPECT_EQ(cache.hits(), 1u);
    EXPECT_EQ(cache.stored(), 1u);
    EXPECT_TRUE(sameSamples(again, fresh));

    // Another shape, another seed, another band depth: other keys, sampled and kept.
    PoissonSettings seeded = settings;
    seeded.seed = 7;
    PoissonSettings banded = settings;
    banded.bandDepth = 3 * H;
    const LevelSet bigger = sphere(Real(0.1) + H / 8);
    const std::uint64_t key = sampleKey(ball, settings);
    EXPECT_NE(sampleKey(bigger, settings), key);
    EXPECT_NE(sampleKey(ball, seeded), key);
    EXPECT_NE(sampleKey(ball, banded), key);
    EXPECT_EQ(sampleKey(sphere(Real(0.1)), settings), key); // the same grid made again
    sampleVolumeStored(seeded, ball, &cache);
    EXPECT_EQ(cache.stored(), 2u);

    // A damaged file (cut short, as by a full disk) is not used: sampled again, rewritten.
    const std::string path = cache.pathOf(key);
    fs::resize_file(path, fs::file_size(path) / 2);
    const SampleSet repaired = sampleVolumeStored(settings, ball, &cache);
    EXPECT_TRUE(sameSamples(repaired, fresh));
    EXPECT_EQ(cache.hits(), 1u);
    EXPECT_EQ(cache.stored(), 3u);
    EXPECT_TRUE(sameSamples(sampleVolumeStored(settings, ball, &cache), fresh));
    EXPECT_EQ(cache.hits(), 2u);

    // A cache that cannot keep a shape (its folder removed since) costs the time, nothing else.
    vdbio::SampleCache gone((dir / "gone").string());
    fs::remove_all(dir / "gone");
    EXPECT_TRUE(sameSamples(sampleVolumeStored(settings, ball, &gone), fresh));
    EXPECT_EQ(gone.failures(), 1u);
    EXPECT_EQ(gone.stored(), 0u);
    EXPECT_NE(gone.firstFailure().find("gone"), std::string::npos) << gone.firstFailure();
}

TEST(SampleCache, ALiquidSolverSetUpThroughTheCacheStepsAsOneWithout)
{
    // A water block in a closed tank: the first solver samples and keeps the tank and the
    // block, the second loads both; 20 steps later their particles are the same, bit for bit.
    const fs::path dir = ghostfx::testing::freshDir("sample_cache_solver");
    vdbio::SampleCache cache(dir.string());
    ghost::GhostSettings s;
    s.spacing = H;
    s.seed = 3;
    const LevelSet tank =
        makeLevelSet(ghostfx::testing::closedTankGrid(
                         Vec3(0), Vec3(Real(0.4), Real(0.3), Real(0.2)), 4 * H, H / 2),
                     "tank");
    const LevelSet water = makeLevelSet(
        makeBoxLevelSet(Vec3(0), Vec3(Real(0.15), Real(0.2), Real(0.2)), H / 2), "water");
    auto run = [&](SampleStore* store) {
        auto solver = std::make_unique<ghost::GhostSolver>(s);
        solver->setSampleStore(store);
        solver->addSolid(tank);
        solver->addLiquid(water);
        for (int k = 0; k < 20; ++k) solver->step(Real(1e-3));
        return solver->allParticles();
    };
    const ParticleSet without = run(nullptr);
    const ParticleSet kept = run(&cache);
    const ParticleSet loaded = run(&cache);
    EXPECT_EQ(cache.stored(), 2u);
    EXPECT_EQ(cache.hits(), 2u);
    for (const ParticleSet* p : {&kept, &loaded}) {
        ASSERT_EQ(p->size(), without.size());
        EXPECT_EQ(p->ids(), without.ids());
        EXPECT_EQ(p->positions(), without.positions());
        EXPECT_EQ(p->velocities(), without.velocities());
    }
}

TEST(SampleCache, ALimitedFolderRemovesTheLeastRecentlyUsedShapes)
{
    // Three shapes through a folder that holds two: the one neither written nor loaded most
    // recently goes. File times are set by hand (a clock tick is coarser than three writes).
    const fs::path dir = ghostfx::testing::freshDir("sample_cache_limit");
    const PoissonSettings settings = PoissonSettings::forSpacing(H);
    const LevelSet a = sphere(Real(0.1)), b = sphere(Real(0.1) + H / 8),
                   c = sphere(Real(0.1) + H / 4);
    std::uint64_t bytes = 0;
    {
        vdbio::SampleCache unlimited(dir.string());
        sampleVolumeStored(settings, a, &unlimited);
        sampleVolumeStored(settings, b, &unlimited);
        for (const LevelSet* s : {&a, &b}) {
            bytes = std::max<std::uintmax_t>(
                bytes, fs::file_size(unlimited.pathOf(sampleKey(*s, settings))));
        }
    }
    // Room for two files of the largest size, not three.
    vdbio::SampleCache cache(dir.string(), 2 * bytes + bytes / 2);
    const auto now = fs::file_time_type::clock::now();
    fs::last_write_time(cache.pathOf(sampleKey(a, settings)), now - std::chrono::hours(2));
    fs::last_write_time(cache.pathOf(sampleKey(b, settings)), now - std::chrono::hours(1));
    // Loading a makes it the most recently used, so b is now the oldest.
    const SampleSet loaded = sampleVolumeStored(settings, a, &cache);
    EXPECT_EQ(cache.hits(), 1u);
    EXPECT_GT(fs::last_write_time(cache.pathOf(sampleKey(a, settings))),
              fs::last_write_time(cache.pathOf(sampleKey(b, settings))));
    sampleVolumeStored(settings, c, &cache);
    EXPECT_EQ(cache.stored(), 1u);
    EXPECT_EQ(cache.evicted(), 1u);
    EXPECT_TRUE(fs::exists(cache.pathOf(sampleKey(a, settings))));
    EXPECT_FALSE(fs::exists(cache.pathOf(sampleKey(b, settings))));
    EXPECT_TRUE(fs::exists(cache.pathOf(sampleKey(c, settings))));
    // What is left still loads bit for bit.
    EXPECT_TRUE(sameSamples(sampleVolumeStored(settings, a, &cache), loaded));
    EXPECT_EQ(cache.hits(), 2u);

    // A limit smaller than one shape keeps the shape just written, and only it.
    vdbio::SampleCache tiny(dir.string(), 1);
    sampleVolumeStored(settings, b, &tiny);
    std::size_t files = 0;
    for (const fs::directory_entry& e : fs::directory_iterator(dir))
        files += e.path().extension() == ".gfxsamples";
    EXPECT_EQ(files, 1u);
    EXPECT_TRUE(fs::exists(tiny.pathOf(sampleKey(b, settings))));
    EXPECT_EQ(tiny.evicted(), 2u);
}
