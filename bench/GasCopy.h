/// @file   GasCopy.h
/// @brief  Benchmarks' helper: hand one gas solver's gas particles to another (the ambient-air
///         baseline continuing from the fast solver's state, in bench_gas and bench_plume).
#pragma once

#include <ghostfx/gas/GasSolver.h>

#include <vector>

namespace ghostfx {
namespace bench {

/// Add a copy of every gas particle of `from` (position, velocity, temperature, mass and
/// support radius) to `to`.
inline void copyGas(const gas::GasSolver& from, gas::GasSolver& to)
{
    using namespace sph;
    const ParticleSet& g = from.particles();
    std::vector<Vec3> x, v;
    std::vector<Real> T, m, h;
    const auto& gT = g.scalarChannel(gas::channel::TEMPERATURE);
    const auto& gh = g.scalarChannel(gas::channel::SUPPORT);
    for (std::size_t i = 0; i < g.size(); ++i) {
        if (g.kinds()[i] != ParticleKind::Gas) continue;
        x.push_back(g.positions()[i]);
        v.push_back(g.velocities()[i]);
        T.push_back(gT[i]);
        m.push_back(g.masses()[i]);
        h.push_back(gh[i]);
    }
    to.addGasParticles(x, v, T, m, h);
}

} // namespace bench
} // namespace ghostfx
