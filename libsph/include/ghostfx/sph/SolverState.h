/// @file   SolverState.h
/// @brief  Everything a solver needs to continue a run exactly: its particles and its scalars.
/// @details A solver's saveState() fills one of these and restoreState() takes it back; vdbio
///          writes it to an HDF5 checkpoint and reads it back bit for bit (DESIGN.md, data flow:
///          "vdbio checkpoint (HDF5) every N frames"). The struct knows no solver: each solver
///          documents the keys it stores in `reals` and `integers`. What a solver is built from
///          (settings, solid and emitter level sets, motions) is not part of the state: the caller
///          constructs the solver with the same settings and adds the same inputs again.
#pragma once

#include "ghostfx/sph/Exceptions.h"
#include "ghostfx/sph/ParticleSet.h"

#include <cstdint>
#include <map>
#include <string>

namespace ghostfx {
namespace sph {

struct SolverState
{
    /// Which solver wrote the state: "ghost", "basic", "gas"... restoreState refuses another.
    std::string solver;
    /// Every particle with every built-in and named channel, its id and the next id to give.
    ParticleSet particles;
    /// Floating-point scalars (time in s, particle mass in kg, ...), stored as double: a Real
    /// (float or double) converts to double and back exactly.
    std::map<std::string, double> reals;
    /// Integer scalars (step, frame, counters, flags as 0 / 1).
    std::map<std::string, std::int64_t> integers;

    /// The value of `reals[key]`; ValueError naming the key and the solver if it is missing.
    double real(const std::string& key) const { return lookup(reals, key, "real"); }
    /// The value of `integers[key]`; ValueError naming the key and the solver if it is missing.
    std::int64_t integer(const std::string& key) const { return lookup(integers, key, "integer"); }

private:
    template <typename T>
    T lookup(const std::map<std::string, T>& values, const std::string& key, const char* what) const
    {
        const auto it = values.find(key);
        if (it == values.end()) {
            throw ValueError(msg("solver state ('", solver, "'): missing ", what, " '", key,
                                 "'; it was not saved by this solver or comes from another "
                                 "version"));
        }
        return it->second;
    }
};

} // namespace sph
} // namespace ghostfx
