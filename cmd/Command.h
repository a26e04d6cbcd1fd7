/// @file   Command.h
/// @brief  How a `ghostfx` sub-command plugs into main: it registers its options on the CLI11
///         app and hands back the action to run once parsing succeeded.
#pragma once

#include <CLI/CLI.hpp>

#include <functional>
#include <memory>
#include <string>

namespace ghostfx {
namespace cmd {

/// A registered sub-command. `run` returns the process exit code and throws ghostfx::Error on
/// bad input (main prints it as one line and exits 1).
struct Command
{
    CLI::App* app = nullptr;
    std::function<int()> run;
};

/// The arguments of a command that turns one file into another with options (`preview`,
/// `mesh2sdf`): the positional input, `-o` and the options, shared with the action.
template <typename Options>
struct FileToFileArgs
{
    std::string input, output;
    Options options;
};

/// A sub-command `name` with `description` and FileToFileArgs: the input's positional option
/// (`inputName`, `inputHelp`) and a required `-o,--output` (`outputHelp`).
template <typename Options>
CLI::App* addFileToFileCommand(CLI::App& parent, const std::string& name,
                               const std::string& description, const std::string& inputName,
                               const std::string& inputHelp, const std::string& outputHelp,
                               FileToFileArgs<Options>& args)
{
    CLI::App* c = parent.add_subcommand(name, description);
    c->add_option(inputName, args.input, inputHelp)->required();
    c->add_option("-o,--output", args.output, outputHelp)->required();
    return c;
}

Command addSampleCommand(CLI::App& parent);
Command addRunCommand(CLI::App& parent);
Command addInfoCommand(CLI::App& parent);
Command addPreviewCommand(CLI::App& parent);
Command addMesh2SdfCommand(CLI::App& parent);
Command addStudyCommand(CLI::App& parent);
Command addWhitewaterCommand(CLI::App& parent);

} // namespace cmd
} // namespace ghostfx
