/// @file   SampleCommand.h
/// @brief  `ghostfx sample`: Poisson-disk sampling of a built-in shape, with statistics.
#pragma once

#include "Command.h"

#include <cstdint>
#include <string>

namespace ghostfx {
namespace cmd {

struct SampleOptions
{
    std::string shape = "sphere";       ///< sphere | box | torus
    double size = 0.1;                  ///< sphere radius, box half edge, torus major radius (m)
    double spacing = 0.01;              ///< particle spacing h (m)
    double voxelFactor = 0.5;           ///< level-set voxel size as a fraction of h
    double bandDepth = 0;               ///< > 0: sample only this deep below the surface (m)
    double restDensity = 1000;          ///< rho0 for the mass scaling (kg/m^3)
    std::string relaxation = "packing"; ///< volume relaxation: packing | sb12 (as the liquid's)
    std::uint64_t seed = 0;
    int threads = 0;
};

/// Run the command; returns the process exit code. Throws ghostfx::Error on bad input.
int runSample(const SampleOptions& options);

} // namespace cmd
} // namespace ghostfx
