/// @file   main.cc
/// @brief  The `ghostfx` command line. Only this file exits; libraries throw (STYLE.md rule 7).
/// @details Sub-commands:
///            ghostfx run       simulate a scene to a VDB frame sequence (checkpoints, stats, previews)
///            ghostfx info      describe a .vdb file (grids, classes, voxels, points) or an .h5 file
///            ghostfx preview   render a density or surface grid to an EXR image
///            ghostfx mesh2sdf  convert an OBJ/PLY/... triangle mesh to a level set
///            ghostfx sample    Poisson-disk sample a built-in shape and print statistics
///            ghostfx study     run a scene over a sweep of settings: cost against error
#include "Command.h"

#include <ghostfx/sph/Exceptions.h>

#include <CLI/CLI.hpp>
#include <openvdb/openvdb.h>

#include <cstdio>
#include <exception>
#include <vector>

int main(int argc, char** argv)
{
    CLI::App app{"ghostfx: Ghost SPH liquids and fast SPH gases on OpenVDB"};
#if defined(GHOSTFX_AVX2)
    const char* simd = ", AVX2";
#else
    const char* simd = "";
#endif
    app.set_version_flag("--version", std::string("ghostfx 0.1.0 (OpenVDB ")
                                          + openvdb::getLibraryAbiVersionString() + simd + ")");
    app.require_subcommand(1);

    using namespace ghostfx::cmd;
    const std::vector<Command> commands = {addRunCommand(app),     addInfoCommand(app),
                                           addPreviewCommand(app), addMesh2SdfCommand(app),
                                           addSampleCommand(app),  addStudyCommand(app),
                                           addWhitewaterCommand(app)};
    try {
        app.parse(argc, argv);
    } catch (const CLI::ParseError& e) {
        return app.exit(e);
    }

    try {
        openvdb::initialize();
        for (const Command& command : commands) {
            if (command.app->parsed()) return command.run();
        }
    } catch (const ghostfx::Error& e) {
        std::fprintf(stderr, "ghostfx: error: %s\n", e.what());
        return 1;
    } catch (const std::exception& e) {
        std::fprintf(stderr, "ghostfx: internal error: %s\n", e.what());
        return 2;
    }
    return 0;
}
