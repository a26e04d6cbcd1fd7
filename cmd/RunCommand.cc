/// @file   RunCommand.cc
/// @brief  placeholder, filled in by the pipeline work (issue 4)
#include "Command.h"

#include <ghostfx/sph/Exceptions.h>

namespace ghostfx {
namespace cmd {

Command addRunCommand(CLI::App& parent)
{
    CLI::App* c = parent.add_subcommand("run", "(not yet available)");
    return {c, []() -> int { throw Error("'run' is not available yet"); }};
}

} // namespace cmd
} // namespace ghostfx
