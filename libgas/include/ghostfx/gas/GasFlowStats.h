/// @file   GasFlowStats.h
/// @brief  What a gas's flow does, for the statistics: its kinetic energy, its resolved
///         enstrophy and, for a plume, how fast it widens with height.
#pragma once

#include <ghostfx/gas/GasSettings.h>
#include <ghostfx/sph/ParticleSet.h>

namespace ghostfx {
namespace gas {

struct GasFlowStats
{
    /// sum_i m_i |v_i|^2 / 2 (J) of the visible gas.
    double kineticEnergy = 0;
    /// sum_i V_i |omega_i|^2 / 2 (m^3/s^2), omega_i = sum_j V_j (v_j - v_i) x grad W_ij the SPH
    /// curl of the velocity over visible gas neighbours (V = m / rho, the spiky kernel at the
    /// pair's support): the resolved eddies' strength.
    double enstrophy = 0;
    /// db/dz of the visible gas along the buoyancy direction: the top-hat radius
    /// b = sqrt(2) r_rms of 10 height slices between its 20th and 80th mass percentile
    /// (r_rms the mass-weighted RMS distance from the slice's own centre of mass across the
    /// direction; a uniform disc of radius b has r_rms = b / sqrt(2)), fitted by least squares.
    /// NaN with fewer than 3 slices of at least 8 particles (no plume to speak of).
    double spreadRate = 0;
};

/// The flow statistics of the visible gas (kind Gas, not ambient air) of `particles`, which
/// carry the gas's channels ("h", "ambient" where there is air) and densities.
GasFlowStats gasFlowStats(const sph::ParticleSet& particles, const GasSettings& settings);

} // namespace gas
} // namespace ghostfx
