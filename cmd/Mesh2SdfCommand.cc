/// @file   Mesh2SdfCommand.cc
/// @brief  placeholder, filled in by the pipeline work (issue 4)
#include "Command.h"

#include <ghostfx/sph/Exceptions.h>

namespace ghostfx {
namespace cmd {

Command addMesh2SdfCommand(CLI::App& parent)
{
    CLI::App* c = parent.add_subcommand("mesh2sdf", "(not yet available)");
    return {c, []() -> int { throw Error("'mesh2sdf' is not available yet"); }};
}

} // namespace cmd
} // namespace ghostfx
