/// @file   test_study.cc
/// @brief  `ghostfx study` end to end: the table, the plot, reference traces, failed cases and
///         bad study files, on a free-falling drop small enough to run many times.
#include <ghostfx/sph/Types.h>

#include "common/Expect.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <sstream>
#include <string>
#include <sys/wait.h>
#include <vector>

namespace fs = std::filesystem;
using Json = nlohmann::json;

namespace {

using ghostfx::testing::slurp;

/// A CSV table as rows of column -> text.
std::vector<std::map<std::string, std::string>> readCsv(const fs::path& p)
{
    std::ifstream in(p);
    std::string line;
    std::vector<std::string> header;
    std::vector<std::map<std::string, std::string>> rows;
    auto split = [](const std::string& l) {
        std::vector<std::string> f;
        std::string cur;
        bool quoted = false;
        for (char c : l) {
            if (c == '"') quoted = !quoted;
            else if (c == ',' && !quoted) {
                f.push_back(cur);
                cur.clear();
            } else cur += c;
        }
        f.push_back(cur);
        return f;
    };
    if (std::getline(in, line)) header = split(line);
    while (std::getline(in, line)) {
        const std::vector<std::string> f = split(line);
        std::map<std::string, std::string> row;
        for (std::size_t k = 0; k < header.size() && k < f.size(); ++k) row[header[k]] = f[k];
        rows.push_back(row);
    }
    return rows;
}

double num(const std::map<std::string, std::string>& row, const std::string& key)
{
    auto it = row.find(key);
    return it == row.end() || it->second.empty() ? NAN : std::stod(it->second);
}

class Study : public ::testing::Test
{
protected:
    void SetUp() override
    {
        mDir = ghostfx::testing::freshTestDir("study");
        // A drop of water in free fall, no solid anywhere: its centre of mass must follow
        // x0 + v0 t + g t^2 / 2 whatever the internal forces do (they cancel in pairs).
        std::ofstream(mDir / "drop.json") << R"({
            "ghostfx_scene": 1,
            "settings": { "method": "ghost", "spacing": 0.02, "substeps": 10, "frame_range": [1, 4],
                          "stiffness": 2000, "seed": 3 },
            "liquids": [ { "name": "drop", "geometry": { "sphere": { "center": [0, 1, 0], "radius": 0.06 } },
                           "velocity": [0.5, 0, 0] } ]
        })";
    }

    fs::path writeStudy(const Json& study, const std::string& name = "study.json") const
    {
        std::ofstream(mDir / name) << study.dump(2);
        return mDir / name;
    }

    Json baseStudy() const
    {
        Json s = Json::parse(R"({ "ghostfx_study": 1, "scene": "drop.json",
                                  "metrics": ["free_fall", "density_error", "volume_drift"] })");
        s["output"]["directory"] = (mDir / "out").string();
        return s;
    }

    struct Result
    {
        int code = -1;
        std::string err;
    };

    Result run(const std::string& args) const
    {
        const fs::path err = mDir / "stderr.txt";
        const std::string command = std::string(GHOSTFX_EXE) + " " + args + " 2> " + err.string();
        const int status = std::system(command.c_str());
        return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, slurp(err)};
    }

    /// A bad study: exit code 1, one line on stderr (returned), nothing written.
    std::string errorLine(const Json& study) const
    {
        const Result r = run("study " + writeStudy(study).string() + " --threads 1");
        EXPECT_EQ(r.code, 1) << r.err;
        EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
        EXPECT_FALSE(fs::exists(mDir / "out")) << "a refused study wrote output";
        return r.err;
    }

    fs::path mDir;
};

} // namespace

