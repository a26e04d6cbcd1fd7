/// @file   PreviewCommand.cc
/// @brief  `ghostfx preview`: render a surface (level-set) or density (fog) grid to an EXR or
///         PNG image.
#include "Command.h"

#include <ghostfx/vdbio/Preview.h>

#include <cstdio>
#include <memory>
#include <string>

namespace ghostfx {
namespace cmd {

Command addPreviewCommand(CLI::App& parent)
{
    auto args = std::make_shared<FileToFileArgs<vdbio::PreviewOptions>>();
    vdbio::PreviewOptions& o = args->options;
    CLI::App* c = addFileToFileCommand(
        parent, "preview",
        "Render a level set (the liquid's surface) or fog volume (density) of a .vdb to an "
        "image, camera framed on the grid. The output's extension chooses the format: .png "
        "writes an 8-bit sRGB PNG, .exr (or any other name) a half-float RGBA OpenEXR",
        "file", "input .vdb file", "output image: .exr (half-float RGBA) or .png (8-bit sRGB)",
        *args);
    c->add_option("--grid", o.grid,
                  "grid to render (default: 'surface', the liquid's level set, if present, "
                  "else 'density', else the first float grid)");
    c->add_option("--width", o.width, "image width (pixels)")->capture_default_str();
    c->add_option("--height", o.height, "image height (pixels)")->capture_default_str();
    c->add_option("--azimuth", o.azimuth,
                  "camera azimuth about +y (degrees; 0: camera on the +z side)")
        ->capture_default_str();
    c->add_option("--elevation", o.elevation, "camera elevation above the xz-plane (degrees)")
        ->capture_default_str();
    c->add_option("--extinction", o.extinction,
                  "fog extinction at density 1 (1/m); the default makes a 0.2 m body 86 % opaque")
        ->capture_default_str();
    return {c, [args] {
                const vdbio::PreviewSummary s =
                    vdbio::renderPreviewFromFile(args->input, args->options, args->output);
                std::printf("ghostfx preview: grid '%s' (%s, %llu active voxels) of '%s' -> "
                            "'%s' (%dx%d, azimuth %g, elevation %g degrees) in %.2f s\n",
                            s.gridName.c_str(), s.gridClass.c_str(),
                            static_cast<unsigned long long>(s.activeVoxels), args->input.c_str(),
                            args->output.c_str(), args->options.width, args->options.height,
                            args->options.azimuth, args->options.elevation, s.seconds);
                return 0;
            }};
}

} // namespace cmd
} // namespace ghostfx
