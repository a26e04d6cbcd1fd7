/// @file   Command.h
/// @brief  How a `ghostfx` sub-command plugs into main: it registers its options on the CLI11
///         app and hands back the action to run once parsing succeeded.
#pragma once

#include <CLI/CLI.hpp>

#include <functional>

namespace ghostfx {
namespace cmd {

/// A registered sub-command. `run` returns the process exit code and throws ghostfx::Error on
/// bad input (main prints it as one line and exits 1).
struct Command
{
    CLI::App* app = nullptr;
    std::function<int()> run;
};

Command addSampleCommand(CLI::App& parent);
Command addRunCommand(CLI::App& parent);
Command addInfoCommand(CLI::App& parent);
Command addPreviewCommand(CLI::App& parent);
Command addMesh2SdfCommand(CLI::App& parent);
Command addStudyCommand(CLI::App& parent);

} // namespace cmd
} // namespace ghostfx
