/// @file   test_methods.cc
/// @brief  The method registry (cmd/Methods.h): every entry builds and steps a simulation of
///         its medium, scene names resolve to it, and the scene rules of a medium (what a gas or
///         a liquid scene may hold) are refused with the key that breaks them.
#include "Methods.h"
#include "Simulation.h"

#include "common/Expect.h"

#include <ghostfx/sph/Exceptions.h>
#include <ghostfx/vdbio/Scene.h>

#include <gtest/gtest.h>

#include <fstream>
#include <set>

using namespace ghostfx;
using ghostfx::testing::contains;
using vdbio::Json;

namespace {

class Methods : public ::testing::Test
{
protected:
    void SetUp() override { mDir = ghostfx::testing::freshTestDir("methods"); }

    /// A liquid block in a small tank; few particles, so every method steps it in a moment.
    static Json liquidScene(const std::string& method)
    {
        Json s = Json::parse(R"({
            "ghostfx_scene": 1,
            "settings": { "spacing": 0.03, "substeps": 0, "frame_rate": 100, "frame_range": [1, 1] },
            "solids": [ { "name": "tank",
                          "geometry": { "container": { "min": [0, 0, 0], "max": [0.3, 0.3, 0.3] } } } ],
            "liquids": [ { "name": "water",
                           "geometry": { "box": { "min": [0, 0, 0], "max": [0.15, 0.12, 0.15] } } } ]
        })");
        s["settings"]["method"] = method;
        return s;
    }

    /// A hot source in a closed box of gas.
    static Json gasScene(const std::string& method)
    {
        Json s = Json::parse(R"({
            "ghostfx_scene": 1,
            "settings": { "spacing": 0.06, "frame_rate": 100, "frame_range": [1, 1],
                          "gas": { "substeps": 1 } },
            "domain": { "kill_box": { "min": [-0.3, -0.1, -0.3], "max": [0.3, 0.6, 0.3] } },
            "gas_sources": [ { "name": "burner",
                               "geometry": { "sphere": { "center": [0, 0.1, 0], "radius": 0.1 } },
                               "temperature": 600 } ]
        })");
        s["settings"]["method"] = method;
        return s;
    }

    vdbio::Scene read(const Json& doc) const
    {
        const std::string path = (mDir / "scene.json").string();
        std::ofstream(path) << doc.dump(2);
        return vdbio::readScene(path);
    }

    /// The one-line error that checking `doc` for a simulation gives.
    std::string checkError(const Json& doc) const
    {
        const vdbio::Scene scene = read(doc);
        return ghostfx::testing::errorOf<SceneError>([&] { cmd::checkSimulationSettings(scene); });
    }

    std::filesystem::path mDir;
};

#define EXPECT_CONTAINS(text, part) EXPECT_TRUE(contains(text, part)) << "message: " << (text)

} // namespace

TEST_F(Methods, EveryEntryBuildsAndStepsASimulationOfItsMedium)
{
    std::set<std::string> names;
    bool liquid = false, gas = false;
    for (const cmd::Method& m : cmd::methods()) {
        SCOPED_TRACE(m.name);
        EXPECT_TRUE(names.insert(m.name).second) << "duplicate method name";
        EXPECT_FALSE(m.summary.empty());
        const bool isLiquid = m.medium == cmd::Medium::Liquid;
        liquid |= isLiquid;
        gas |= !isLiquid;
        const vdbio::Scene scene = read(isLiquid ? liquidScene(m.name) : gasScene(m.name));
        EXPECT_EQ(&cmd::methodOf(scene), &m);
        EXPECT_NO_THROW(m.check(scene));
        std::unique_ptr<cmd::Simulation> sim = cmd::makeSimulation(scene);
        sim->advanceFrame();
        EXPECT_EQ(sim->frame(), 1);
        EXPECT_NEAR(sim->time(), 0.01, 1e-6); // one frame at 100 fps
        const std::vector<cmd::OutputMedium> media = sim->media();
        ASSERT_EQ(media.size(), 1u);
        EXPECT_EQ(media[0].liquid, isLiquid);
        EXPECT_GT(media[0].particles->size(), 0u);
        // One solver state, and a simulation continued from it is at the same frame.
        const std::vector<sph::SolverState> states = sim->saveStates();
        ASSERT_EQ(states.size(), 1u);
        EXPECT_EQ(cmd::makeSimulation(scene, &states)->frame(), 1);
    }
    EXPECT_TRUE(liquid && gas) << "each medium has a method";
    // A baseline names a method of the same medium.
    for (const cmd::Method& m : cmd::methods()) {
        if (m.baselineOf.empty()) continue;
        bool found = false;
        for (const cmd::Method& of : cmd::methods())
            found |= of.name == m.baselineOf && of.medium == m.medium;
        EXPECT_TRUE(found) << m.name << " is a baseline of '" << m.baselineOf << "'";
    }
}

