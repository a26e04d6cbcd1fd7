/// @file   StudyCommand.cc
/// @brief  `ghostfx study`: one scene over a sweep of settings, cost against error.
/// @details The study file names a scene, the keys to sweep (any scene key, as for `-D`), the
///          metrics to measure and where to write. A study is three pieces, which a farm runs
///          as separate jobs and a local run runs in turn:
///          - the cases (`--list`): every combination of the sweep, numbered from 0;
///          - one case (`--case K`): runs the scene with case K's settings and writes its row
///            file, `runs/case_KK.json` in the output folder (status, cost, metric values and
///            traces), in a process of its own: a clean peak-memory figure, a case that blows
///            up is recorded as such, and a case may run on another build (double precision);
///          - the collection (`--collect`): reads every row file and writes the table (CSV and
///            Markdown), the observed convergence order and a plot of error against cost with
///            the Pareto front.
///          Without a flag the study runs each case as a child process and collects after every
///          case; `--emit slurm` writes an `sbatch --array` job script for the same `--case K`
///          commands. Format and metric definitions: docs/study.md.
#include "Command.h"
#include "LiquidScene.h"
#include "Simulation.h"
#include "StudyMetrics.h"
#include "StudyPlot.h"

#include <ghostfx/sph/Exceptions.h>
#include <ghostfx/sph/Parallel.h>
#include <ghostfx/vdbio/AtomicFile.h>
#include <ghostfx/vdbio/JsonReader.h>
#include <ghostfx/vdbio/Scene.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <map>
#include <memory>
#include <optional>
#include <set>
#include <sstream>
#include <thread>

#include <fcntl.h>
#include <signal.h>
#include <spawn.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

extern char** environ;

