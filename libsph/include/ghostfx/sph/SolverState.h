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

#include <cstddef>
#include <cstdint>
#include <limits>
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
    /// `integers[key]` checked to lie in [lo, hi]: ValueError "restoreState: integer 'step' =
    /// -1: expected 0 to ..." otherwise (a damaged or hand-edited checkpoint).
    std::int64_t integer(const std::string& key, std::int64_t lo, std::int64_t hi) const
    {
        const std::int64_t value = integer(key);
        if (value < lo || value > hi) {
            throw ValueError(
                msg("restoreState: integer '", key, "' = ", value, ": expected ", lo, " to ", hi));
        }
        return value;
    }
    /// A count or step number: `integers[key]` checked to be >= 0.
    std::int64_t count(const std::string& key) const
    {
        return integer(key, 0, std::numeric_limits<std::int64_t>::max());
    }
    /// The frame counter: in [0, INT_MAX].
    int frame() const { return int(integer("frame", 0, std::numeric_limits<int>::max())); }

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

/// Where a solver's run stands: the clock and the counters every solver keeps, saved in a
/// SolverState under the same keys by all of them ("time", "max_acceleration",
/// "mean_neighbors"; "step", "frame", "initialized", "emitted", "killed").
struct RunCounters
{
    double time = 0;          ///< simulated time (s), exact at frame ends
    std::uint64_t step = 0;   ///< steps taken
    int frame = 0;            ///< frames advanced (the state is at frame / fps)
    bool initialized = false; ///< the first step's set-up (mass, air, ...) is done
    std::size_t emitted = 0;  ///< particles emitters or sources have added
    std::size_t killed = 0;   ///< particles removed by the kill box
    Real maxAcceleration = 0; ///< largest acceleration of the last step (m/s^2, CFL)
    double meanNeighbors = 0; ///< neighbours per particle in the last step (diagnostic)

    void save(SolverState& state) const
    {
        state.reals["time"] = time;
        state.reals["max_acceleration"] = double(maxAcceleration);
        state.reals["mean_neighbors"] = meanNeighbors;
        state.integers["step"] = std::int64_t(step);
        state.integers["frame"] = frame;
        state.integers["initialized"] = initialized ? 1 : 0;
        state.integers["emitted"] = std::int64_t(emitted);
        state.integers["killed"] = std::int64_t(killed);
    }

    /// The counters of `state`; ValueError for a missing key or one out of range.
    static RunCounters load(const SolverState& state)
    {
        RunCounters c;
        c.time = state.real("time");
        c.maxAcceleration = Real(state.real("max_acceleration"));
        c.meanNeighbors = state.real("mean_neighbors");
        c.step = std::uint64_t(state.count("step"));
        c.frame = state.frame();
        c.initialized = state.integer("initialized", 0, 1) != 0;
        c.emitted = std::size_t(state.count("emitted"));
        c.killed = std::size_t(state.count("killed"));
        return c;
    }
};

} // namespace sph
} // namespace ghostfx
