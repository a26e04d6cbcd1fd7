/// @file   LiquidMeasures.h
/// @brief  Test helper: what the liquid solver tests measure on a particle set.
#pragma once

#include <ghostfx/sph/ParticleSet.h>

#include <algorithm>
#include <functional>
#include <vector>

namespace ghostfx {
namespace testing {

/// Total mass of the liquid particles (kg).
inline double liquidMass(const sph::ParticleSet& p)
{
    double m = 0;
    for (std::size_t i = 0; i < p.size(); ++i) {
        if (p.kinds()[i] == sph::ParticleKind::Liquid) m += p.masses()[i];
    }
    return m;
}

/// Centre of the liquid particles (m).
inline sph::Vec3d liquidCentre(const sph::ParticleSet& p)
{
    sph::Vec3d c(0);
    double n = 0;
    for (std::size_t i = 0; i < p.size(); ++i) {
        if (p.kinds()[i] != sph::ParticleKind::Liquid) continue;
        c += sph::Vec3d(p.positions()[i]);
        n += 1;
    }
    return c / n;
}

/// Mean height (y, m) of the highest tenth of the liquid particles.
inline double topLayerHeight(const sph::ParticleSet& p)
{
    std::vector<double> y;
    for (std::size_t i = 0; i < p.size(); ++i) {
        if (p.kinds()[i] == sph::ParticleKind::Liquid) y.push_back(p.positions()[i][1]);
    }
    const std::size_t top = std::max<std::size_t>(1, y.size() / 10);
    std::nth_element(y.begin(), y.begin() + top, y.end(), std::greater<double>());
    double sum = 0;
    for (std::size_t k = 0; k < top; ++k) sum += y[k];
    return sum / double(top);
}

} // namespace testing
} // namespace ghostfx