TEST_F(Study, SweepWritesTableAndParetoPlotWithMeasuredErrors)
{
    Json s = baseStudy();
    s["sweep"]["settings.substeps"] = {5, 20};
    s["sweep"]["settings.method"] = {"ghost", "basic"};
    s["plot"]["series"] = "settings.method";
    s["convergence"] = {{"key", "settings.substeps"}, {"inverse", true}};
    const Result r = run("study " + writeStudy(s).string() + " --threads 1");
    ASSERT_EQ(r.code, 0) << r.err;
    EXPECT_NE(r.err.find("[4/4]"), std::string::npos) << r.err;

    const auto rows = readCsv(mDir / "out" / "study.csv");
    ASSERT_EQ(rows.size(), 4u);
    for (const auto& row : rows) {
        ASSERT_EQ(row.at("status"), "ok") << row.at("note");
        EXPECT_EQ(row.at("precision"), sizeof(ghostfx::sph::Real) == 8 ? "double" : "float");
        // Cost: 4 frames at 30 fps; wall time per simulated second = wall / (4/30).
        EXPECT_NEAR(num(row, "sim_s"), 4.0 / 30.0, 1e-6);
        EXPECT_NEAR(num(row, "wall_per_sim_second"), num(row, "wall_s") / num(row, "sim_s"),
                    1e-3 * num(row, "wall_per_sim_second"));
        EXPECT_EQ(num(row, "steps"), 4 * std::stod(row.at("settings.substeps")));
        EXPECT_GT(num(row, "peak_rss_mb"), 1.0);
        EXPECT_GT(num(row, "count_liquid"), 50);
        // Free fall: pairwise forces cancel, so the centre of mass moves as the integrator moves
        // one particle. Symplectic Euler (v += dt g, then x += dt v) over n steps of dt lands at
        // x0 + v0 T + g T^2 / 2 + g T dt / 2: an O(dt) error of exactly |g| T dt / 2, which the
        // metric must find. Basic SPH's forces are symmetric: to 1 %. Ghost SPH's are not quite
        // (ghost air pushes the liquid but is not pushed back; XSPH weights m_j / rho_j differ):
        // over 12 sample realisations (the sampler's seed salted, both volume relaxations;
        // bench/history/diary-2026-11.md, "Tests that hold over sample realisations") -0.040 to
        // +0.109 spacings from the integrator's error, as the sampling falls; allowed 0.15.
        const double T = 4.0 / 30.0, dt = T / num(row, "steps");
        const double expected = 9.81 * T * dt / 2 / 0.02;
        const double tolerance = row.at("settings.method") == "basic" ? 0.01 * expected : 0.15;
        std::printf("[measured] study free fall (%s, %s substeps): centre-of-mass error %.4f "
                    "spacings, integrator's %.4f\n",
                    row.at("settings.method").c_str(), row.at("settings.substeps").c_str(),
                    num(row, "free_fall_com_error_spacings"), expected);
        EXPECT_NEAR(num(row, "free_fall_com_error_spacings"), expected, tolerance)
            << row.at("settings.method");
        // No particle is added or removed.
        EXPECT_EQ(num(row, "mass_drift"), 0.0);
        EXPECT_GE(num(row, "density_error_max"), num(row, "density_error_mean"));
    }
    // Ghost air fills the drop's missing neighbours: its density error is smaller than Basic's
    // (Basic's surface particles see a truncated sum, [SB12] Fig. 3).
    EXPECT_LT(num(rows[0], "density_error_mean") + num(rows[1], "density_error_mean"),
              num(rows[2], "density_error_mean") + num(rows[3], "density_error_mean"));
    // Order in dt (step = 1 / substeps): Basic SPH's centre of mass carries exactly the
    // integrator's first-order error, so 1 to round-off (measured 1.0000); Ghost SPH's ghost air
    // adds a small dt-independent drift, which lowers its order (measured 0.3-1.0).
    const auto order = readCsv(mDir / "out" / "convergence.csv");
    ASSERT_EQ(order.size(), 2u);
    for (const auto& row : order) {
        EXPECT_EQ(num(row, "1/settings.substeps_coarse"), 0.2);
        EXPECT_EQ(num(row, "1/settings.substeps_fine"), 0.05);
        if (row.at("group") == "settings.method=basic")
            EXPECT_NEAR(num(row, "observed_order"), 1.0, 0.01);
        else EXPECT_GT(num(row, "observed_order"), 0.2);
    }
    // The plot is a PNG with its signature.
    const std::string png = slurp(mDir / "out" / "study.png");
    ASSERT_GT(png.size(), 8u);
    EXPECT_EQ(png.substr(1, 3), "PNG");

    // --replot redraws from the table alone (no run: the table is left as it was).
    const std::string table = slurp(mDir / "out" / "study.csv");
    fs::remove(mDir / "out" / "study.png");
    const Result again = run("study " + (mDir / "study.json").string() + " --replot");
    ASSERT_EQ(again.code, 0) << again.err;
    EXPECT_TRUE(fs::exists(mDir / "out" / "study.png"));
    EXPECT_EQ(slurp(mDir / "out" / "study.csv"), table);
}

