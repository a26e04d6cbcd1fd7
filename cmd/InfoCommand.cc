/// @file   InfoCommand.cc
/// @brief  `ghostfx info`: describe a .vdb (grids, classes, voxels, points) or an .h5 file.
#include "Command.h"

#include <ghostfx/vdbio/Info.h>

#include <cstdio>
#include <memory>
#include <string>

namespace ghostfx {
namespace cmd {

Command addInfoCommand(CLI::App& parent)
{
    auto path = std::make_shared<std::string>();
    CLI::App* c = parent.add_subcommand(
        "info", "Describe a .vdb file (grids, classes, voxels, bounds, points, metadata) or an "
                ".h5 file (groups, datasets, attributes)");
    c->add_option("file", *path, ".vdb, .h5 or .hdf5 file")->required();
    return {c, [path] {
                std::fputs(vdbio::describeFile(*path).c_str(), stdout);
                return 0;
            }};
}

} // namespace cmd
} // namespace ghostfx
