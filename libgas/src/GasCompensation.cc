/// @file   GasCompensation.cc
/// @brief  Density correction (Eqs. 5, 7, 8) of the fast gas [RYY15] Sec. 3.1.
#include "ghostfx/gas/GasCompensation.h"

#include "GasPairs.h"

#include <ghostfx/sph/Kernels.h>

namespace ghostfx {
namespace gas {

using namespace detail;

GasCompensation::GasCompensation(const GasSettings& settings)
    : mEnabled(settings.method == Method::Fast)
    , mDelta(settings.delta)
    , mAtmosphericPressure(settings.atmosphericPressure)
    , mInteriorPressureScale(settings.interiorPressureScale)
    , mDamping(settings.boundaryDamping())
{}

void GasCompensation::storeNormal(const NeighborLists& lists, const std::vector<Vec3>& x,
                                  const std::vector<Real>& m, const std::vector<Real>& h,
                                  const std::vector<Real>& rhoBar, std::size_t i)
{
    Vec3d nbar(0.0);
    forEachListed(lists, x, i, [&](Index j, const Vec3& xij, Real r) {
        if (j == i) return;
        const Real R = pairSupport(h[i], h[j]);
        if (r >= R) return;
        const Vec3 g = sph::spikyGrad(xij, r, R);
        const double vj = double(m[j]) / double(rhoBar[j]);
        accumulate(nbar, g * Real(vj));
    });
    mNbar[i] = sph::toVec3(nbar);
}

Real GasCompensation::correctedDensity(const NeighborLists& lists, const std::vector<Vec3>& x,
                                       const std::vector<Real>& m, const std::vector<Real>& h,
                                       const std::vector<Real>& rhoBar, std::size_t i)
{
    // Eq. 5: V_0 = |sum_j m_j / rho_bar_j grad W_ij| / |grad W_ik|, with the uncorrected
    // neighbour densities as in Eq. 4 and the derivation of Eqs. 7 - 8 (Appendix A); the virtual
    // particle k sits delta h_i away (Sec. 3.1), so |grad W_ik| and W_ik use the particle's own h.
    storeNormal(lists, x, m, h, rhoBar, i);
    // Eq. 8: rho_i = rho_bar_i (1 + V_0 W_ik).
    const Real rk = mDelta * h[i];
    const Real V0 = mNbar[i].length() / sph::spikySlope(rk, h[i]);
    return rhoBar[i] * (Real(1) + V0 * sph::poly6W(rk, h[i]));
}

} // namespace gas
} // namespace ghostfx
