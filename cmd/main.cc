/// @file   main.cc
/// @brief  The `ghostfx` command line. Only this file exits; libraries throw (STYLE.md rule 7).
/// @details Sub-commands so far:
///            ghostfx sample   Poisson-disk sample a built-in level-set shape ([SB12] Sec. 4.5)
///                             and print particle statistics.
///          `run`, `info`, `preview` and `mesh2sdf` arrive with the pipeline (vdbio).
#include "SampleCommand.h"

#include <ghostfx/sph/Exceptions.h>

#include <CLI/CLI.hpp>
#include <openvdb/openvdb.h>

#include <cstdio>
#include <exception>

int main(int argc, char** argv)
{
    CLI::App app{"ghostfx: Ghost SPH liquids and fast SPH gases on OpenVDB"};
    app.set_version_flag("--version", std::string("ghostfx 0.1.0 (OpenVDB ") +
                                          openvdb::getLibraryAbiVersionString() + ")");
    app.require_subcommand(1);

    ghostfx::cmd::SampleOptions sampleOptions;
    CLI::App* sample = ghostfx::cmd::addSampleCommand(app, sampleOptions);

    try {
        app.parse(argc, argv);
    } catch (const CLI::ParseError& e) {
        return app.exit(e);
    }

    try {
        openvdb::initialize();
        if (sample->parsed()) return ghostfx::cmd::runSample(sampleOptions);
    } catch (const ghostfx::Error& e) {
        std::fprintf(stderr, "ghostfx: error: %s\n", e.what());
        return 1;
    } catch (const std::exception& e) {
        std::fprintf(stderr, "ghostfx: internal error: %s\n", e.what());
        return 2;
    }
    return 0;
}
