/// @file   GasFlowStats.cc
#include "ghostfx/gas/GasFlowStats.h"

#include <ghostfx/gas/GasChannels.h>
#include <ghostfx/sph/Kernels.h>
#include <ghostfx/sph/NeighborGrid.h>
#include <ghostfx/sph/Parallel.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <vector>

namespace ghostfx {
namespace gas {

using Vec3d = openvdb::math::Vec3<double>;

namespace {

/// The visible gas of `p`: its indices.
std::vector<std::size_t> visibleGas(const sph::ParticleSet& p)
{
    const std::vector<Real>* ambient =
        p.hasScalarChannel(channel::AMBIENT) ? &p.scalarChannel(channel::AMBIENT) : nullptr;
    std::vector<std::size_t> out;
    for (std::size_t i = 0; i < p.size(); ++i) {
        if (p.kinds()[i] == sph::ParticleKind::Gas && !(ambient && (*ambient)[i] != Real(0)))
            out.push_back(i);
    }
    return out;
}

/// sum_i V_i |omega_i|^2 / 2 over the particles `gas` of `p`.
double enstrophyOf(const sph::ParticleSet& p, const std::vector<std::size_t>& gas, Real rho0)
{
    if (gas.empty()) return 0;
    const auto& h = p.scalarChannel(channel::SUPPORT);
    std::vector<Vec3> x;
    Real hMax = 0;
    for (std::size_t i : gas) {
        x.push_back(p.positions()[i]);
        hMax = std::max(hMax, h[i]);
    }
    const auto volume = [&](std::size_t i) {
        const Real rho = p.densities()[i] > Real(0) ? p.densities()[i] : rho0;
        return double(p.masses()[i]) / double(rho);
    };
    sph::NeighborGrid grid(hMax);
    grid.build(x);
    return parallel::sum(0, gas.size(), [&](std::size_t a) {
        const std::size_t i = gas[a];
        Vec3d omega(0.0);
        grid.forEachInRadius(x[a], hMax, [&](sph::Index b, const Vec3& xij, Real r) {
            const std::size_t j = gas[std::size_t(b)];
            const Real R = Real(0.5) * (h[i] + h[j]);
            if (j == i || r >= R) return;
            const Vec3d dv(p.velocities()[j] - p.velocities()[i]);
            omega += dv.cross(Vec3d(sph::spikyGrad(xij, r, R))) * volume(j);
        });
        return 0.5 * volume(i) * omega.lengthSqr();
    });
}

/// db/dz of GasFlowStats::spreadRate.
double spreadRateOf(const sph::ParticleSet& p, const std::vector<std::size_t>& gas, Vec3d up)
{
    const double nan = std::numeric_limits<double>::quiet_NaN();
    if (gas.size() < 24 || !(up.length() > 0)) return nan;
    up.normalize();
    std::vector<std::pair<double, std::size_t>> byHeight;
    for (std::size_t i : gas) byHeight.push_back({Vec3d(p.positions()[i]).dot(up), i});
    std::sort(byHeight.begin(), byHeight.end());
    const double lo = byHeight[byHeight.size() / 5].first;
    const double hi = byHeight[byHeight.size() * 4 / 5].first;
    constexpr int SLICES = 10;
    std::vector<double> z, b;
    for (int k = 0; k < SLICES && hi > lo; ++k) {
        const double z0 = lo + (hi - lo) * k / SLICES, z1 = lo + (hi - lo) * (k + 1) / SLICES;
        double m = 0, r2 = 0;
        Vec3d c(0.0);
        std::size_t count = 0;
        for (int pass = 0; pass < 2; ++pass) {
            for (const auto& [height, i] : byHeight) {
                if (height < z0 || height >= z1) continue;
                const Vec3d x(p.positions()[i]), across = x - up * x.dot(up);
                const double w = double(p.masses()[i]);
                if (pass == 0) {
                    m += w;
                    c += across * w;
                    ++count;
                } else {
                    r2 += w * (across - c / m).lengthSqr();
                }
            }
        }
        if (count < 8) continue;
        z.push_back(0.5 * (z0 + z1));
        b.push_back(std::sqrt(2 * r2 / m));
    }
    if (z.size() < 3) return nan;
    const double n = double(z.size());
    const double sz = std::accumulate(z.begin(), z.end(), 0.0);
    const double sb = std::accumulate(b.begin(), b.end(), 0.0);
    const double szz = std::inner_product(z.begin(), z.end(), z.begin(), 0.0);
    const double szb = std::inner_product(z.begin(), z.end(), b.begin(), 0.0);
    return (n * szb - sz * sb) / (n * szz - sz * sz);
}

} // namespace

GasFlowStats gasFlowStats(const sph::ParticleSet& particles, const GasSettings& settings)
{
    const std::vector<std::size_t> gas = visibleGas(particles);
    GasFlowStats s;
    for (std::size_t i : gas) {
        s.kineticEnergy +=
            0.5 * double(particles.masses()[i]) * double(particles.velocities()[i].lengthSqr());
    }
    s.enstrophy = enstrophyOf(particles, gas, settings.restDensity);
    s.spreadRate = spreadRateOf(particles, gas, Vec3d(settings.buoyancyDirection));
    return s;
}

} // namespace gas
} // namespace ghostfx
