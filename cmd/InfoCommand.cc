/// @file   InfoCommand.cc
/// @brief  placeholder, filled in by the pipeline work (issue 4)
#include "Command.h"

#include <ghostfx/sph/Exceptions.h>

namespace ghostfx {
namespace cmd {

Command addInfoCommand(CLI::App& parent)
{
    CLI::App* c = parent.add_subcommand("info", "(not yet available)");
    return {c, []() -> int { throw Error("'info' is not available yet"); }};
}

} // namespace cmd
} // namespace ghostfx
