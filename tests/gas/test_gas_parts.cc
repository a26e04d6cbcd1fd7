/// @file   test_gas_parts.cc
/// @brief  The gas step's parts one at a time: temperature (Eqs. 15 - 17), compensation
///         (Eqs. 10, 13, 14) and vorticity (Eqs. 25 - 26) against their formulas and the
///         properties the solver relies on (antisymmetric heat exchange, which method has which
///         term). Tolerances are exact where the formula is evaluated in the same operations.
#include <ghostfx/gas/GasCompensation.h>
#include <ghostfx/gas/GasSolver.h>
#include <ghostfx/gas/GasTemperature.h>
#include <ghostfx/gas/GasVorticity.h>
#include <ghostfx/sph/Kernels.h>

#include <gtest/gtest.h>

#include <vector>

using namespace ghostfx;
using namespace ghostfx::gas;
using sph::Real;
using sph::Vec3;

TEST(GasTemperature, Eq15ExchangeIsAntisymmetricAndFlowsFromHotToCold)
{
    GasSettings s;
    const GasTemperature part(s);
    ASSERT_TRUE(part.diffuses());
    const Real R = s.supportRadius(), m = Real(1e-4), rho = Real(1.02), r = Real(0.3) * R;
    const Vec3 xij(r, 0, 0);
    const Real hot = Real(400), cold = Real(300);
    const double ij = part.pairRate(m, rho, rho, hot, cold, xij, sph::spikyGrad(xij, r, R), r, R);
    const double ji = part.pairRate(m, rho, rho, cold, hot, -xij, sph::spikyGrad(-xij, r, R), r, R);
    // Equal masses and densities: the pair's exchange is exactly antisymmetric, so
    // sum_i m_i T_i is conserved (the solver's heat conservation test measures it over a run).
    EXPECT_EQ(ij, -ji);
    EXPECT_LT(ij, 0.0); // the hotter particle cools
}

TEST(GasTemperature, BuoyancyFollowsEq17AndRadiationOnlyAtTheBoundaryWithoutAir)
{
    GasSettings s;
    s.buoyancyDirection = Vec3(0, 2, 0); // not unit: the part normalises it
    const GasTemperature part(s);
    EXPECT_EQ(part.buoyancy(s.ambientTemperature), Vec3(0));
    const Real T = s.ambientTemperature + Real(80);
    EXPECT_EQ(part.buoyancy(T), s.buoyancy * (T - s.ambientTemperature) * Vec3(0, 1, 0));

    // Eq. 16: dT/dt = -(T - T_ambient) / D_r on boundary particles, nothing inside.
    const Real dt = Real(0.01);
    std::vector<Real> temps{T, T};
    GasTemperature fast(s);
    fast.begin(2);
    fast.setRate(0, 0.0, T, true);
    fast.setRate(1, 0.0, T, false);
    fast.advance(temps, 0, dt);
    fast.advance(temps, 1, dt);
    EXPECT_EQ(temps[0], T + dt * (-(T - s.ambientTemperature) / s.radiationTime));
    EXPECT_EQ(temps[1], T);

    // The ambient baseline simulates the air, so it loses no heat to it.
    s.method = Method::Ambient;
    s.domain = sph::Aabb{Vec3(-1), Vec3(1)};
    GasTemperature ambient(s);
    ambient.begin(1);
    ambient.setRate(0, 0.0, T, true);
    std::vector<Real> one{T};
    ambient.advance(one, 0, dt);
    EXPECT_EQ(one[0], T);
}

TEST(GasCompensation, OnlyTheFastMethodCompensatesAndItsForcesFollowEqs13And14)
{
    GasSettings s;
    s.turbulence = Turbulence::None; // [RYY15] as published: Eq. 14's automatic C_d is 7 /s
    s.interiorPressureScale = Real(0.25);
    GasCompensation part(s);
    ASSERT_TRUE(part.enabled());
    s.method = Method::Uncorrected;
    EXPECT_FALSE(GasCompensation(s).enabled());

    // With n_bar = 0 (no neighbour) Eq. 10 adds nothing and Eq. 13 adds P_a n_i at the
    // boundary, beta P_a n_i inside.
    part.beginDensity(1);
    const Vec3 n(0, 3, 0);
    Vec3 surface(0), inside(0);
    part.addForces(surface, 0, Real(0.1), Real(1), Real(1), n, true);
    part.addForces(inside, 0, Real(0.1), Real(1), Real(1), n, false);
    EXPECT_EQ(surface, s.atmosphericPressure * n);
    EXPECT_EQ(inside, (s.atmosphericPressure * s.interiorPressureScale) * n);

    // Eq. 14: damping -C_d v on boundary particles only.
    const Vec3 v(Real(0.5), 0, 0);
    Vec3 a(0), b(0);
    part.damp(a, v, true);
    part.damp(b, v, false);
    EXPECT_EQ(a, -(s.boundaryDamping() * v));
    EXPECT_EQ(s.boundaryDamping(), Real(7)); // automatic without entrainment
    EXPECT_EQ(GasSettings().boundaryDamping(), Real(0)); // automatic with it (the default)
    EXPECT_EQ(b, Vec3(0));
}

TEST(GasVorticity, ChannelOnlyWhenEnabledAndTheBoundaryGeneratesBetaNCrossG)
{
    GasSettings s;
    sph::ParticleSet off;
    GasVorticity(s).addChannel(off);
    EXPECT_FALSE(off.hasVectorChannel(channel::VORTICITY));

    s.vorticity = true;
    GasVorticity part(s);
    sph::ParticleSet on;
    part.addChannel(on);
    EXPECT_TRUE(on.hasVectorChannel(channel::VORTICITY));

    // No neighbours: no vortex acceleration, and d omega/dt = beta n x g with g = 9.81 m/s^2
    // against the buoyancy direction (the default gas has no weight).
    part.begin(1);
    const Vec3 n(1, 0, 0);
    Vec3 a(0);
    part.finish(0, GasVorticity::Sums{}, n, a);
    EXPECT_EQ(a, Vec3(0));
    std::vector<Vec3> omega{Vec3(0)};
    const Real dt = Real(0.01);
    part.advance(omega, 0, dt);
    const Vec3 g = Real(-9.81) * s.buoyancyDirection.unit();
    EXPECT_EQ(omega[0], dt * (Vec3(0) + s.vorticityGeneration * n.cross(g)));
    EXPECT_GT(omega[0].length(), Real(0));
}