TEST_F(Study, TracesAreComparedWithTheReferenceAndOrderIsReported)
{
    Json s = baseStudy();
    // The drop's lowest point, tracked downwards, against a reference with finer steps.
    s["metrics"] = Json::array(
        {Json{{"metric", "surge_front"}, {"direction", {0, -1, 0}}, {"percentile", 100}}});
    s["sweep"]["settings.spacing"] = {0.03, 0.02};
    s["reference"]["settings.spacing"] = 0.015;
    const Result r = run("study " + writeStudy(s).string() + " --threads 1");
    ASSERT_EQ(r.code, 0) << r.err;
    const auto rows = readCsv(mDir / "out" / "study.csv");
    ASSERT_EQ(rows.size(), 3u);
    EXPECT_EQ(rows[0].at("role"), "reference");
    EXPECT_EQ(num(rows[0], "surge_front_error_m"), 0.0);
    for (std::size_t k = 1; k < 3; ++k) {
        // Every drop falls 8.7 cm in 4 frames; they differ only in where their lowest particle
        // sits (within a spacing of the sphere's surface): error finite, under 2 spacings.
        const double e = num(rows[k], "surge_front_error_m");
        EXPECT_TRUE(std::isfinite(e));
        EXPECT_LT(e, 2 * 0.03);
        EXPECT_NEAR(num(rows[k], "surge_front_error"), e / (0.5 * 9.81 * std::pow(4.0 / 30.0, 2)),
                    0.2 * num(rows[k], "surge_front_error") + 1e-9);
    }
    const auto order = readCsv(mDir / "out" / "convergence.csv");
    ASSERT_EQ(order.size(), 1u);
    EXPECT_EQ(num(order[0], "settings.spacing_coarse"), 0.03);
    EXPECT_EQ(num(order[0], "settings.spacing_fine"), 0.02);
    EXPECT_NEAR(num(order[0], "observed_order"),
                std::log(num(rows[1], "surge_front_error") / num(rows[2], "surge_front_error"))
                    / std::log(1.5),
                1e-3);
}

TEST_F(Study, BlownUpCaseIsRecordedAndTheStudyGoesOn)
{
    Json s = baseStudy();
    // One fixed step per frame at a stiffness of 1e7 Pa (sound speed 84 m/s, dt = 1/30 s):
    // the acoustic CFL number is 140, far beyond stability.
    s["runs"] = Json::array({Json{{"settings.stiffness", 1e7}, {"settings.substeps", 1}},
                             Json{{"settings.stiffness", 2000}, {"settings.substeps", 10}}});
    const Result r = run("study " + writeStudy(s).string() + " --threads 1");
    ASSERT_EQ(r.code, 0) << r.err;
    EXPECT_NE(r.err.find("unstable"), std::string::npos) << r.err;
    const auto rows = readCsv(mDir / "out" / "study.csv");
    ASSERT_EQ(rows.size(), 2u);
    EXPECT_EQ(rows[0].at("status"), "unstable");
    EXPECT_NE(rows[0].at("note").find("blew up"), std::string::npos) << rows[0].at("note");
    EXPECT_EQ(rows[1].at("status"), "ok");
    EXPECT_TRUE(fs::exists(mDir / "out" / "runs" / "case_00.log"));
}

