/// @file   WhitewaterCommand.cc
/// @brief  `ghostfx whitewater`: spray, foam and bubbles made after a run, from its liquid points
///         files, as the run would have made them inline (SceneWhitewater.h).
#include "Command.h"
#include "LiquidScene.h"
#include "Methods.h"
#include "RunCommand.h"
#include "SceneWhitewater.h"

#include <ghostfx/sph/Exceptions.h>
#include <ghostfx/sph/Parallel.h>
#include <ghostfx/vdbio/AtomicFile.h>
#include <ghostfx/vdbio/Scene.h>

#include <openvdb/openvdb.h>

#include <algorithm>
#include <cctype>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <map>
#include <memory>
#include <regex>

namespace ghostfx {
namespace cmd {

namespace fs = std::filesystem;

namespace {

struct WhitewaterArgs
{
    std::string folder; ///< the run's output folder
    std::string from = "liquid_points.$F4.vdb";
    std::string scene;  ///< "": the points files' ghostfx_scene
    std::string out;    ///< "": `folder`
    std::string frames; ///< "A-B"; "": every frame found
    std::vector<std::string> defines;
    int threads = 0;
    bool quiet = false;
};

/// The frames of `pattern` ($F4 or $F) that exist in `folder`, by frame number.
std::map<int, std::string> framesIn(const std::string& folder, const std::string& pattern)
{
    std::string expression;
    for (std::size_t i = 0; i < pattern.size(); ++i) {
        if (pattern.compare(i, 2, "$F") == 0) {
            const bool padded = i + 2 < pattern.size() && std::isdigit(pattern[i + 2]);
            expression += "([0-9]+)";
            i += padded ? 2 : 1;
        } else {
            expression +=
                std::string(std::strchr(".^$|()[]{}*+?\\", pattern[i]) ? "\\" : "") + pattern[i];
        }
    }
    if (expression.find("([0-9]+)") == std::string::npos) {
        throw ValueError(msg("--from '", pattern,
                             "': expected a frame pattern with $F (e.g. "
                             "liquid_points.$F4.vdb)"));
    }
    const std::regex re(expression);
    std::map<int, std::string> frames;
    std::error_code error;
    for (const fs::directory_entry& e : fs::directory_iterator(folder, error)) {
        std::smatch m;
        const std::string name = e.path().filename().string();
        if (!std::regex_match(name, m, re)) continue;
        const int frame = std::stoi(m[1].str());
        if (vdbio::expandFramePattern(pattern, frame) == name) frames[frame] = e.path().string();
    }
    if (error) throw IoError(msg("ghostfx whitewater: folder '", folder, "': ", error.message()));
    return frames;
}

/// The string metadata `key` of the .vdb `path`, or "".
std::string fileMetadata(const std::string& path, const std::string& key)
{
    openvdb::io::File file(path);
    try {
        file.open(false);
    } catch (const openvdb::Exception& e) {
        throw IoError(
            msg("ghostfx whitewater: '", path, "': not a readable .vdb (", e.what(), ")"));
    }
    const openvdb::MetaMap::Ptr meta = file.getMetadata();
    file.close();
    const auto value = meta->getMetadata<openvdb::StringMetadata>(key);
    return value ? value->value() : std::string();
}

/// The scene: --scene, else the one the first points file names; its whitewater output on
/// (the defaults where the scene has it off).
vdbio::Scene whitewaterScene(const WhitewaterArgs& a, const std::string& firstFile)
{
    std::string file = a.scene;
    if (file.empty()) file = fileMetadata(firstFile, "ghostfx_scene");
    if (file.empty()) {
        throw SceneError(msg("ghostfx whitewater: '", firstFile,
                             "' does not name its scene "
                             "(metadata ghostfx_scene): give it with --scene"));
    }
    vdbio::Scene scene = vdbio::readScene(file, a.defines);
    const Method& method = methodOf(scene);
    if (method.medium != Medium::Liquid || !scene.heaters.empty()) {
        throw SceneError(msg("scene '", scene.file, "': settings.method '", scene.method,
                             "': whitewater is made from a liquid scene without heaters"));
    }
    if (scene.outputs.whitewaterFile.empty()) scene.outputs.whitewaterFile = "whitewater.$F4.vdb";
    return scene;
}

/// The frames to make: every one found, or those of --frames (all of which must exist), with
/// no frame missing between the first and the last.
std::map<int, std::string> chosenFrames(const WhitewaterArgs& a, std::map<int, std::string> found)
{
    if (found.empty()) {
        throw IoError(msg("ghostfx whitewater: no '", a.from, "' files in '", a.folder, "'"));
    }
    int first = found.begin()->first, last = found.rbegin()->first;
    if (!a.frames.empty()) parseFrames(a.frames, first, last);
    std::map<int, std::string> chosen;
    for (int f = first; f <= last; ++f) {
        const auto it = found.find(f);
        if (it == found.end()) {
            throw IoError(msg("ghostfx whitewater: frame ", f, " ('",
                              vdbio::expandFramePattern(a.from, f), "') is missing in '", a.folder,
                              "': whitewater steps through every frame"));
        }
        chosen.insert(*it);
    }
    return chosen;
}

bool hasDynamicSolids(const vdbio::Scene& scene)
{
    return std::any_of(scene.solids.begin(), scene.solids.end(),
                       [](const vdbio::SceneSolid& s) { return bool(s.dynamic); });
}

int runWhitewater(const WhitewaterArgs& a)
{
    const parallel::ThreadLimit limit(a.threads);
    const std::map<int, std::string> frames = chosenFrames(a, framesIn(a.folder, a.from));
    const vdbio::Scene scene = whitewaterScene(a, frames.begin()->second);
    const ghost::GhostSettings liquid = liquidSettings(scene, ghost::methodFromName(scene.method));
    SceneWhitewater white(scene, liquid);
    const std::string outFolder = a.out.empty() ? a.folder : a.out;
    vdbio::ensureWritableDirectory(outFolder);
    const vdbio::SceneOutputs& out = scene.outputs;
    const std::string csv = (fs::path(a.folder) / "bodies.csv").string();
    const std::vector<vdbio::BodyRow> bodies =
        hasDynamicSolids(scene) ? vdbio::readBodiesCsv(csv) : std::vector<vdbio::BodyRow>();
    const auto start = std::chrono::steady_clock::now();
    for (const auto& [frame, path] : frames) {
        const auto frameStart = std::chrono::steady_clock::now();
        white.step(vdbio::readPoints(path, "", "ghostfx whitewater"), frame,
                   bodies.empty() ? std::vector<sph::RigidTransform>()
                                  : bodyPlacements(scene, bodies, frame, csv),
                   path);
        openvdb::MetaMap meta;
        meta.insertMeta("ghostfx_scene", openvdb::StringMetadata(scene.file));
        meta.insertMeta("ghostfx_method", openvdb::StringMetadata(scene.method));
        meta.insertMeta("frame", openvdb::Int32Metadata(frame));
        meta.insertMeta("time", openvdb::DoubleMetadata(double(frame) / scene.frameRate));
        auto inOut = [&](const std::string& p) {
            return (fs::path(outFolder) / vdbio::expandFramePattern(p, frame)).string();
        };
        writeWhitewaterFiles(scene, white.points(), inOut(out.whitewaterFile),
                             out.whitewaterFogVoxelSize > 0 ? inOut(out.whitewaterFogFile) : "",
                             meta);
        const ghost::Whitewater& w = white.whitewater();
        if (!a.quiet) {
            std::printf("frame %d: %zu whitewater (%zu spray, %zu foam, %zu bubbles), %.2f s\n",
                        frame, w.size(), w.count(ghost::WhitewaterType::Spray),
                        w.count(ghost::WhitewaterType::Foam),
                        w.count(ghost::WhitewaterType::Bubble),
                        std::chrono::duration<double>(std::chrono::steady_clock::now() - frameStart)
                            .count());
        }
    }
    const double seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    std::printf("done: %zu frames in %.2f s (%.1f frames/s), %llu whitewater particles made\n",
                frames.size(), seconds, double(frames.size()) / seconds,
                static_cast<unsigned long long>(white.whitewater().made()));
    return 0;
}

} // namespace

Command addWhitewaterCommand(CLI::App& parent)
{
    auto a = std::make_shared<WhitewaterArgs>();
    CLI::App* c = parent.add_subcommand(
        "whitewater",
        "Make spray, foam and bubbles from a run's liquid points files, as outputs.whitewater "
        "makes them inline: the same particles from the same points (their files need the "
        "channels v and id). Writes the scene's outputs.whitewater files (whitewater.$F4.vdb "
        "by default) beside them");
    c->add_option("folder", a->folder, "the run's output folder, holding its points files")
        ->required();
    c->add_option("--from", a->from, "the liquid points files, a frame pattern in the folder")
        ->capture_default_str();
    c->add_option("--scene", a->scene,
                  "the scene (default: the one the points files name, metadata ghostfx_scene)");
    c->add_option("--out", a->out, "folder the whitewater files go to (default: the folder)");
    c->add_option("--frames", a->frames,
                  "frames A-B (default: every frame found; none may be missing between)");
    c->add_option("-D,--define", a->defines,
                  "override a scene key: -D settings.whitewater.trapped_air_rate=5e7");
    c->add_option("--threads", a->threads, "worker threads (0: all cores)");
    c->add_flag("-q,--quiet", a->quiet, "no line per frame");
    return {c, [a] { return runWhitewater(*a); }};
}

} // namespace cmd
} // namespace ghostfx
