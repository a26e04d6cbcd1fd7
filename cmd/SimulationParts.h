/// @file   SimulationParts.h
/// @brief  What the liquid, gas and boiling simulations share inside `cmd`, and their
///         factories, which the method registry (Methods.cc) calls.
#pragma once

#include "Simulation.h"

#include <ghostfx/gas/GasSettings.h>
#include <ghostfx/gas/GasSolver.h>
#include <ghostfx/ghost/GhostSettings.h>
#include <ghostfx/ghost/GhostSolver.h>

#include <memory>
#include <string>
#include <utility>
#include <vector>

namespace ghostfx {
namespace cmd {

/// max |v| and the mean / max of |rho / rho0 - 1| over particles of `kind` (and not ambient air).
struct FieldStats
{
    std::size_t count = 0;
    double maxSpeed = 0, errorMean = 0, errorMax = 0;
};

/// Statistics of particles of `kind`, skipping those whose `skip` value is non-zero.
FieldStats fieldStats(const sph::ParticleSet& p, sph::ParticleKind kind, double rho0,
                      const std::vector<sph::Real>* skip);

/// 1 / (frame rate substeps), or 0 for CFL-limited steps.
template <typename Settings>
double fixedStep(const Settings& s)
{
    return s.substeps > 0 ? 1.0 / (double(s.frameRate) * s.substeps) : 0.0;
}

/// The statistics column `bytes_per_particle` of a simulation.
inline std::pair<std::string, double> bytesPerParticle(const Simulation& sim)
{
    const std::size_t n = sim.particleCount();
    return {"bytes_per_particle", n ? double(sim.memoryBytes()) / double(n) : 0.0};
}

// Liquid
/// Liquid, air and solid particles of a liquid solver.
std::size_t liquidParticleCount(const ghost::GhostSolver& s);
OutputMedium liquidMedium(const ghost::GhostSolver& s);
/// A liquid scene's simulation ([SB12] `method`); with heaters, the boiling simulation.
std::unique_ptr<Simulation> makeLiquidSimulation(const vdbio::Scene& scene, ghost::Method method,
                                                 const std::vector<sph::SolverState>* restored);
/// Read and check a liquid scene's keys (boiling ones too, with heaters).
void checkLiquidSimulation(const vdbio::Scene& scene, ghost::Method method);

// Gas
/// Visible gas (not ambient air) copied into a set of its own for the outputs.
void copyVisibleGas(const sph::ParticleSet& from, sph::ParticleSet& to);
OutputMedium gasMedium(const gas::GasSolver& s, const sph::ParticleSet& visible);
/// The visible gas of `s` as a script sets it (kind Gas, ambient air skipped); none for
/// another kind.
WritableParticles writableGas(gas::GasSolver& s, sph::ParticleKind kind);
/// The gas statistics columns, timings as differences from `before`.
std::vector<std::pair<std::string, double>> gasStats(const gas::GasSolver& s,
                                                     const gas::GasTimings& before);
/// A gas scene's simulation ([RYY15] `method`).
std::unique_ptr<Simulation> makeGasSimulation(const vdbio::Scene& scene, gas::Method method,
                                              const sph::SolverState* restored);
void checkGasSimulation(const vdbio::Scene& scene, gas::Method method);

// Boiling: a liquid with heaters, its vapour a fast gas ([RYY15] Sec. 4).
/// `restored`: the three states saveStates() gives (liquid, vapour, phase transition), or null.
std::unique_ptr<Simulation> makeBoilingSimulation(const vdbio::Scene& scene, ghost::Method method,
                                                  const std::vector<sph::SolverState>* restored);
void checkBoilingSimulation(const vdbio::Scene& scene, ghost::Method method);

} // namespace cmd
} // namespace ghostfx
