/// @file   test_surface_tension.cc
/// @brief  Surface tension (GhostSettings::surfaceTension) against the analytic answers of a
///         free drop: Laplace's pressure jump 2 sigma / R, a cube pulled into a sphere, and
///         Rayleigh's period of a drop's l = 2 oscillation.
#include <ghostfx/ghost/GhostSolver.h>
#include <ghostfx/sph/Exceptions.h>
#include <ghostfx/sph/LevelSetGrid.h>

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

using namespace ghostfx;
using namespace ghostfx::sph;
using namespace ghostfx::ghost;

namespace {

constexpr Real H = Real(0.005);

GhostSettings dropSettings(double sigma)
{
    GhostSettings s;
    s.spacing = H;
    s.pressure = PressureModel::Dfsph;
    s.substeps = 0;
    s.seed = 11;
    s.gravity = Vec3(0);
    s.surfaceTension = Real(sigma);
    return s;
}

Vec3d centreOf(const ParticleSet& p)
{
    Vec3d c(0.0);
    double n = 0;
    for (std::size_t i = 0; i < p.size(); ++i) {
        if (p.kinds()[i] != ParticleKind::Liquid) continue;
        c += Vec3d(p.positions()[i]);
        n += 1;
    }
    return c / n;
}

/// The mean pressure (Pa) of the liquid deeper than `depth` below a drop's surface of radius R.
double innerPressure(const GhostSolver& solver, double R, double depth)
{
    const ParticleSet& p = solver.particles();
    const Vec3d c = centreOf(p);
    double sum = 0, n = 0;
    for (std::size_t i = 0; i < p.size(); ++i) {
        if (p.kinds()[i] != ParticleKind::Liquid) continue;
        if ((Vec3d(p.positions()[i]) - c).length() > R - depth) continue;
        sum += p.pressures()[i];
        n += 1;
    }
    return sum / n;
}

} // namespace

// Laplace: a still drop of radius R in zero gravity holds a pressure 2 sigma / R above the
// air's, within the 10 %, at R = 4 and 6 cm (sigma = 1 N/m: 50 and 33 Pa), its
// interior (deeper than 3 spacings) averaged over the frames of its second tenth of a second.
TEST(SurfaceTension, AStillDropHoldsLaplacesPressureJump)
{
    for (const double R : {0.04, 0.06}) {
        GhostSolver solver(dropSettings(1.0));
        solver.addLiquid(makeLevelSet(makeSphereLevelSet(Vec3(0), Real(R), H / 2), "drop"));
        double sum = 0;
        int frames = 0;
        for (int f = 0; f < 6; ++f) {
            solver.advanceFrame();
            if (f < 3) continue;
            sum += innerPressure(solver, R, 3 * double(H));
            ++frames;
        }
        const double p = sum / frames, laplace = 2 * 1.0 / R;
        std::printf("[measured] drop of R = %.2f m: inner pressure %.2f Pa, Laplace %.2f Pa "
                    "(%+.1f %%)\n",
                    R, p, laplace, 100 * (p / laplace - 1));
        EXPECT_NEAR(p / laplace, 1.0, 0.10) << R;
    }
}

namespace {

/// The spread (m) of a body's extent over 14 directions (the 6 axes and 8 diagonals): in each,
/// the farthest liquid particle within 25 degrees of it from the centre; a cube of side a has
/// 0.366 a, a sphere about none.
double extentSpread(const ParticleSet& p)
{
    const Vec3d c = centreOf(p);
    std::vector<Vec3d> directions;
    for (int a = 0; a < 3; ++a) {
        for (const double s : {-1.0, 1.0}) {
            Vec3d d(0.0);
            d[a] = s;
            directions.push_back(d);
        }
    }
    for (int k = 0; k < 8; ++k) {
        directions.push_back(Vec3d(k & 1 ? 1 : -1, k & 2 ? 1 : -1, k & 4 ? 1 : -1)
                             / std::sqrt(3.0));
    }
    double lo = 1e9, hi = 0;
    for (const Vec3d& d : directions) {
        double farthest = 0;
        for (std::size_t i = 0; i < p.size(); ++i) {
            if (p.kinds()[i] != ParticleKind::Liquid) continue;
            const Vec3d r = Vec3d(p.positions()[i]) - c;
            if (r.dot(d) > std::cos(25 * M_PI / 180) * r.length())
                farthest = std::max(farthest, r.length());
        }
        lo = std::min(lo, farthest);
        hi = std::max(hi, farthest);
    }
    return hi - lo;
}

} // namespace