TEST_F(Methods, UnknownAndRetiredNamesAreRefusedWithTheKnownOnes)
{
    EXPECT_CONTAINS(checkError(liquidScene("flip")),
                    "scene.json': settings.method = \"flip\": expected 'ghost', 'basic', 'gas', "
                    "'gas_ambient' or 'gas_uncorrected'");
    EXPECT_CONTAINS(checkError(liquidScene("gost")), "(did you mean 'ghost'?)");
    EXPECT_CONTAINS(checkError(gasScene("gas_ambiant")), "(did you mean 'gas_ambient'?)");
    // The gas baselines were chosen by settings.gas.variant once; the key now points at the method.
    Json g = gasScene("gas");
    g["settings"]["gas"]["variant"] = "ambient";
    EXPECT_CONTAINS(checkError(g), "settings.gas.variant: replaced by the method: settings.method "
                                   "'gas' (fast), 'gas_ambient' or 'gas_uncorrected'");
    g = gasScene("gas");
    g["settings"]["gas"]["method"] = "gas_ambient";
    EXPECT_CONTAINS(checkError(g), "settings.gas.method: a gas scene's method is settings.method");
    // The ambient baseline fills the kill box with air: without one it is refused by its key.
    g = gasScene("gas_ambient");
    g.erase("domain");
    EXPECT_CONTAINS(checkError(g), "settings.method = \"gas_ambient\": the ambient-air baseline "
                                   "fills a box with air: expected domain.kill_box");
}

TEST_F(Methods, AMediumRefusesWhatItCannotSimulate)
{
    Json s = liquidScene("ghost");
    s.erase("liquids");
    EXPECT_CONTAINS(
        checkError(s),
        "liquids: the scene has no liquid: expected at least one liquid body or emitter");
    s = liquidScene("ghost");
    s["gas_sources"] = gasScene("gas")["gas_sources"];
    EXPECT_CONTAINS(checkError(s), "gas_sources: gas sources need a gas method");
    s["settings"]["method"] = "gas";
    EXPECT_CONTAINS(checkError(s), "liquids: a 'gas' scene simulates gas only");
    s["settings"]["method"] = "gas_uncorrected";
    EXPECT_CONTAINS(checkError(s), "liquids: a 'gas_uncorrected' scene simulates gas only");
    s.erase("liquids");
    s["settings"].erase("substeps"); // a liquid key: the gas's are in settings.gas
    EXPECT_NO_THROW(cmd::checkSimulationSettings(read(s)));
    Json empty = gasScene("gas");
    empty.erase("gas_sources");
    EXPECT_CONTAINS(checkError(empty), "gas_sources: the scene has no gas");

    // Gas settings and attractors in a liquid scene without heaters: nothing would read them.
    s = liquidScene("basic");
    s["settings"]["gas"] = {{"kappa", 2}};
    EXPECT_CONTAINS(checkError(s), "settings.gas: gas settings need a gas method or heaters");
    s = liquidScene("ghost");
    s["force_fields"] = Json::parse(
        R"([{ "name": "magic", "attractor": { "position": [0, 1, 0], "strength": 3 } }])");
    EXPECT_CONTAINS(checkError(s), "force_fields: attractors act on gas; this scene has no gas");

    // A deforming solid: only the liquid solver applies per-frame shapes, so a gas scene and a
    // boiling one (whose vapour would keep the first shape) refuse it instead of ignoring it.
    Json d = gasScene("gas");
    d["solids"] = Json::parse(R"([{ "name": "paddle",
        "geometry": { "sphere": { "center": [0, 0.4, 0], "radius": 0.15 } },
        "sequence": { "file": "paddle.$F4.vdb", "grid": "paddle" } }])");
    EXPECT_CONTAINS(checkError(d), "solids[0].sequence: solid 'paddle' deforms per frame, which "
                                   "only a liquid scene supports; a gas scene takes static or "
                                   "rigidly moving solids");
    Json b = liquidScene("ghost");
    b["solids"][0]["sequence"] = {{"file", "tank.$F4.vdb"}, {"grid", "tank"}};
    b["heaters"] = Json::parse(
        R"([{ "geometry": { "box": { "min": [0, -0.05, 0], "max": [0.3, 0, 0.3] } }, "temperature": 400 }])");
    EXPECT_CONTAINS(checkError(b), "solids[0].sequence: solid 'tank' deforms per frame, which "
                                   "only a liquid scene supports; a boiling scene");
}

TEST_F(Methods, ABoilingScenePicksItsVapourMethodBySettingsGasMethod)
{
    Json b = liquidScene("ghost");
    b["heaters"] = Json::parse(
        R"([{ "geometry": { "box": { "min": [0, -0.05, 0], "max": [0.3, 0, 0.3] } }, "temperature": 400 }])");
    b["settings"]["gas"] = {{"method", "gas_uncorrected"}};
    EXPECT_NO_THROW(cmd::checkSimulationSettings(read(b)));
    b["settings"]["gas"]["method"] = "steam";
    EXPECT_CONTAINS(checkError(b), "settings.gas.method = \"steam\": expected one of 'gas', "
                                   "'gas_ambient', 'gas_uncorrected'");
    // The ambient baseline needs its box, named by the vapour's key.
    b["settings"]["gas"]["method"] = "gas_ambient";
    EXPECT_CONTAINS(checkError(b), "settings.gas.method = \"gas_ambient\": the ambient-air "
                                   "baseline fills a box with air: expected domain.kill_box");
    // A boiling checkpoint holds the liquid, the vapour and the phase transition.
    b["settings"]["gas"]["method"] = "gas";
    const vdbio::Scene scene = read(b);
    EXPECT_EQ(cmd::stateCount(scene), 3u);
}