namespace ghostfx {
namespace cmd {

namespace fs = std::filesystem;
using Json = nlohmann::json;
using Clock = std::chrono::steady_clock;

namespace {

const char* const PRECISION_KEY = "precision";
const char* const BUILD_PRECISION = sizeof(sph::Real) == sizeof(double) ? "double" : "float";

// The study file ----------------------------------------------------------------------------------

struct StudyCase
{
    std::string label;                  ///< "settings.spacing=0.02 settings.cfl=0.4"
    std::map<std::string, Json> values; ///< swept key -> value
    std::vector<std::string> overrides; ///< "-D" assignments for the scene
    std::string precision = BUILD_PRECISION;
    bool reference = false;
};

struct StudySpec
{
    std::string file, scene;
    std::vector<std::string> axes; ///< swept keys, in column order
    std::vector<StudyCase> cases;  ///< the reference (if any) first
    std::vector<MetricSpec> metrics;
    std::map<std::string, std::string> executables; ///< precision -> program
    double maxSecondsPerRun = 0;
    std::string directory, table, plot, plotTitle;
    std::string plotCost = "wall_per_sim_second", plotError, plotSeries;
    std::string convergenceKey, convergenceError;
    bool convergenceInverse = false; ///< the step size is 1 / key (substeps)
    std::optional<std::vector<std::string>>
        convergenceGroupBy; ///< keys that form groups (default: all others)
    bool hasReference() const { return !cases.empty() && cases.front().reference; }
};

std::string valueText(const Json& v) { return v.is_string() ? v.get<std::string>() : v.dump(); }

/// key=value pairs of a JSON object, in the file's key order (nlohmann sorts; fine for columns).
std::vector<std::pair<std::string, Json>> assignments(const vdbio::JsonObject& o,
                                                      const std::string& key)
{
    std::vector<std::pair<std::string, Json>> out;
    const Json* v = o.raw(key);
    if (!v || v->is_null()) return out;
    if (!v->is_object())
        o.failValue(key,
                    "expected an object of scene keys and values { \"settings.spacing\": 0.02 }");
    for (auto it = v->begin(); it != v->end(); ++it) out.emplace_back(it.key(), it.value());
    return out;
}

/// The "-D" assignments of `root.set`, kept by every case.
std::vector<std::string> fixedAssignments(const vdbio::JsonObject& root)
{
    std::vector<std::string> fixed;
    for (const auto& [key, value] : assignments(root, "set")) {
        if (key == PRECISION_KEY) root.fail("set", "precision is chosen per case in sweep or runs");
        fixed.push_back(key + "=" + value.dump());
    }
    return fixed;
}

/// Every combination of the values of `root.sweep`, its keys appended to `axes`.
std::vector<std::map<std::string, Json>> sweepCombinations(const vdbio::JsonObject& root,
                                                           std::vector<std::string>& axes)
{
    std::vector<std::map<std::string, Json>> combos(1);
    for (const auto& [key, values] : assignments(root, "sweep")) {
        if (!values.is_array() || values.empty()) {
            root.fail("sweep", msg("'", key, "' = ", values.dump(),
                                   ": expected a non-empty array of values"));
        }
        axes.push_back(key);
        std::vector<std::map<std::string, Json>> next;
        for (const auto& combo : combos) {
            for (const Json& v : values) {
                next.push_back(combo);
                next.back()[key] = v;
            }
        }
        combos = std::move(next);
    }
    return combos;
}

/// The entries of `root.runs` (of the document `doc`), their keys appended to `axes` when new;
/// one empty entry without runs.
std::vector<std::map<std::string, Json>> readRuns(const vdbio::JsonObject& root, const Json& doc,
                                                  std::vector<std::string>& axes)
{
    std::vector<std::map<std::string, Json>> runs;
    for (const vdbio::JsonObject& run : root.objects("runs")) {
        std::map<std::string, Json> values;
        const Json* raw = doc.contains("runs") ? &doc["runs"][runs.size()] : nullptr;
        for (auto it = raw->begin(); it != raw->end(); ++it) {
            values[it.key()] = it.value();
            if (std::find(axes.begin(), axes.end(), it.key()) == axes.end())
                axes.push_back(it.key());
        }
        (void)run;
        runs.push_back(std::move(values));
    }
    if (runs.empty()) runs.emplace_back();
    return runs;
}

/// The case of the swept `values` (the reference case with `reference`), after the `fixed`
/// assignments; a precision value picks the build instead of becoming an assignment.
StudyCase makeCase(const vdbio::JsonObject& root, const std::vector<std::string>& fixed,
                   const std::map<std::string, Json>& values, bool reference)
{
    StudyCase c;
    c.values = values;
    c.reference = reference;
    c.overrides = fixed;
    for (const auto& [key, value] : values) {
        c.label += (c.label.empty() ? "" : " ") + key + "=" + valueText(value);
        if (key == PRECISION_KEY) {
            if (value != "float" && value != "double") {
                root.fail(reference ? "reference" : "sweep",
                          msg("precision = ", value.dump(), ": expected \"float\" or \"double\""));
            }
            c.precision = value.get<std::string>();
        } else {
            c.overrides.push_back(key + "=" + value.dump());
        }
    }
    if (reference) c.label = "reference" + (c.label.empty() ? "" : " " + c.label);
    return c;
}

/// The cases into `s.cases`, the reference first: every combination of the sweep, times every
/// entry of "runs"; the swept keys into `s.axes`.
void readCases(const vdbio::JsonObject& root, const Json& doc, StudySpec& s)
{
    const std::vector<std::string> fixed = fixedAssignments(root);
    const std::vector<std::map<std::string, Json>> combos = sweepCombinations(root, s.axes);
    const std::vector<std::map<std::string, Json>> runs = readRuns(root, doc, s.axes);
    if (root.has("reference")) {
        std::map<std::string, Json> values;
        for (const auto& [key, value] : assignments(root, "reference")) values[key] = value;
        s.cases.push_back(makeCase(root, fixed, values, true));
    }
    for (const auto& combo : combos) {
        for (const auto& run : runs) {
            std::map<std::string, Json> values = combo;
            for (const auto& [key, value] : run) values[key] = value;
            s.cases.push_back(makeCase(root, fixed, values, false));
        }
    }
}

/// `root.metrics` of the study `path`: each "name" or { "metric": "name", options... }.
std::vector<MetricSpec> readMetrics(const vdbio::JsonObject& root, const std::string& path)
{
    const Json* metrics = root.raw("metrics");
    if (!metrics || !metrics->is_array() || metrics->empty()) {
        root.failValue("metrics", "expected a non-empty array of metric names (docs/study.md)");
    }
    std::vector<MetricSpec> specs;
    for (std::size_t k = 0; k < metrics->size(); ++k) {
        const Json& m = (*metrics)[k];
        MetricSpec spec;
        if (m.is_string()) {
            spec.name = m.get<std::string>();
        } else if (m.is_object() && m.contains("metric") && m["metric"].is_string()) {
            spec.name = m["metric"].get<std::string>();
            spec.options = m;
        } else {
            root.fail("metrics", msg("[", k, "] = ", m.dump(),
                                     ": expected a name or { \"metric\": name, ... }"));
        }
        makeMetric(spec, msg("study '", path, "': metrics[", k, "]")); // checks name and options
        specs.push_back(std::move(spec));
    }
    return specs;
}

/// `root.executables`: the program to run per precision.
std::map<std::string, std::string> readExecutables(const vdbio::JsonObject& root)
{
    std::map<std::string, std::string> executables;
    for (const auto& [precision, program] : assignments(root, "executables")) {
        if (precision != "float" && precision != "double") {
            root.fail("executables", msg("'", precision, "': expected \"float\" or \"double\""));
        }
        executables[precision] = valueText(program);
    }
    return executables;
}

/// The optional object `root.key`, or an empty one that answers every key with its default.
vdbio::JsonObject optionalSection(const vdbio::JsonObject& root, const char* key)
{
    return root.has(key) ? root.object(key) : vdbio::JsonObject();
}

/// `root.output` of the study `path`: folder, table and plot file names.
void readOutput(const vdbio::JsonObject& root, const std::string& path, StudySpec& s)
{
    const vdbio::JsonObject out = optionalSection(root, "output");
    s.directory = out.get<std::string>("directory", "out/study_" + fs::path(path).stem().string());
    s.table = out.get<std::string>("table", "study.csv");
    s.plot = out.get<std::string>("plot", "study.png");
    const std::string ext = fs::path(s.plot).extension().string();
    if (ext != ".png" && ext != ".pdf" && ext != ".svg")
        out.failValue("plot", "expected an image file name ending in .png, .pdf or .svg");
    out.finish();
}

/// Whether `key` is one of the swept keys `axes`.
bool isSwept(const std::vector<std::string>& axes, const std::string& key)
{
    return std::find(axes.begin(), axes.end(), key) != axes.end();
}

/// `root.plot` of the study `path`: the cost and error columns, the series and the title.
void readPlot(const vdbio::JsonObject& root, const std::string& path, StudySpec& s)
{
    const vdbio::JsonObject plot = optionalSection(root, "plot");
    s.plotCost = plot.choice("cost", s.plotCost,
                             {"wall_per_sim_second", "cpu_per_sim_second", "wall_s", "cpu_s",
                              "peak_rss_mb", "particles_max", "particle_memory_mb", "steps"});
    s.plotError = plot.get<std::string>(
        "error", primaryErrorColumn(s.metrics.front().name, s.hasReference()));
    s.plotSeries = plot.get<std::string>("series", "");
    s.plotTitle = plot.get<std::string>("title", fs::path(path).stem().string());
    plot.finish();
    if (!s.plotSeries.empty() && !isSwept(s.axes, s.plotSeries)) {
        root.fail("plot", msg("series = \"", s.plotSeries, "\": not a swept key (swept: ",
                              s.axes.empty() ? std::string("none") : s.axes.front(),
                              s.axes.size() > 1 ? ", ..." : "", ")"));
    }
}

/// `root.convergence`: the step-size key (the spacing when swept), the error column, whether
/// the step is 1 / key, and the keys that form groups.
void readConvergence(const vdbio::JsonObject& root, StudySpec& s)
{
    const vdbio::JsonObject conv = optionalSection(root, "convergence");
    const bool sweptSpacing = isSwept(s.axes, "settings.spacing");
    s.convergenceKey = conv.get<std::string>("key", sweptSpacing ? "settings.spacing" : "");
    s.convergenceError = conv.get<std::string>("error", s.plotError);
    s.convergenceInverse = conv.get<bool>("inverse", false);
    if (conv.has("group_by")) {
        s.convergenceGroupBy = conv.get<std::vector<std::string>>("group_by", {});
        for (const std::string& key : *s.convergenceGroupBy) {
            if (!isSwept(s.axes, key)) {
                conv.failValue("group_by", msg("'", key, "' is not a swept key"));
            }
        }
    }
    conv.finish();
    if (!s.convergenceKey.empty() && !isSwept(s.axes, s.convergenceKey)) {
        root.fail("convergence", msg("key = \"", s.convergenceKey, "\": not a swept key"));
    }
}

/// Every column the plot or the convergence names must be one the metrics produce.
void checkErrorColumns(const StudySpec& s)
{
    std::set<std::string> columns;
    for (const MetricSpec& m : s.metrics) {
        auto metric = makeMetric(m, "");
        for (const auto& [name, value] : metric->values()) columns.insert(name);
        if (s.hasReference() && (m.name == "surge_front" || m.name == "plume_rise")) {
            columns.insert(m.name + "_error");
            columns.insert(m.name + "_error_m");
        }
    }
    for (const std::string* column : {&s.plotError, &s.convergenceError}) {
        if (!columns.count(*column)) {
            std::string list;
            for (const std::string& c : columns) list += (list.empty() ? "" : ", ") + c;
            throw SceneError(msg("study '", s.file,
                                 "': ", column == &s.plotError ? "plot.error" : "convergence.error",
                                 " = \"", *column, "\": not a column of these metrics (", list,
                                 ")"));
        }
    }
}

StudySpec readStudy(const std::string& path)
{
    auto shared = std::make_shared<const Json>(vdbio::readJsonFile(path, "study"));
    const vdbio::JsonObject root(shared, shared.get(), "", path, "study");

    StudySpec s;
    s.file = path;
    const int version = root.require<int>("ghostfx_study");
    if (version != 1) root.failValue("ghostfx_study", "unsupported version: expected 1");
    const fs::path folder = fs::path(path).parent_path();
    s.scene = (folder / root.require<std::string>("scene")).lexically_normal().string();
    readCases(root, *shared, s);
    s.metrics = readMetrics(root, path);
    s.executables = readExecutables(root);
    s.maxSecondsPerRun = root.nonNegative("max_seconds_per_run", 0);
    readOutput(root, path, s);
    readPlot(root, path, s);
    readConvergence(root, s);
    root.finish();
    checkErrorColumns(s);
    return s;
}

// One case, in the child process ------------------------------------------------------------------

/// CPU time of this process, all threads, user + system (s). Unlike wall time it does not grow
/// when other work shares the machine (with one thread per run it is the run's cost on an idle
/// core); the metrics' sampling, single-threaded, is subtracted from both.
double cpuSeconds()
{
    struct rusage u
    {};
    ::getrusage(RUSAGE_SELF, &u);
    return double(u.ru_utime.tv_sec + u.ru_stime.tv_sec)
           + 1e-6 * double(u.ru_utime.tv_usec + u.ru_stime.tv_usec);
}

/// The metrics of `spec`, fresh for one run.
std::vector<std::unique_ptr<Metric>> makeMetrics(const StudySpec& spec)
{
    std::vector<std::unique_ptr<Metric>> metrics;
    for (std::size_t k = 0; k < spec.metrics.size(); ++k) {
        metrics.push_back(
            makeMetric(spec.metrics[k], msg("study '", spec.file, "': metrics[", k, "]")));
    }
    return metrics;
}

/// Show each metric the medium it watches in `sim` at frame `frame` (`first`: the initial
/// state, which starts it).
void sampleMetrics(const std::vector<std::unique_ptr<Metric>>& metrics, const Simulation& sim,
                   const vdbio::Scene& scene, int frame, bool first)
{
    const std::vector<OutputMedium> media = sim.media();
    for (const auto& metric : metrics) {
        auto it = std::find_if(media.begin(), media.end(),
                               [&](const OutputMedium& m) { return m.name == metric->medium(); });
        if (it == media.end()) {
            throw SceneError(msg("metric ", metric->name(), " watches the ", metric->medium(),
                                 ", and scene '", scene.file, "' has none"));
        }
        MetricSample s{&*it, sim.time(), frame, scene.lastFrame};
        if (first) metric->start(s);
        else metric->frame(s);
    }
}

/// What a case's frames cost, the metrics' own sampling left out.
struct FramesCost
{
    double wall = 0, cpu = 0;                    ///< s
    std::size_t particlesMax = 0, memoryMax = 0; ///< the most particles and bytes at a frame
};

/// Advance `sim` through every frame of `scene`, sampling `metrics` after each.
FramesCost runFrames(Simulation& sim, const vdbio::Scene& scene,
                     const std::vector<std::unique_ptr<Metric>>& metrics)
{
    FramesCost cost;
    cost.particlesMax = sim.particleCount();
    cost.memoryMax = sim.memoryBytes();
    const double cpuStart = cpuSeconds();
    const auto loopStart = Clock::now();
    double sampling = 0;
    for (int frame = 1; frame <= scene.lastFrame; ++frame) {
        const auto frameStart = Clock::now();
        sim.beforeFrame(frame);
        sim.advanceFrame();
        const auto sampleStart = Clock::now();
        sampleMetrics(metrics, sim, scene, frame, false);
        sampling += std::chrono::duration<double>(Clock::now() - sampleStart).count();
        cost.particlesMax = std::max(cost.particlesMax, sim.particleCount());
        cost.memoryMax = std::max(cost.memoryMax, sim.memoryBytes());
        std::fprintf(stderr, "frame %d/%d: t = %.4f s, %llu steps, %s, %.2f s\n", frame,
                     scene.lastFrame, sim.time(), static_cast<unsigned long long>(sim.stepCount()),
                     sim.counts().c_str(),
                     std::chrono::duration<double>(Clock::now() - frameStart).count());
    }
    // The metrics' own sampling is not the solver's cost.
    cost.wall = std::chrono::duration<double>(Clock::now() - loopStart).count() - sampling;
    cost.cpu = cpuSeconds() - cpuStart - sampling;
    return cost;
}

/// The "cost" of a result document: `setup` (s) and `frames`, per simulated second and per
/// step, and the particles of each medium of `sim` at the end.
Json costJson(const Simulation& sim, double setup, const FramesCost& frames)
{
    Json cost;
    const double wall = frames.wall, cpu = frames.cpu;
    cost["setup_s"] = setup;
    cost["wall_s"] = wall;
    cost["sim_s"] = sim.time();
    cost["wall_per_sim_second"] = sim.time() > 0 ? wall / sim.time() : NAN;
    cost["cpu_s"] = cpu;
    cost["cpu_per_sim_second"] = sim.time() > 0 ? cpu / sim.time() : NAN;
    cost["steps"] = double(sim.stepCount());
    cost["steps_per_second"] = wall > 0 ? double(sim.stepCount()) / wall : NAN;
    cost["particles_max"] = double(frames.particlesMax);
    cost["particle_memory_mb"] = double(frames.memoryMax) / 1048576.0;
    for (const OutputMedium& m : sim.media()) {
        std::size_t n = 0;
        for (sph::ParticleKind k : m.particles->kinds())
            n += std::count(m.kinds.begin(), m.kinds.end(), k) > 0;
        cost["count_" + m.name] = double(n);
    }
    return cost;
}

/// Run case `index` and return its result document. Throws like `ghostfx run`.
Json runCase(const StudySpec& spec, std::size_t index)
{
    const StudyCase& c = spec.cases.at(index);
    if (c.precision != BUILD_PRECISION) {
        throw ValueError(msg("case '", c.label, "' asks for ", c.precision, ", this ghostfx is ",
                             BUILD_PRECISION));
    }
    const auto t0 = Clock::now();
    const vdbio::Scene scene = vdbio::readScene(spec.scene, c.overrides);
    std::unique_ptr<Simulation> sim = makeSimulation(scene);
    checkSolidSequences(scene, 1, scene.lastFrame);
    const std::vector<std::unique_ptr<Metric>> metrics = makeMetrics(spec);
    sampleMetrics(metrics, *sim, scene, 0, true);
    const double setup = std::chrono::duration<double>(Clock::now() - t0).count();
    const FramesCost frames = runFrames(*sim, scene, metrics);

    Json result;
    result["status"] = "ok";
    result["cost"] = costJson(*sim, setup, frames);
    result["counts"] = sim->counts();
    for (const auto& metric : metrics) {
        for (const auto& [name, value] : metric->values()) result["values"][name] = value;
        const std::vector<double> trace = metric->trace();
        if (!trace.empty()) result["traces"][metric->name()] = trace;
    }
    return result;
}

// The parent: spawn, wait, tabulate ---------------------------------------------------------------

struct CaseOutcome
{
    std::string status = "missing"; ///< ok, failed, unstable, timeout, missing
    std::string note;
    std::map<std::string, double> numbers;
    std::map<std::string, std::vector<double>> traces;
};

struct StudyOptions
{
    std::string study;
    std::string out;
    int threads = 0;
    bool quiet = false;
    int caseIndex = -1;
    bool list = false;
    bool collect = false;
    std::string emit;
    bool replot = false;
    std::string sampleCache; ///< absolute once runStudy has started (LiquidScene.h)
};

std::string outputFolder(const StudyOptions& o, const StudySpec& spec)
{
    return o.out.empty() ? spec.directory : o.out;
}

/// The row file of case k: runs/case_07.json (two digits at least, so they list in order).
std::string rowPath(const std::string& folder, std::size_t k)
{
    return (fs::path(folder) / "runs" / msg("case_", k < 10 ? "0" : "", k, ".json")).string();
}

std::string logPath(const std::string& folder, std::size_t k)
{
    return fs::path(rowPath(folder, k)).replace_extension(".log").string();
}

/// Peak resident memory (MB) of this process (RUSAGE_SELF) or of its waited-for children.
double peakRssMb(int who)
{
    struct rusage u
    {};
    ::getrusage(who, &u);
    return double(u.ru_maxrss) / 1024.0; // Linux: kilobytes
}

/// Write a case's result as its row file, tagged with the case it answers: --collect refuses a
/// row whose label is not the study's case of that number (the study changed since it ran).
void writeRow(const StudySpec& spec, std::size_t k, Json result, const std::string& path)
{
    result["case"] = k;
    result["label"] = spec.cases[k].label;
    vdbio::writeTextFile(path, result.dump(1), "study row");
}

/// Case k's outcome from its row file; status "missing" when there is none (the job has not
/// run, or was killed before it could write).
CaseOutcome readRow(const StudySpec& spec, std::size_t k, const std::string& path)
{
    CaseOutcome o;
    const std::optional<std::string> text = vdbio::readTextFile(path);
    if (!text) {
        o.status = "missing";
        o.note = msg("no row file ", fs::path(path).filename().string(),
                     ": the case has not run, or its job ended before writing it");
        return o;
    }
    Json result;
    try {
        result = Json::parse(*text);
    } catch (const Json::exception& e) {
        throw SceneError(msg("study row '", path, "': not valid JSON (", e.what(), ")"));
    }
    if (!result.is_object() || !result.contains("label") || !result["label"].is_string()
        || !result.contains("status") || !result["status"].is_string()) {
        throw SceneError(msg("study row '", path,
                             "': expected an object with \"label\" and \"status\" (a row file "
                             "written by ghostfx study --case)"));
    }
    if (result["label"] != spec.cases[k].label) {
        throw SceneError(
            msg("study row '", path, "': holds case '", result["label"].get<std::string>(),
                "', but case ", k, " of study '", spec.file, "' is '", spec.cases[k].label,
                "': the study changed since the case ran (run it again: --case ", k, ")"));
    }
    o.status = result["status"].get<std::string>();
    o.note = result.value("error", result.value("counts", ""));
    for (const char* group : {"cost", "values"}) {
        if (!result.contains(group)) continue;
        for (auto it = result[group].begin(); it != result[group].end(); ++it) {
            o.numbers[it.key()] = it.value().is_number() ? it.value().get<double>() : NAN;
        }
    }
    if (result.contains("traces")) {
        for (auto it = result["traces"].begin(); it != result["traces"].end(); ++it) {
            std::vector<double> t;
            for (const Json& v : it.value()) t.push_back(v.is_number() ? v.get<double>() : NAN);
            o.traces[it.key()] = std::move(t);
        }
    }
    return o;
}

/// This program, for the child runs. /proc/self/exe names the running image itself, so a study
/// keeps working while its program file is rebuilt or replaced under it.
std::string selfExecutable()
{
    if (::access("/proc/self/exe", X_OK) != 0) {
        throw IoError(msg("ghostfx study: cannot run its own program again (/proc/self/exe: ",
                          std::strerror(errno), ")"));
    }
    return "/proc/self/exe";
}

/// Run case `index` as a child process (`ghostfx study FILE --case K --out FOLDER`) and read
/// its row file. A child that is killed (max_seconds_per_run, a signal) or dies without writing
/// its row gets a row written here, so that --collect sees what this run saw.
CaseOutcome runChild(const StudySpec& spec, std::size_t index, const std::string& program,
                     int threads, const std::string& folder)
{
    const std::string row = rowPath(folder, index), log = logPath(folder, index);
    std::vector<std::string> args = {program,
                                     "study",
                                     spec.file,
                                     "--case",
                                     std::to_string(index),
                                     "--out",
                                     folder,
                                     "--threads",
                                     std::to_string(threads)};
    std::vector<char*> argv;
    for (std::string& a : args) argv.push_back(a.data());
    argv.push_back(nullptr);

    posix_spawn_file_actions_t actions;
    posix_spawn_file_actions_init(&actions);
    posix_spawn_file_actions_addopen(&actions, STDOUT_FILENO, log.c_str(),
                                     O_WRONLY | O_CREAT | O_TRUNC, 0644);
    posix_spawn_file_actions_adddup2(&actions, STDOUT_FILENO, STDERR_FILENO);
    std::error_code ec;
    fs::remove(row, ec);
    pid_t pid = 0;
    const int err = posix_spawn(&pid, program.c_str(), &actions, nullptr, argv.data(), environ);
    posix_spawn_file_actions_destroy(&actions);
    if (err != 0)
        throw IoError(msg("ghostfx study: cannot start '", program, "': ", std::strerror(err)));

    const auto start = Clock::now();
    int status = 0;
    struct rusage usage
    {};
    bool timedOut = false;
    for (;;) {
        const pid_t done = ::wait4(pid, &status, WNOHANG, &usage);
        if (done == pid) break;
        if (done < 0 && errno != EINTR)
            throw IoError(
                msg("ghostfx study: waiting for case ", index, ": ", std::strerror(errno)));
        if (spec.maxSecondsPerRun > 0 && !timedOut
            && std::chrono::duration<double>(Clock::now() - start).count()
                   > spec.maxSecondsPerRun) {
            ::kill(pid, SIGKILL);
            timedOut = true;
        }
        std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }

    if (timedOut || !fs::exists(row)) {
        Json result;
        result["status"] = timedOut ? "timeout" : "failed";
        result["error"] =
            timedOut ? msg("stopped after max_seconds_per_run = ", spec.maxSecondsPerRun, " s")
            : WIFSIGNALED(status) ? msg("killed by signal ", WTERMSIG(status))
                                  : vdbio::lastLineOf(log);
        result["cost"]["peak_rss_mb"] = double(usage.ru_maxrss) / 1024.0; // Linux: kilobytes
        writeRow(spec, index, result, row);
    }
    return readRow(spec, index, row);
}

/// Trace errors against the reference run (which is case 0).
void compareWithReference(const StudySpec& spec, std::vector<CaseOutcome>& outcomes)
{
    if (!spec.hasReference() || outcomes.front().status != "ok") return;
    for (CaseOutcome& o : outcomes) {
        for (const auto& [name, trace] : o.traces) {
            auto ref = outcomes.front().traces.find(name);
            if (ref == outcomes.front().traces.end()) continue;
            const TraceError e = compareTraces(trace, ref->second);
            o.numbers[name + "_error"] = e.relative;
            o.numbers[name + "_error_m"] = e.rms;
        }
    }
}

const std::vector<std::string>& costColumns()
{
    static const std::vector<std::string> c = {"setup_s",      "wall_s",
                                               "sim_s",        "wall_per_sim_second",
                                               "cpu_s",        "cpu_per_sim_second",
                                               "steps",        "steps_per_second",
                                               "peak_rss_mb",  "particle_memory_mb",
                                               "particles_max"};
    return c;
}

std::string number(double v)
{
    if (!std::isfinite(v)) return std::isnan(v) ? "" : (v > 0 ? "inf" : "-inf");
    char buffer[32];
    std::snprintf(buffer, sizeof(buffer), "%.6g", v);
    return buffer;
}

std::string csvField(const std::string& s)
{
    if (s.find_first_of(",\"\n") == std::string::npos) return s;
    std::string q = "\"";
    for (char ch : s) q += ch == '"' ? std::string("\"\"") : std::string(1, ch);
    return q + "\"";
}

double numberOr(const CaseOutcome& o, const std::string& key)
{
    auto it = o.numbers.find(key);
    return it == o.numbers.end() ? NAN : it->second;
}

void writeTable(const StudySpec& spec, const std::vector<CaseOutcome>& outcomes,
                const std::string& path)
{
    std::vector<std::string> columns = costColumns();
    std::set<std::string> seen(columns.begin(), columns.end());
    for (const CaseOutcome& o : outcomes) {
        for (const auto& [name, value] : o.numbers) {
            if (seen.insert(name).second) columns.push_back(name);
        }
    }
    std::string text = "case,role,status";
    // The precision is a column of its own unless it is swept (then it is one of the axes).
    const bool precisionColumn =
        std::find(spec.axes.begin(), spec.axes.end(), PRECISION_KEY) == spec.axes.end();
    for (const std::string& a : spec.axes) text += "," + csvField(a);
    if (precisionColumn) text += ",precision";
    for (const std::string& c : columns) text += "," + c;
    text += ",note\n";
    for (std::size_t k = 0; k < outcomes.size(); ++k) {
        const StudyCase& c = spec.cases[k];
        const CaseOutcome& o = outcomes[k];
        text += std::to_string(k) + "," + (c.reference ? "reference" : "sweep") + "," + o.status;
        for (const std::string& a : spec.axes) {
            auto it = c.values.find(a);
            text += "," + csvField(it == c.values.end() ? "" : valueText(it->second));
        }
        if (precisionColumn) text += "," + c.precision;
        for (const std::string& col : columns) {
            auto it = o.numbers.find(col);
            text += "," + (it == o.numbers.end() ? std::string() : number(it->second));
        }
        text += "," + csvField(o.note) + "\n";
    }
    vdbio::writeTextFile(path, text, "study table");
}

/// The same table in Markdown, with the columns a reader compares (cost, then every metric),
/// numbers to 3 significant digits: for documentation and review.
void writeMarkdown(const StudySpec& spec, const std::vector<CaseOutcome>& outcomes,
                   const std::string& path)
{
    const std::vector<std::string> cost = {"cpu_per_sim_second", "wall_per_sim_second", "steps",
                                           "peak_rss_mb", "particles_max"};
    std::vector<std::string> metrics;
    std::set<std::string> skip(costColumns().begin(), costColumns().end());
    for (const CaseOutcome& o : outcomes) {
        for (const auto& [name, value] : o.numbers) {
            if (!skip.count(name) && name.rfind("count_", 0) != 0
                && std::find(metrics.begin(), metrics.end(), name) == metrics.end()) {
                metrics.push_back(name);
            }
        }
    }
    auto cell = [](double v) {
        if (!std::isfinite(v)) return std::string(std::isnan(v) ? "" : "inf");
        char buffer[32];
        std::snprintf(buffer, sizeof(buffer), std::abs(v) >= 1000 ? "%.0f" : "%.3g", v);
        return std::string(buffer);
    };
    std::string text = "| run |";
    std::string rule = "|---|";
    for (const std::string& a : spec.axes) {
        text += " " + a + " |";
        rule += "---|";
    }
    text += " status |";
    rule += "---|";
    for (const std::string& c : cost) {
        text += " " + c + " |";
        rule += "---:|";
    }
    for (const std::string& m : metrics) {
        text += " " + m + " |";
        rule += "---:|";
    }
    text += "\n" + rule + "\n";
    for (std::size_t k = 0; k < outcomes.size(); ++k) {
        const StudyCase& c = spec.cases[k];
        text += "| " + std::to_string(k) + (c.reference ? " (ref)" : "") + " |";
        for (const std::string& a : spec.axes) {
            auto it = c.values.find(a);
            text += " " + (it == c.values.end() ? std::string() : valueText(it->second)) + " |";
        }
        text += " " + outcomes[k].status + " |";
        for (const std::string& col : cost) text += " " + cell(numberOr(outcomes[k], col)) + " |";
        for (const std::string& col : metrics)
            text += " " + cell(numberOr(outcomes[k], col)) + " |";
        text += "\n";
    }
    vdbio::writeTextFile(path, text, "study table");
}

/// Observed order of convergence between successive values of the convergence key (halving the
/// spacing, say), among cases that agree on every other swept key: p = ln(e1 / e2) / ln(h1 / h2).
std::string convergenceReport(const StudySpec& spec, const std::vector<CaseOutcome>& outcomes,
                              const std::string& path)
{
    if (spec.convergenceKey.empty()) return {};
    std::map<std::string, std::vector<std::pair<double, double>>> groups; // others -> (h, error)
    for (std::size_t k = 0; k < outcomes.size(); ++k) {
        const StudyCase& c = spec.cases[k];
        if (c.reference || outcomes[k].status != "ok") continue;
        auto key = c.values.find(spec.convergenceKey);
        if (key == c.values.end() || !key->second.is_number()) continue;
        std::string others;
        for (const auto& [name, value] : c.values) {
            const bool grouping = spec.convergenceGroupBy
                                      ? std::count(spec.convergenceGroupBy->begin(),
                                                   spec.convergenceGroupBy->end(), name)
                                            > 0
                                      : name != spec.convergenceKey;
            if (grouping) others += (others.empty() ? "" : " ") + name + "=" + valueText(value);
        }
        const double value = key->second.get<double>();
        groups[others].push_back({spec.convergenceInverse ? 1.0 / value : value,
                                  numberOr(outcomes[k], spec.convergenceError)});
    }
    const std::string h =
        spec.convergenceInverse ? "1/" + spec.convergenceKey : spec.convergenceKey;
    std::string csv = "group," + h + "_coarse," + h + "_fine," + spec.convergenceError + "_coarse,"
                      + spec.convergenceError + "_fine,observed_order\n";
    std::string report;
    for (auto& [group, points] : groups) {
        std::sort(points.begin(), points.end(), [](auto& a, auto& b) { return a.first > b.first; });
        for (std::size_t k = 0; k + 1 < points.size(); ++k) {
            const auto [h1, e1] = points[k];
            const auto [h2, e2] = points[k + 1];
            const double order =
                (e1 > 0 && e2 > 0 && h1 != h2) ? std::log(e1 / e2) / std::log(h1 / h2) : NAN;
            csv += csvField(group) + "," + number(h1) + "," + number(h2) + "," + number(e1) + ","
                   + number(e2) + "," + number(order) + "\n";
            report += msg("  ", group.empty() ? "" : group + ": ", h, " ", number(h1), " -> ",
                          number(h2), ": ", spec.convergenceError, " ", number(e1), " -> ",
                          number(e2), ", observed order ", number(order), "\n");
        }
    }
    vdbio::writeTextFile(path, csv, "convergence table");
    return report;
}

/// The plotted runs (ok, with a positive cost and error; not the reference); the indices of the
/// others go to `skipped`.
std::vector<PlotPoint> plotPoints(const StudySpec& spec, const std::vector<CaseOutcome>& outcomes,
                                  std::string& skipped)
{
    std::vector<PlotPoint> points;
    for (std::size_t k = 0; k < outcomes.size(); ++k) {
        const StudyCase& c = spec.cases[k];
        if (c.reference) continue;
        const double x = numberOr(outcomes[k], spec.plotCost),
                     y = numberOr(outcomes[k], spec.plotError);
        if (outcomes[k].status != "ok" || !(x > 0) || !(y > 0)) {
            skipped += msg(skipped.empty() ? "" : ", ", k);
            continue;
        }
        PlotPoint p;
        p.x = x;
        p.y = y;
        auto series = c.values.find(spec.plotSeries);
        // The key's last part names the series ("method=ghost"): legends have little room.
        const std::string key = spec.plotSeries.substr(spec.plotSeries.find_last_of('.') + 1);
        p.series = series == c.values.end() ? "runs" : key + "=" + valueText(series->second);
        // The other swept keys name the point, by their last part: "damping=7 spacing=0.025".
        for (const auto& [name, value] : c.values) {
            if (name == spec.plotSeries) continue;
            p.label += (p.label.empty() ? "" : " ") + name.substr(name.find_last_of('.') + 1) + "="
                       + valueText(value);
        }
        points.push_back(p);
    }
    return points;
}

/// Read a study table back (for --replot): numbers by column, status and note, row by row.
std::vector<CaseOutcome> readTable(const StudySpec& spec, const std::string& path)
{
    const std::optional<std::string> text = vdbio::readTextFile(path);
    if (!text)
        throw IoError(msg("study table '", path, "': cannot open the file (run the study first)"));
    std::istringstream in(*text);
    auto split = [](const std::string& line) {
        std::vector<std::string> fields(1);
        bool quoted = false;
        for (std::size_t k = 0; k < line.size(); ++k) {
            const char ch = line[k];
            if (ch == '"') {
                if (quoted && k + 1 < line.size() && line[k + 1] == '"') fields.back() += line[++k];
                else quoted = !quoted;
            } else if (ch == ',' && !quoted) {
                fields.emplace_back();
            } else {
                fields.back() += ch;
            }
        }
        return fields;
    };
    std::string line;
    std::getline(in, line);
    const std::vector<std::string> header = split(line);
    // case, role, status, the axes, the precision (unless swept), then numbers (writeTable).
    const bool precisionSwept =
        std::find(spec.axes.begin(), spec.axes.end(), PRECISION_KEY) != spec.axes.end();
    const std::size_t firstNumber = 3 + spec.axes.size() + (precisionSwept ? 0 : 1);
    std::vector<CaseOutcome> outcomes(spec.cases.size());
    std::size_t row = 0;
    while (std::getline(in, line)) {
        const std::vector<std::string> f = split(line);
        if (row >= outcomes.size() || f.size() != header.size()) {
            throw SceneError(msg("study table '", path, "': row ", row + 1, " does not fit study '",
                                 spec.file, "' (", spec.cases.size(), " cases, ", header.size(),
                                 " columns)"));
        }
        CaseOutcome& o = outcomes[row++];
        for (std::size_t k = 0; k < header.size(); ++k) {
            if (header[k] == "status") o.status = f[k];
            else if (header[k] == "note") o.note = f[k];
            else if (std::find(costColumns().begin(), costColumns().end(), header[k])
                         != costColumns().end()
                     || header[k].rfind("count_", 0) == 0 || k >= firstNumber) {
                o.numbers[header[k]] = f[k].empty() ? NAN : std::strtod(f[k].c_str(), nullptr);
            }
        }
    }
    return outcomes;
}

int runStudyCase(const StudyOptions& o, const StudySpec& spec)
{
    if (o.caseIndex < 0 || std::size_t(o.caseIndex) >= spec.cases.size()) {
        throw ValueError(
            msg("--case ", o.caseIndex, ": the study has cases 0-", spec.cases.size() - 1));
    }
    const std::string folder = outputFolder(o, spec);
    vdbio::ensureWritableDirectory((fs::path(folder) / "runs").string());
    const std::string path = rowPath(folder, std::size_t(o.caseIndex));
    parallel::ThreadLimit threadLimit(o.threads);
    Json result;
    int code = 0;
    try {
        result = runCase(spec, std::size_t(o.caseIndex));
    } catch (const NumericalError& e) {
        result = {{"status", "unstable"}, {"error", e.what()}};
        code = 1;
    } catch (const Error& e) {
        result = {{"status", "failed"}, {"error", e.what()}};
        code = 1;
    }
    result["cost"]["peak_rss_mb"] = peakRssMb(RUSAGE_SELF);
    writeRow(spec, std::size_t(o.caseIndex), result, path);
    if (code != 0)
        std::fprintf(stderr, "ghostfx study: case %d %s: %s\n", o.caseIndex,
                     result["status"].get<std::string>().c_str(),
                     result["error"].get<std::string>().c_str());
    return code;
}

/// The convergence table and the plot, from the outcomes of every case.
int finishStudy(const StudyOptions& o, const StudySpec& spec,
                const std::vector<CaseOutcome>& outcomes, const std::string& folder)
{
    auto say = [&](const std::string& line) {
        if (!o.quiet) std::fprintf(stderr, "%s\n", line.c_str());
    };
    const std::string order =
        convergenceReport(spec, outcomes, (fs::path(folder) / "convergence.csv").string());
    if (!order.empty()) say("convergence (convergence.csv):\n" + order.substr(0, order.size() - 1));
    writeMarkdown(spec, outcomes,
                  (fs::path(fs::path(folder) / spec.table).replace_extension(".md")).string());
    // The plotted points (with their Pareto front) as a table, drawn by the matplotlib script.
    std::string skipped;
    const std::vector<PlotPoint> points = plotPoints(spec, outcomes, skipped);
    const std::string plot = (fs::path(folder) / spec.plot).string();
    const std::string pointsFile = (fs::path(folder) / "plot.csv").string();
    writePlotPoints(pointsFile, spec.plotCost, spec.plotError, points);
    const std::string notPlotted =
        skipped.empty()
            ? ""
            : " (not plotted, failed or without a positive value: cases " + skipped + ")";
    say(msg("table: ", (fs::path(folder) / spec.table).string(), "; plot points: ", pointsFile,
            notPlotted));
    if (points.empty()) {
        say("plot: nothing to draw (no run finished with a positive cost and error)");
        return 0;
    }
    const std::string why = drawPlot(pointsFile, plot, spec.plotTitle);
    // The table is the study's result; a plot that cannot be drawn (no matplotlib on this
    // machine) is a warning with the command that draws it elsewhere, not a failed study.
    if (why.empty()) say("plot: " + plot);
    else {
        std::fprintf(stderr, "ghostfx study: warning: plot not drawn: %s; to draw it: %s\n",
                     why.c_str(), plotCommand(pointsFile, plot, spec.plotTitle).c_str());
    }
    return 0;
}

/// Check every case before anything runs: a program for its precision, its scene and settings.
void checkCases(const StudySpec& spec)
{
    // Cases of the other precision run on the program named for it (checked here only: a child
    // of the other build sees this build's cases as "other").
    for (const StudyCase& c : spec.cases) {
        if (c.precision != BUILD_PRECISION && !spec.executables.count(c.precision)) {
            throw SceneError(msg("study '", spec.file, "': executables: case '", c.label,
                                 "' needs a ", c.precision, " build: this ghostfx is ",
                                 BUILD_PRECISION, "; name one with \"executables\": { \"",
                                 c.precision, "\": \"build-", c.precision, "/cmd/ghostfx\" }"));
        }
    }
    for (const StudyCase& c : spec.cases) {
        try {
            const vdbio::Scene scene = vdbio::readScene(spec.scene, c.overrides);
            if (c.precision == BUILD_PRECISION) checkSimulationSettings(scene);
        } catch (const Error& e) {
            throw SceneError(msg("study '", spec.file, "': case '", c.label, "': ", e.what()));
        }
    }
}

/// The program that runs case c: this one, or the study's executable for c's precision.
std::string programFor(const StudySpec& spec, const StudyCase& c, const std::string& self)
{
    return c.precision == BUILD_PRECISION ? self : spec.executables.at(c.precision);
}

/// A word for the shell, in single quotes.
std::string shellQuoted(const std::string& s)
{
    std::string q = "'";
    for (char ch : s) q += ch == '\'' ? std::string("'\\''") : std::string(1, ch);
    return q + "'";
}

/// The command a farm runs for case k: absolute paths, since a farm job starts elsewhere.
std::string caseCommand(const StudySpec& spec, std::size_t k, const std::string& program,
                        const std::string& folder, const std::string& threads,
                        const std::string& sampleCache)
{
    // A relative program (an "executables" entry such as build-double/cmd/ghostfx) is taken
    // from where the study was listed; a bare name is left to the farm node's PATH.
    const bool path = program.find('/') != std::string::npos;
    return msg(shellQuoted(path ? fs::absolute(program).lexically_normal().string() : program),
               " study ", shellQuoted(fs::absolute(spec.file).string()), " --case ", k, " --out ",
               shellQuoted(fs::absolute(folder).string()), " --threads ", threads,
               sampleCache.empty() ? std::string() : " --sample-cache " + shellQuoted(sampleCache));
}

/// This program's own file (not /proc/self/exe: a farm node runs the command elsewhere).
std::string selfPath()
{
    std::error_code ec;
    const fs::path p = fs::read_symlink("/proc/self/exe", ec);
    if (ec) throw IoError(msg("ghostfx study: cannot find its own program file: ", ec.message()));
    return p.string();
}

/// Read every row file, compare with the reference, write the table: the collection step.
std::vector<CaseOutcome> collectRows(const StudySpec& spec, const std::string& folder)
{
    std::vector<CaseOutcome> outcomes;
    for (std::size_t k = 0; k < spec.cases.size(); ++k)
        outcomes.push_back(readRow(spec, k, rowPath(folder, k)));
    compareWithReference(spec, outcomes);
    writeTable(spec, outcomes, (fs::path(folder) / spec.table).string());
    return outcomes;
}

int listCases(const StudyOptions& o, const StudySpec& spec)
{
    checkCases(spec);
    const std::string folder = outputFolder(o, spec), self = selfPath();
    const std::string collect =
        msg("ghostfx study ", spec.file, " --collect", o.out.empty() ? "" : " --out " + o.out);
    std::printf("# case\tlabel\tcommand (study '%s': %zu cases; then: %s)\n", spec.file.c_str(),
                spec.cases.size(), collect.c_str());
    for (std::size_t k = 0; k < spec.cases.size(); ++k) {
        const StudyCase& c = spec.cases[k];
        std::printf("%zu\t%s\t%s\n", k, c.label.empty() ? "base scene" : c.label.c_str(),
                    caseCommand(spec, k, programFor(spec, c, self), folder,
                                std::to_string(o.threads), o.sampleCache)
                        .c_str());
    }
    return 0;
}

/// The Slurm array job of the cases of `spec`: task k runs case k with `cpus` threads (the
/// task's CPUs) by `self` or the case's own program, its output under `folder`.
std::string casesSbatch(const StudyOptions& o, const StudySpec& spec, const std::string& folder,
                        const std::string& self, const std::string& name, int cpus)
{
    const std::string slurm = (fs::path(folder) / "slurm").string();
    std::string cases = msg(
        "#!/bin/bash\n"
        "# ghostfx study '",
        spec.file, "': one array task per case (", "ghostfx study --emit slurm; docs/study.md).\n",
        "#SBATCH --job-name=", name, "\n#SBATCH --array=0-", spec.cases.size() - 1,
        "\n#SBATCH --cpus-per-task=", cpus, "\n#SBATCH --output=", slurm, "/case_%a.slurm.out\n");
    if (spec.maxSecondsPerRun > 0) {
        // max_seconds_per_run, rounded up to whole minutes, as the task's time limit.
        cases += msg("#SBATCH --time=", int(std::ceil(spec.maxSecondsPerRun / 60.0)), "\n");
    }
    cases += "set -u\n"
             "threads=${SLURM_CPUS_PER_TASK:-"
             + std::to_string(cpus)
             + "}\n"
               "case \"${SLURM_ARRAY_TASK_ID:?run this script with sbatch (an array job)}\" in\n";
    for (std::size_t k = 0; k < spec.cases.size(); ++k) {
        cases += msg("  ", k, ") exec ",
                     caseCommand(spec, k, programFor(spec, spec.cases[k], self), folder,
                                 "\"$threads\"", o.sampleCache),
                     " > ", shellQuoted(logPath(folder, k)), " 2>&1 ;;\n");
    }
    cases += "  *) echo \"no case $SLURM_ARRAY_TASK_ID in this study\" >&2; exit 1 ;;\nesac\n";
    return cases;
}

/// The Slurm job that collects the study `spec` in `folder` by `self`.
std::string collectSbatch(const StudySpec& spec, const std::string& folder, const std::string& self,
                          const std::string& name)
{
    const std::string slurm = (fs::path(folder) / "slurm").string();
    return msg("#!/bin/bash\n# ghostfx study '", spec.file,
               "': the table, convergence and plot from every case's row file.\n"
               "#SBATCH --job-name=",
               name, "-collect\n#SBATCH --cpus-per-task=1\n#SBATCH --output=", slurm,
               "/collect.slurm.out\nexec ", shellQuoted(self), " study ",
               shellQuoted(fs::absolute(spec.file).string()), " --collect --out ",
               shellQuoted(folder), "\n");
}

/// The script that submits the cases of `spec` (scripts in `slurm`) and the collection after.
std::string submitScript(const StudySpec& spec, const std::string& slurm)
{
    return msg("#!/bin/sh\n"
               "# Submit the study's cases as an array job and the collection after them.\n"
               "# Options go to both sbatch calls: ./submit.sh --partition=sim --mem=8G\n"
               "set -e\n"
               "cd ",
               shellQuoted(slurm),
               "\n"
               "array=$(sbatch --parsable \"$@\" cases.sbatch)\n"
               "array=${array%%;*}\n"
               "collect=$(sbatch --parsable --dependency=afterany:\"$array\" \"$@\" "
               "collect.sbatch)\n"
               "echo \"cases: job $array (",
               spec.cases.size(), " tasks); collect: job ${collect%%;*}\"\n");
}

/// `--emit slurm`: an array job of the cases, a collect job, and a script that submits both
/// (the collect job waits for every case to end, whether it succeeded or not).
int emitSlurm(const StudyOptions& o, const StudySpec& spec)
{
    checkCases(spec);
    const std::string folder = fs::absolute(outputFolder(o, spec)).lexically_normal().string();
    const std::string slurm = (fs::path(folder) / "slurm").string();
    vdbio::ensureWritableDirectory((fs::path(folder) / "runs").string());
    vdbio::ensureWritableDirectory(slurm);
    const std::string self = selfPath(), name = "ghostfx-" + fs::path(spec.file).stem().string();
    const int cpus = std::max(1, o.threads);
    auto write = [](const std::string& path, const std::string& text) {
        vdbio::writeTextFile(path, text, "job script");
        fs::permissions(path, fs::perms::owner_exec | fs::perms::group_exec, fs::perm_options::add);
    };
    write((fs::path(slurm) / "cases.sbatch").string(),
          casesSbatch(o, spec, folder, self, name, cpus));
    write((fs::path(slurm) / "collect.sbatch").string(), collectSbatch(spec, folder, self, name));
    write((fs::path(slurm) / "submit.sh").string(), submitScript(spec, slurm));
    if (!o.quiet) {
        std::fprintf(stderr,
                     "ghostfx study '%s': %zu cases; Slurm scripts in '%s' (cases.sbatch, "
                     "collect.sbatch); submit with: %s/submit.sh\n",
                     spec.file.c_str(), spec.cases.size(), slurm.c_str(), slurm.c_str());
    }
    return 0;
}

int collectStudy(const StudyOptions& o, const StudySpec& spec)
{
    const std::string folder = outputFolder(o, spec);
    if (!fs::is_directory(fs::path(folder) / "runs")) {
        throw IoError(msg("study '", spec.file, "': no folder '",
                          (fs::path(folder) / "runs").string(),
                          "' (run the cases first: ghostfx study ", spec.file, " --list)"));
    }
    const std::vector<CaseOutcome> outcomes = collectRows(spec, folder);
    std::map<std::string, std::vector<std::size_t>> byStatus;
    for (std::size_t k = 0; k < outcomes.size(); ++k) byStatus[outcomes[k].status].push_back(k);
    std::string summary;
    for (const auto& [status, cases] : byStatus) {
        summary += msg(summary.empty() ? "" : ", ", cases.size(), " ", status);
        if (status != "ok") {
            summary += " (cases";
            for (std::size_t k : cases) summary += msg(" ", k);
            summary += ")";
        }
    }
    if (!o.quiet) {
        std::fprintf(stderr, "ghostfx study '%s': collected %zu cases: %s\n", spec.file.c_str(),
                     outcomes.size(), summary.c_str());
    }
    if (byStatus.count("missing")) {
        std::fprintf(stderr,
                     "ghostfx study: warning: %zu of %zu cases have no row file yet; their rows "
                     "say \"missing\" (run them, then --collect again)\n",
                     byStatus["missing"].size(), outcomes.size());
    }
    return finishStudy(o, spec, outcomes, folder);
}

/// The line a local study prints when case `k` of `spec` ended with `r`, `seconds` after it
/// started (its log under `folder`).
std::string caseEndLine(const StudySpec& spec, std::size_t k, const CaseOutcome& r, double seconds,
                        const std::string& folder)
{
    const StudyCase& c = spec.cases[k];
    std::string line = msg("[", k + 1, "/", spec.cases.size(), "] ",
                           c.label.empty() ? "base scene" : c.label, ": ", r.status);
    if (r.status == "ok") {
        line +=
            msg(", ", number(numberOr(r, "wall_s")), " s wall, ", number(numberOr(r, "cpu_s")),
                " s CPU (", number(numberOr(r, "wall_per_sim_second")), " s per simulated s), ",
                number(numberOr(r, "peak_rss_mb")), " MB, ", number(numberOr(r, "particles_max")),
                " particles; ", spec.plotError, " = ", number(numberOr(r, spec.plotError)));
    } else {
        line += msg(" after ", number(seconds), " s: ", r.note, " (log: ", logPath(folder, k), ")");
    }
    return line;
}

/// A study without a step flag: each case as a child process, collected after every case.
int runStudyLocally(const StudyOptions& o, const StudySpec& spec)
{
    checkCases(spec);
    const std::string folder = outputFolder(o, spec);
    vdbio::ensureWritableDirectory(folder);
    vdbio::ensureWritableDirectory((fs::path(folder) / "runs").string());
    const std::string self = selfExecutable();
    auto say = [&](const std::string& line) {
        if (!o.quiet) std::fprintf(stderr, "%s\n", line.c_str());
    };
    say(msg("ghostfx study '", spec.file, "': scene '", spec.scene, "', ", spec.cases.size(),
            " runs, ", spec.metrics.size(), " metrics, output in '", folder, "'"));

    // Rows of an earlier run would be collected as this run's until their case runs again.
    for (std::size_t k = 0; k < spec.cases.size(); ++k) {
        std::error_code ec;
        fs::remove(rowPath(folder, k), ec);
    }
    std::vector<CaseOutcome> outcomes;
    for (std::size_t k = 0; k < spec.cases.size(); ++k) {
        const auto start = Clock::now();
        runChild(spec, k, programFor(spec, spec.cases[k], self), o.threads, folder);
        outcomes = collectRows(spec, folder);
        const double seconds = std::chrono::duration<double>(Clock::now() - start).count();
        say(caseEndLine(spec, k, outcomes[k], seconds, folder));
    }
    return finishStudy(o, spec, outcomes, folder);
}

int runStudy(const StudyOptions& options)
{
    // One sample cache for every case: this process's, the child processes' (through the
    // environment) and the farm commands' (--list, --emit), by its absolute path.
    StudyOptions o = options;
    if (!o.sampleCache.empty()) {
        if (!isSampleCacheOff(o.sampleCache))
            o.sampleCache = fs::absolute(o.sampleCache).lexically_normal().string();
        setProcessSampleCache(o.sampleCache);
        ::setenv("GHOSTFX_SAMPLE_CACHE", o.sampleCache.c_str(), 1);
    }
    const StudySpec spec = readStudy(o.study);
    if (int(o.caseIndex >= 0) + int(o.list) + int(o.collect) + int(!o.emit.empty()) + int(o.replot)
        > 1) {
        throw ValueError(msg("study '", o.study,
                             "': --case, --list, --collect, --emit and --replot are separate "
                             "steps: give one of them"));
    }
    if (o.caseIndex >= 0) return runStudyCase(o, spec);
    if (o.list) return listCases(o, spec);
    if (o.collect) return collectStudy(o, spec);
    if (!o.emit.empty()) return emitSlurm(o, spec);
    if (o.replot) {
        const std::string folder = outputFolder(o, spec);
        const std::vector<CaseOutcome> outcomes =
            readTable(spec, (fs::path(folder) / spec.table).string());
        return finishStudy(o, spec, outcomes, folder);
    }
    return runStudyLocally(o, spec);
}

} // namespace

Command addStudyCommand(CLI::App& parent)
{
    auto o = std::make_shared<StudyOptions>();
    CLI::App* c = parent.add_subcommand(
        "study", "Run a scene over a sweep of settings: cost against error (CSV + PNG plot)");
    c->add_option("study", o->study, "study file (.json; docs/study.md)")->required();
    c->add_option("--out", o->out, "output folder (default: output.directory of the study)");
    c->add_option("--threads", o->threads, "worker threads per run (0: all cores)")
        ->check(CLI::NonNegativeNumber);
    c->add_flag("-q,--quiet", o->quiet, "print errors only");
    c->add_flag("--replot", o->replot,
                "only redraw the plot and convergence table from the study's existing table "
                "(after changing \"plot\" or \"convergence\")");
    c->add_flag("--list", o->list,
                "print the cases, one per line: number, label and the command that runs it");
    c->add_option("--case", o->caseIndex,
                  "run case K only and write its row file (runs/case_KK.json in the output "
                  "folder): one farm job")
        ->check(CLI::NonNegativeNumber);
    c->add_flag("--collect", o->collect,
                "build the table, convergence and plot from the cases' row files");
    c->add_option("--emit", o->emit,
                  "write job scripts for a farm into the output folder: slurm (an sbatch "
                  "--array job, a collect job and submit.sh)")
        ->check(CLI::IsMember({"slurm"}));
    c->add_option("--sample-cache", o->sampleCache,
                  "one sample cache folder for every case (ghostfx run --sample-cache): a shape "
                  "sampled by one case is loaded by the others; also written into the commands "
                  "of --list and --emit (default: as ghostfx run; 'off': none)");
    return {c, [o] { return runStudy(*o); }};
}

} // namespace cmd
} // namespace ghostfx
