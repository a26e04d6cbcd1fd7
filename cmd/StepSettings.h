/// @file   StepSettings.h
/// @brief  The step-control keys every solver's settings read the same way from a scene.
#pragma once

#include <ghostfx/sph/Types.h>
#include <ghostfx/vdbio/JsonReader.h>

#include <cstdint>

namespace ghostfx {
namespace cmd {

/// Read `substeps` (0 = CFL-limited), `cfl`, `max_speed` (the blow-up bound) and `seed` of
/// `o` into `s` (GhostSettings or GasSettings), each with its range check.
template <typename Settings>
void readStepSettings(const vdbio::JsonObject& o, Settings& s)
{
    s.substeps = int(o.inRange("substeps", s.substeps, 0, 100000));
    s.cflNumber = sph::Real(o.inRange("cfl", s.cflNumber, 1e-3, 10));
    s.maxSpeed = sph::Real(o.nonNegative("max_speed", s.maxSpeed));
    s.seed = o.get<std::uint64_t>("seed", s.seed);
}

} // namespace cmd
} // namespace ghostfx