// A cube of liquid 8 cm on a side in zero gravity becomes a sphere: the spread of its extent
// over 14 directions falls from 2.6 cm (sampled) to below one spacing (the bound),
// taken as its mean over the last 0.3 s of 1.5 s (it rings as it rounds, its l = 4 mode at
// a period of about 0.3 s with sigma = 1 N/m). Measured 2.0 mm.
TEST(SurfaceTension, ACubeInZeroGravityBecomesASphere)
{
    // With sigma = 1 N/m, and without (Ghost SPH keeps the cube's shape, [SB12] Fig. 4: the
    // control that the rounding is the surface tension's, over 0.5 s: the tension rounds the
    // cube's edges within 0.2 s).
    for (const double sigma : {1.0, 0.0}) {
        const int last = sigma > 0 ? 45 : 15;
        GhostSolver solver(dropSettings(sigma));
        solver.addLiquid(makeLevelSet(
            makeBoxLevelSet(Vec3(-0.04f, -0.04f, -0.04f), Vec3(0.04f, 0.04f, 0.04f), H / 2),
            "cube"));
        solver.prepare();
        const double start = extentSpread(solver.particles());
        double sum = 0;
        int frames = 0;
        while (solver.frame() < last) {
            solver.advanceFrame();
            if (solver.frame() <= last - 9) continue;
            sum += extentSpread(solver.particles());
            ++frames;
        }
        const double spread = sum / frames;
        std::printf("[measured] cube of 8 cm, sigma %.0f N/m: extent spread %.4f m at the start, "
                    "%.4f m over the last 0.3 s of %.1f s (spacing %.3f m)\n",
                    sigma, start, spread, solver.time(), double(H));
        EXPECT_GT(start, 0.02);
        if (sigma > 0) {
            EXPECT_LT(spread, double(H));
        } else {
            EXPECT_GT(spread, 0.015);
        }
    }
}

// Rayleigh: a drop of radius R = 5 cm, settled for 0.3 s, is set moving in its l = 2 mode (the
// potential flow v = A (2x, -y, -z), A = 0.4 /s: 2 cm/s at the poles) and oscillates with the
// period 2 pi sqrt(rho R^3 / (8 sigma)) (Rayleigh 1879; 0.785 s at sigma = 1 N/m), within the
// issue's 10 %. The period is read from the times its quadrupole <x^2> - <y^2> crosses zero,
// every step over 1.4 s.
TEST(SurfaceTension, ADropOscillatesWithRayleighsPeriod)
{
    const double R = 0.05, sigma = 1.0, A = 0.4;
    const double rayleigh = 2 * M_PI * std::sqrt(1000 * R * R * R / (8 * sigma));
    GhostSolver solver(dropSettings(sigma));
    solver.addLiquid(makeLevelSet(makeSphereLevelSet(Vec3(0), Real(R), H / 2), "drop"));
    while (solver.time() < 0.3 - 1e-9) solver.advanceFrame();
    {
        ParticleSet& p = solver.particles();
        const Vec3d c = centreOf(p);
        for (std::size_t i = 0; i < p.size(); ++i) {
            if (p.kinds()[i] != ParticleKind::Liquid) continue;
            const Vec3d r = Vec3d(p.positions()[i]) - c;
            p.velocities()[i] = Vec3(Vec3d(2 * r[0], -r[1], -r[2]) * A);
        }
    }
    const double t0 = solver.time();
    std::vector<double> crossings;
    double last = 0, lastTime = -1;
    solver.setStepObserver([&](const GhostSolver& g, Real) {
        const ParticleSet& p = g.particles();
        const Vec3d c = centreOf(p);
        double xx = 0, yy = 0, n = 0;
        for (std::size_t i = 0; i < p.size(); ++i) {
            if (p.kinds()[i] != ParticleKind::Liquid) continue;
            const Vec3d r = Vec3d(p.positions()[i]) - c;
            xx += r[0] * r[0];
            yy += r[1] * r[1];
            n += 1;
        }
        const double q = (xx - yy) / n;
        // The kicked sphere starts at q = 0: crossings in the first tenth of a period are its
        // noise.
        if (lastTime >= 0 && (q > 0) != (last > 0) && g.time() - t0 > 0.1 * rayleigh)
            crossings.push_back(lastTime + (g.time() - lastTime) * last / (last - q));
        last = q;
        lastTime = g.time();
    });
    while (solver.time() < t0 + 1.4) solver.advanceFrame();
    ASSERT_GE(crossings.size(), 3u);
    const double period = crossings[2] - crossings[0];
    std::printf("[measured] drop of R = %.2f m: zero crossings at", R);
    for (double t : crossings) std::printf(" %.3f", t - t0);
    std::printf(" s after the kick; period %.3f s, Rayleigh %.3f s (%+.1f %%)\n", period, rayleigh,
                100 * (period / rayleigh - 1));
    EXPECT_NEAR(period / rayleigh, 1.0, 0.10);
}