TEST_F(Study, BadStudyFilesGetOneClearLine)
{
    const std::string file = (mDir / "study.json").string();
    {
        Json s = baseStudy();
        s["metrics"] = {"free_fal"};
        EXPECT_EQ(
            errorLine(s),
            "ghostfx: error: study '" + file
                + "': metrics[0] = \"free_fal\": unknown metric "
                  "(expected one of density_error, volume_drift, hydrostatic_pressure, free_fall, "
                  "cube_shape, surge_front, plume_rise, poiseuille)\n");
    }
    {
        Json s = baseStudy();
        s["sweep"]["settings.spacng"] = {0.02};
        EXPECT_EQ(errorLine(s),
                  "ghostfx: error: study '" + file + "': case 'settings.spacng=0.02': scene '"
                      + (mDir / "drop.json").string()
                      + "': settings.spacng: unknown key (did you mean 'spacing'?)\n");
    }
    {
        Json s = baseStudy();
        s["sweep"]["settings.spacing"] = Json::array();
        EXPECT_EQ(
            errorLine(s),
            "ghostfx: error: study '" + file
                + "': sweep: 'settings.spacing' = []: expected a non-empty array of values\n");
    }
    {
        Json s = baseStudy();
        s["sweep"]["precision"] = {sizeof(ghostfx::sph::Real) == 8 ? "float" : "double"};
        const std::string e = errorLine(s);
        EXPECT_NE(e.find("executables: case 'precision="), std::string::npos) << e;
    }
    {
        Json s = baseStudy();
        s["plot"]["error"] = "hydrostatic_pressure_error";
        const std::string e = errorLine(s);
        EXPECT_NE(
            e.find("plot.error = \"hydrostatic_pressure_error\": not a column of these metrics"),
            std::string::npos)
            << e;
    }
    {
        Json s = baseStudy();
        s["metrics"] = Json::array({Json{{"metric", "surge_front"}, {"percentil", 90}}});
        const std::string e = errorLine(s);
        EXPECT_NE(e.find("metrics[0].percentil: unknown option of this metric"), std::string::npos)
            << e;
    }
    {
        Json s = baseStudy();
        s["scene"] = "missing.json";
        EXPECT_EQ(errorLine(s), "ghostfx: error: study '" + file + "': case '': scene '"
                                    + (mDir / "missing.json").string()
                                    + "': cannot open the file\n");
    }
    EXPECT_EQ(errorLine(Json::parse(R"({"ghostfx_study": 1, "scene": "drop.json"})")),
              "ghostfx: error: study '" + file
                  + "': metrics = null: expected a non-empty array of metric names "
                    "(docs/study.md)\n");
}

