/// @file   BenchMain.h
/// @brief  The main of a plain (not Google Benchmark) benchmark program with a command line:
///         options, line-buffered output, one line per error.
#pragma once

#include "BenchCommon.h"

#include <CLI/CLI.hpp>

#include <cstdio>
#include <exception>

namespace ghostfx {
namespace bench {

/// Run `body` (returns the exit status); an exception is printed as "<program>: <what>" on
/// stderr and gives 1.
template <typename Body>
int runReportingErrors(const char* program, Body&& body)
{
    try {
        return body();
    } catch (const std::exception& e) {
        std::fprintf(stderr, "%s: %s\n", program, e.what());
        return 1;
    }
}

/// Parse the command line into an `Options` (its defaults, then what `addOptions` registers),
/// make stdout line-buffered (progress shows while a run takes minutes) and return `run`'s
/// status; an exception is printed as "<program>: <what>" and gives 1.
/// @param program      the program's name, as its messages begin
/// @param description  the one-line help text
template <typename Options>
int benchMain(int argc, char** argv, const char* program, const char* description,
              void (*addOptions)(CLI::App&, Options&), int (*run)(const Options&))
{
    CLI::App app{description};
    Options options;
    addOptions(app, options);
    CLI11_PARSE(app, argc, argv);
    std::setvbuf(stdout, nullptr, _IOLBF, 0);
    return runReportingErrors(program, [&] { return run(options); });
}

} // namespace bench
} // namespace ghostfx
