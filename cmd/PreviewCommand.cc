/// @file   PreviewCommand.cc
/// @brief  placeholder, filled in by the pipeline work (issue 4)
#include "Command.h"

#include <ghostfx/sph/Exceptions.h>

namespace ghostfx {
namespace cmd {

Command addPreviewCommand(CLI::App& parent)
{
    CLI::App* c = parent.add_subcommand("preview", "(not yet available)");
    return {c, []() -> int { throw Error("'preview' is not available yet"); }};
}

} // namespace cmd
} // namespace ghostfx
