/// @file   GasSource.h
/// @brief  A gas source as the solver keeps it: its shape, parameters and emission budget, and
///         its placement at a step's time (libgas internal; GasEmission.cc emits from it).
#pragma once

#include "ghostfx/gas/GasSolver.h"

namespace ghostfx {
namespace gas {

/// A source and its emission budget (rate-limited sources).
struct GasSolver::Source
{
    LevelSet shape;
    GasSource params;
    double budget = 0; ///< particles the rate still allows

    RigidTransform at(double time) const
    {
        return params.motion ? params.motion(time) : RigidTransform();
    }
    bool active(double time) const { return time >= params.start && time < params.end; }
    /// Add the step's allowance (dt in s) to a rate-limited source's budget; the particles it
    /// may emit now (unlimited without a rate).
    std::size_t allowance(Real dt);
};

/// A source placed at the step's time: its world box and its inside test.
struct GasSolver::PlacedSource
{
    const Source& source;
    RigidTransform xf; ///< local to world
    sph::Aabb box;     ///< world box: the source's local bounds' corners placed

    PlacedSource(const Source& src, double time) : source(src), xf(src.at(time))
    {
        const sph::Aabb lb = src.shape.bounds();
        for (int c = 0; c < 8; ++c) {
            box.expand(xf.toWorld(Vec3(c & 1 ? lb.max[0] : lb.min[0], c & 2 ? lb.max[1] : lb.min[1],
                                       c & 4 ? lb.max[2] : lb.min[2])));
        }
    }
    /// x (m, world) inside the source's level set.
    bool inside(const Vec3& x) const { return source.shape.phi(xf.toLocal(x)) < Real(0); }
    /// x (m, world) in the world box and inside the level set.
    bool contains(const Vec3& x) const { return box.contains(x) && inside(x); }
};

} // namespace gas
} // namespace ghostfx