TEST_F(Study, HydrostaticTankPressureFollowsRhoGD)
{
    // [SB12]'s stiffness, k = 2000 Pa: stable and repeatable here (0.087-0.093 profile error over
    // 0.5 and 1 s, keep fractions 0.8 and 10). At k = 20000 Pa this coarse tank (8 layers) is
    // dominated by pressure noise (1.1-1.3 of the bottom pressure, per particle).
    std::ofstream(mDir / "tank.json") << R"({
        "ghostfx_scene": 1,
        "settings": { "method": "ghost", "spacing": 0.025, "substeps": 0, "cfl": 0.4, "stiffness": 2000,
                      "frame_range": [1, 15], "seed": 1 },
        "solids": [ { "name": "tank",
                      "geometry": { "container": { "min": [0, 0, 0], "max": [0.2, 0.3, 0.2], "wall": 0.08 } } } ],
        "liquids": [ { "name": "water", "geometry": { "box": { "min": [0, 0, 0], "max": [0.2, 0.2, 0.2] } } } ]
    })";
    Json s = baseStudy();
    s["scene"] = "tank.json";
    s["metrics"] = {"hydrostatic_pressure", "density_error"};
    const Result r = run("study " + writeStudy(s).string() + " --threads 2");
    ASSERT_EQ(r.code, 0) << r.err;
    const auto rows = readCsv(mDir / "out" / "study.csv");
    ASSERT_EQ(rows.size(), 1u);
    ASSERT_EQ(rows[0].at("status"), "ok") << rows[0].at("note");
    // The free surface is known to half a spacing either way (a particle stands for the cube
    // around it), which alone shifts the profile by up to h / (2 H) = 0.0625 of the bottom
    // pressure; the Tait liquid's compression at this stiffness adds a few percent (below).
    // Measured 0.093 (profile) and 0.070 (balance). Allowed: h / H = 0.125.
    std::printf("[measured] study tank: profile error %.4f, balance error %.4f, slope error "
                "%+.4f, noise %.4f, mean density error %.4f\n",
                num(rows[0], "hydrostatic_pressure_error"),
                num(rows[0], "hydrostatic_balance_error"), num(rows[0], "hydrostatic_slope_error"),
                num(rows[0], "hydrostatic_pressure_noise"), num(rows[0], "density_error_mean"));
    EXPECT_LT(num(rows[0], "hydrostatic_pressure_error"), 0.025 / 0.2);
    EXPECT_LT(num(rows[0], "hydrostatic_balance_error"), 0.025 / 0.2);
    // The slope of p against depth does not depend on where the surface is. At k = 2000 Pa the
    // bottom is 10 % denser than rho0 (rho0 g H / 7k = 0.14 -> (1.14)^(1/7)), so the slope is
    // above rho0 |g| by about the mean compression (about +9 % when first measured); over 12
    // sample realisations (the sampler's seed salted, both volume relaxations;
    // bench/history/diary-2026-11.md, "Tests that hold over sample realisations") +12.9 to +15.2 %;
    // allowed 0 to 20 %.
    EXPECT_GT(num(rows[0], "hydrostatic_slope_error"), 0.0);
    EXPECT_LT(num(rows[0], "hydrostatic_slope_error"), 0.20);
    // Mean |rho / rho0 - 1| below the bottom's 10 %.
    EXPECT_LT(num(rows[0], "density_error_mean"), 0.1);
    // Single particles scatter more than the layer means: the noise bounds the profile error.
    EXPECT_GE(num(rows[0], "hydrostatic_pressure_noise"),
              num(rows[0], "hydrostatic_pressure_error"));
}

// The poiseuille metric on the shipped study's scene (examples/studies/poiseuille/) at 1.25 cm
// spacing (eight layers across the 10 cm gap), DFSPH at nu = 0.5 m^2/s: the profile within the
// issue's 3 % of the parabola's peak (the study measured 1.2 % at this spacing, 8 % at 2 cm,
// where five layers do not resolve the parabola: docs/study.md); a
// liquid without viscosity is refused in one line, since the metric has no answer for it.
TEST_F(Study, PoiseuilleMetricReadsTheParabola)
{
    Json s = baseStudy();
    s["scene"] = (fs::path(GHOSTFX_SOURCE_DIR) / "examples/studies/poiseuille/scene.json").string();
    s["set"] = {{"settings.spacing", 0.0125}};
    s["metrics"] = Json::parse(R"([ { "metric": "poiseuille", "gap": 0.1 } ])");
    const Result r = run("study " + writeStudy(s).string() + " --threads 2");
    ASSERT_EQ(r.code, 0) << r.err;
    const auto rows = readCsv(mDir / "out" / "study.csv");
    ASSERT_EQ(rows.size(), 1u);
    ASSERT_EQ(rows[0].at("status"), "ok") << rows[0].at("note");
    std::printf("[measured] study Poiseuille, 1.25 cm: profile error %.4f of the peak\n",
                num(rows[0], "poiseuille_error"));
    EXPECT_LT(num(rows[0], "poiseuille_error"), 0.03);
    fs::remove_all(mDir / "out");
    s["set"]["settings.viscosity"] = 0;
    const Result refused = run("study " + writeStudy(s).string() + " --threads 2");
    EXPECT_NE(refused.err.find("metric poiseuille: expects a viscous liquid"), std::string::npos)
        << refused.err;
}

