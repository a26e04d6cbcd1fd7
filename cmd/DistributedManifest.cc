/// @file   DistributedManifest.cc
/// @brief  The manifest of a checkpoint written by several processes (DistributedRun.h).
#include "DistributedRun.h"

#include <ghostfx/vdbio/AtomicFile.h>

#include <ghostfx/sph/Exceptions.h>

#include <nlohmann/json.hpp>

#include <filesystem>
#include <sstream>

namespace ghostfx {
namespace cmd {

namespace fs = std::filesystem;

namespace {

const std::string MANIFEST_SUFFIX = ".ranks.json";

std::string stem(const std::string& h5Path)
{
    const fs::path p(h5Path);
    return (p.parent_path() / p.stem()).string();
}

} // namespace

bool isDistributedManifest(const std::string& path)
{
    return path.size() > MANIFEST_SUFFIX.size()
           && path.compare(path.size() - MANIFEST_SUFFIX.size(), MANIFEST_SUFFIX.size(),
                           MANIFEST_SUFFIX)
                  == 0;
}

std::string manifestPath(const std::string& h5Path) { return stem(h5Path) + MANIFEST_SUFFIX; }

std::string rankCheckpointPath(const std::string& h5Path, int rank)
{
    return msg(stem(h5Path), ".rank", rank, fs::path(h5Path).extension().string());
}

DistributedManifest readDistributedManifest(const std::string& path)
{
    const std::optional<std::string> text = vdbio::readTextFile(path);
    if (!text) throw IoError(msg("checkpoint manifest '", path, "': cannot open the file"));
    auto fail = [&](const std::string& why) {
        return SceneError(msg("checkpoint manifest '", path, "': ", why));
    };
    nlohmann::json doc;
    try {
        doc = nlohmann::json::parse(*text);
    } catch (const nlohmann::json::exception& e) {
        throw fail(msg("not valid JSON (", e.what(), ")"));
    }
    DistributedManifest m;
    try {
        if (doc.value("ghostfx_distributed_checkpoint", 0) != 1)
            throw fail("not a ghostfx checkpoint manifest (ghostfx_distributed_checkpoint: 1)");
        m.frame = doc.at("frame").get<int>();
        m.ranks = doc.at("ranks").get<int>();
        for (const auto& f : doc.at("files"))
            m.files.push_back((fs::path(path).parent_path() / f.get<std::string>()).string());
        m.decomposition = doc.at("decomposition").get<std::vector<double>>();
    } catch (const nlohmann::json::exception& e) {
        throw fail(msg("missing or wrong key (", e.what(), ")"));
    }
    if (m.ranks < 1 || int(m.files.size()) != m.ranks)
        throw fail(msg("ranks = ", m.ranks, " but ", m.files.size(), " files"));
    return m;
}

sph::SolverState mergeProcessStates(std::vector<sph::SolverState> states)
{
    if (states.empty()) throw ValueError("mergeProcessStates: no state");
    sph::SolverState whole = std::move(states.front());
    for (std::size_t r = 1; r < states.size(); ++r) {
        const sph::SolverState& part = states[r];
        const auto& kinds = part.particles.kinds();
        std::vector<std::uint8_t> fluid(kinds.size(), 0);
        for (std::size_t i = 0; i < kinds.size(); ++i)
            fluid[i] =
                kinds[i] == sph::ParticleKind::Liquid || kinds[i] == sph::ParticleKind::GhostAir;
        whole.particles.append(part.particles.select(fluid));
        for (const char* key : {"emitted", "killed"})
            whole.integers[key] = whole.integer(key) + part.integer(key);
        whole.reals["max_acceleration"] =
            std::max(whole.real("max_acceleration"), part.real("max_acceleration"));
    }
    // The processes' halo flags (all 0 in a saved state) mean nothing to the merged run.
    if (whole.particles.hasScalarChannel(sph::HALO_CHANNEL))
        whole.particles.removeChannel(sph::HALO_CHANNEL);
    return whole;
}

vdbio::StatsRow DistributedRun::combine(const vdbio::StatsRow& mine)
{
    const auto starts = [](const std::string& name, const char* prefix) {
        return name.rfind(prefix, 0) == 0;
    };
    double liquid = 0, weightedError = 0;
    for (const auto& [name, value] : mine.values) {
        if (name == "count_liquid") liquid = value;
    }
    vdbio::StatsRow all;
    for (const auto& [name, value] : mine.values) {
        double v;
        if (name == "density_error_mean") {
            weightedError = value * liquid;
            const double total = sumOf(liquid);
            v = total > 0 ? sumOf(weightedError) / total : 0.0;
        } else if (starts(name, "count_") && name != "count_ghost_solid"
                   && name != "count_boundary") {
            v = sumOf(value);
        } else {
            v = maxOf(value);
        }
        all.values.emplace_back(name, v);
    }
    return all;
}

} // namespace cmd
} // namespace ghostfx
