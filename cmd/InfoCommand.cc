/// @file   InfoCommand.cc
/// @brief  `ghostfx info`: describe a .vdb (grids, classes, voxels, points), an .h5 file, or the
///         manifest of a checkpoint written by several processes (.ranks.json).
#include "Command.h"
#include "DistributedRun.h"

#include <ghostfx/sph/DomainDecomposition.h>
#include <ghostfx/vdbio/Checkpoint.h>
#include <ghostfx/vdbio/Info.h>

#include <cstdio>
#include <filesystem>
#include <memory>
#include <string>

namespace ghostfx {
namespace cmd {

namespace {

/// The manifest, every process's part (from its header: no particles are read) and the totals.
std::string describeManifest(const std::string& path)
{
    const DistributedManifest m = readDistributedManifest(path);
    std::string out =
        msg(path, ": checkpoint of frame ", m.frame, " written by ", m.ranks,
            " processes (resume with mpirun -np ", m.ranks, " ghostfx run SCENE --resume ", path,
            "; on another count, or as one process, its parts are merged)\n");
    const sph::DomainDecomposition parts = sph::DomainDecomposition::load(m.decomposition, m.ranks);
    std::map<std::string, std::size_t> total;
    for (int r = 0; r < m.ranks; ++r) {
        const std::string& file = m.files[std::size_t(r)];
        const vdbio::CheckpointHeader h = vdbio::readCheckpointHeader(file);
        const sph::Aabb& box = parts.region(r);
        const auto side = [](sph::Real lo, sph::Real hi) {
            const auto bound = [](sph::Real v) {
                return std::abs(v) > sph::Real(1e30) ? std::string(v < 0 ? "-inf" : "inf") : msg(v);
            };
            return msg("[", bound(lo), ", ", bound(hi), "]");
        };
        out +=
            msg("  process ", r, ": ", std::filesystem::path(file).filename().string(), ", ",
                std::filesystem::exists(file) ? msg(std::filesystem::file_size(file) / 1024, " kB")
                                              : std::string("missing"),
                ", step ", h.step, ", t = ", h.time, " s; region x ", side(box.min[0], box.max[0]),
                " y ", side(box.min[1], box.max[1]), " z ", side(box.min[2], box.max[2]), "; ");
        bool first = true;
        for (const auto& [kind, count] : h.countPerKind) {
            if (count == 0) continue;
            out += msg(first ? "" : ", ", count, " ", kind);
            first = false;
            // Solids are whole in every part: count them once.
            if (kind == "liquid" || kind == "ghost_air" || r == 0) total[kind] += count;
        }
        out += "\n";
    }
    out += "  whole simulation: ";
    bool first = true;
    for (const auto& [kind, count] : total) {
        if (count == 0) continue;
        out += msg(first ? "" : ", ", count, " ", kind);
        first = false;
    }
    return out + " (solid ghosts once: every process holds them all)\n";
}

} // namespace

Command addInfoCommand(CLI::App& parent)
{
    auto path = std::make_shared<std::string>();
    CLI::App* c = parent.add_subcommand(
        "info", "Describe a .vdb file (grids, classes, voxels, bounds, points, metadata), an .h5 "
                "file (groups, datasets, attributes) or a checkpoint manifest (.ranks.json)");
    c->add_option("file", *path, ".vdb, .h5, .hdf5 or .ranks.json file")->required();
    return {c, [path] {
                std::fputs((isDistributedManifest(*path) ? describeManifest(*path)
                                                         : vdbio::describeFile(*path))
                               .c_str(),
                           stdout);
                return 0;
            }};
}

} // namespace cmd
} // namespace ghostfx