TEST_F(Study, CasesRunAsSeparateJobsInAnyOrderThenCollectGiveTheLocalTable)
{
    // Four cases and a reference (so the collection also computes trace errors), run once
    // locally and once as a farm would: each case its own process, in a shuffled order, through
    // the emitted Slurm array script (run here with bash, as sbatch would, one task id at a time).
    Json s = baseStudy();
    s["metrics"] = Json::array(
        {"free_fall", "density_error",
         Json{{"metric", "surge_front"}, {"direction", {0, -1, 0}}, {"percentile", 100}}});
    s["sweep"]["settings.substeps"] = {5, 10};
    s["sweep"]["settings.method"] = {"ghost", "basic"};
    s["reference"]["settings.substeps"] = 20;
    s["max_seconds_per_run"] = 600;
    const std::string study = writeStudy(s).string();
    const fs::path local = mDir / "local", farm = mDir / "farm";
    const Result r = run("study " + study + " --threads 1 --out " + local.string());
    ASSERT_EQ(r.code, 0) << r.err;
    // One array task, as Slurm would start it.
    auto task = [&](int id) {
        const std::string command = "env SLURM_ARRAY_TASK_ID=" + std::to_string(id) + " bash "
                                    + (farm / "slurm" / "cases.sbatch").string();
        const int status = std::system(command.c_str());
        return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
    };

    // --list: a header line, then one line per case with the command that runs it.
    const Result listed = run("study " + study + " --list --threads 1 --out " + farm.string()
                              + " > " + (mDir / "list.txt").string());
    ASSERT_EQ(listed.code, 0) << listed.err;
    std::istringstream list(slurp(mDir / "list.txt"));
    std::string line;
    std::vector<std::string> lines;
    while (std::getline(list, line)) lines.push_back(line);
    ASSERT_EQ(lines.size(), 6u) << slurp(mDir / "list.txt");
    EXPECT_EQ(lines[1].rfind("0\treference settings.substeps=20\t", 0), 0u) << lines[1];
    for (std::size_t k = 1; k < lines.size(); ++k) {
        EXPECT_NE(lines[k].find(" --case " + std::to_string(k - 1) + " --out "), std::string::npos)
            << lines[k];
    }

    // --emit slurm: the array script covers the five cases, with the run's time limit.
    const Result emitted =
        run("study " + study + " --emit slurm --threads 1 --out " + farm.string());
    ASSERT_EQ(emitted.code, 0) << emitted.err;
    const std::string script = slurp(farm / "slurm" / "cases.sbatch");
    EXPECT_NE(script.find("#SBATCH --array=0-4\n"), std::string::npos) << script;
    EXPECT_NE(script.find("#SBATCH --time=10\n"), std::string::npos) << script;
    EXPECT_TRUE(fs::exists(farm / "slurm" / "collect.sbatch"));
    EXPECT_TRUE(fs::exists(farm / "slurm" / "submit.sh"));

    // Half the cases, then --collect: the rest are reported missing, and the table says so.
    for (int id : {3, 0}) ASSERT_EQ(task(id), 0) << "task " << id;
    const Result partial = run("study " + study + " --collect --out " + farm.string());
    ASSERT_EQ(partial.code, 0) << partial.err;
    EXPECT_NE(partial.err.find("3 of 5 cases have no row file yet"), std::string::npos)
        << partial.err;
    EXPECT_EQ(readCsv(farm / "study.csv").at(1).at("status"), "missing");

    for (int id : {4, 1, 2}) ASSERT_EQ(task(id), 0) << "task " << id;
    const Result collected = run("study " + study + " --collect --out " + farm.string());
    ASSERT_EQ(collected.code, 0) << collected.err;
    EXPECT_NE(collected.err.find("collected 5 cases: 5 ok"), std::string::npos) << collected.err;
    EXPECT_TRUE(fs::exists(farm / "study.png"));

    // The same table: every column but the measured times and memory is equal, digit for digit
    // (one thread per case, so each case is the same deterministic run wherever it ran).
    const auto a = readCsv(local / "study.csv"), b = readCsv(farm / "study.csv");
    ASSERT_EQ(a.size(), 5u);
    ASSERT_EQ(b.size(), a.size());
    const std::set<std::string> timed = {
        "setup_s",          "wall_s",     "wall_per_sim_second", "cpu_s", "cpu_per_sim_second",
        "steps_per_second", "peak_rss_mb"};
    for (std::size_t k = 0; k < a.size(); ++k) {
        ASSERT_EQ(a[k].size(), b[k].size());
        EXPECT_EQ(a[k].at("status"), "ok") << a[k].at("note");
        for (const auto& [column, value] : a[k]) {
            if (timed.count(column)) {
                EXPECT_GT(num(b[k], column), 0) << column;
                continue;
            }
            EXPECT_EQ(b[k].at(column), value) << "case " << k << ", " << column;
        }
    }
    EXPECT_GT(num(b[1], "surge_front_error_m"), 0);
    EXPECT_EQ(slurp(farm / "convergence.csv"), slurp(local / "convergence.csv"));

    // A row from another version of the study is refused, naming the file and both cases.
    s["sweep"]["settings.substeps"] = {5, 40};
    writeStudy(s);
    const Result changed = run("study " + study + " --collect --out " + farm.string());
    EXPECT_EQ(changed.code, 1);
    EXPECT_NE(changed.err.find("case_02.json': holds case 'settings.method=ghost "
                               "settings.substeps=10', but case 2 of study"),
              std::string::npos)
        << changed.err;
    EXPECT_NE(changed.err.find("the study changed since the case ran"), std::string::npos);
}

