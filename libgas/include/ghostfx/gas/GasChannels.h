/// @file   GasChannels.h
/// @brief  Names of the particle channels the gas solver and its parts keep.
/// @details Exporters and couplers read them by name; see GasSolver.h for who writes them.
#pragma once

namespace ghostfx {
namespace gas {

/// Names of the particle channels the gas solver keeps (exporters read them by name).
namespace channel {
constexpr const char* TEMPERATURE = "temperature"; ///< T (K), gas; boundaries: ambient
constexpr const char* SUPPORT = "h";               ///< kernel support radius h_i (m)
constexpr const char* DENSITY_UNCORRECTED = "density_uncorrected"; ///< rho_bar (kg/m^3)
constexpr const char* NORMAL = "normal";       ///< n_i of Eq. 12 (1/m), points inwards
constexpr const char* LIFE = "life";           ///< life strength l_s left (s), Sec. 5
constexpr const char* AMBIENT = "ambient";     ///< 1 for ambient air (Method::Ambient only)
constexpr const char* VORTICITY = "vorticity"; ///< omega of Eq. 25 (1/s), if enabled
/// The share of a particle's mass that is the gas as emitted (1), the rest entrained air
/// (GasEntrainment.h); only with entrainment.
constexpr const char* SMOKE = "smoke";
constexpr const char* SOLID_LOCAL = "solid_x"; ///< boundary: position in its solid's frame
/// Boundary: index of its solid (>= 0), EXTERNAL_BOUNDARY or DOMAIN_WALL.
constexpr const char* SOLID_INDEX = "solid_index";
} // namespace channel

} // namespace gas
} // namespace ghostfx