TEST_F(Study, CasesShareOneSampleCache)
{
    // Three stiffnesses of the same drop: the first case samples the drop and keeps it, the
    // others load it (one file in the cache), and the farm commands carry the folder.
    Json s = baseStudy();
    s["sweep"] = Json::parse(R"({ "settings.stiffness": [1000, 2000, 4000] })");
    const std::string study = writeStudy(s).string();
    const fs::path cache = mDir / "cache";
    const Result r =
        run("study " + study + " --threads 1 --sample-cache " + cache.string() + " -q");
    ASSERT_EQ(r.code, 0) << r.err;
    std::size_t files = 0;
    for (const auto& entry : fs::directory_iterator(cache))
        files += entry.path().extension() == ".gfxsamples";
    EXPECT_EQ(files, 1u);
    const auto rows = readCsv(mDir / "out" / "study.csv");
    ASSERT_EQ(rows.size(), 3u);
    for (const auto& row : rows) EXPECT_EQ(row.at("status"), "ok");

    const fs::path listed = mDir / "list.txt";
    ASSERT_EQ(std::system((std::string(GHOSTFX_EXE) + " study " + study + " --list --sample-cache "
                           + cache.string() + " > " + listed.string())
                              .c_str()),
              0);
    const std::string list = slurp(listed);
    EXPECT_NE(list.find("--case 2 "), std::string::npos) << list;
    EXPECT_NE(list.find("--sample-cache '" + fs::absolute(cache).string() + "'"), std::string::npos)
        << list;
}
