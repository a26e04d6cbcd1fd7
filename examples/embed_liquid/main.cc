/// @file   main.cc
/// @brief  Embedding the Ghost SPH liquid solver [SB12]: a liquid block collapses in an open tank.
/// @details Builds the tank and the block from level sets, runs N frames with advanceFrame() and
///          prints per frame the liquid count, the centre-of-mass height and the largest speed.
///          Run: embed_liquid [frames]   (default 20 frames = 2/3 s at 30 frames/s)
#include <ghostfx/ghost/GhostSolver.h>
#include <ghostfx/sph/Exceptions.h>
#include <ghostfx/sph/LevelSetGrid.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>

using namespace ghostfx;
using namespace ghostfx::sph;
using openvdb::Vec3d;

int main(int argc, char** argv)
{
    const int frames = argc > 1 ? std::atoi(argv[1]) : 20;
    if (frames < 1) {
        std::fprintf(stderr, "embed_liquid: frames '%s': expected a whole number >= 1\n", argv[1]);
        return 1;
    }
    try {
        openvdb::initialize();
        ghost::GhostSettings settings; // [SB12] defaults: k = 2000 Pa, 20 steps/frame at 30 fps
        settings.spacing = Real(0.02); // h (m); a kernel radius is 3 h
        const double h = settings.spacing, wall = 3 * h; // walls one kernel radius thick

        // Open-top tank, inside [0, 0.4] x [0, 0.6] x [0, 0.2] m: outer box minus an inner box
        // that reaches above the rim.
        const Vec3d in0(0, 0, 0), in1(0.4, 0.6, 0.2), out0 = in0 - Vec3d(wall);
        const Vec3d out1(in1.x() + wall, in1.y(), in1.z() + wall), cut1 = in1 + Vec3d(0, 1, 0);
        auto tankSdf = [=](const Vec3d& x) {
            return std::max(boxSignedDistance(x, out0, out1), -boxSignedDistance(x, in0, cut1));
        };
        const Aabb tankBox{Vec3(out0.x(), out0.y(), out0.z()), Vec3(out1.x(), out1.y(), out1.z())};
        const LevelSet tank = makeLevelSet(levelSetFromSdf(tankSdf, tankBox, Real(h / 2)), "tank");

        // Liquid block 0.15 x 0.3 x 0.2 m in the corner (addLiquid keeps h / 2 from the walls).
        const Vec3 lo{Real(0)}, hi{Real(0.15), Real(0.3), Real(0.2)};
        const LevelSet water = makeLevelSet(makeBoxLevelSet(lo, hi, Real(h / 2)), "water");

        const auto start = std::chrono::steady_clock::now();
        ghost::GhostSolver solver(settings);
        solver.addSolid(tank);   // ghost solid particles, one kernel radius deep
        solver.addLiquid(water); // Poisson-disk sampled and relaxed
        std::printf("set-up %.2f s: %zu liquid, %zu ghost solid particles\n",
                    std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(),
                    solver.count(ParticleKind::Liquid), solver.count(ParticleKind::GhostSolid));

        std::printf("frame  time(s)  liquid  ghost_air  com_height(m)  max_speed(m/s)\n");
        for (int f = 1; f <= frames; ++f) {
            solver.advanceFrame();
            const ParticleSet& p = solver.particles();
            double height = 0, maxSpeed = 0;
            for (std::size_t i = 0; i < p.size(); ++i) {
                if (p.kinds()[i] != ParticleKind::Liquid) continue;
                height += p.positions()[i][1];
                maxSpeed = std::max(maxSpeed, double(p.velocities()[i].length()));
            }
            const std::size_t liquid = solver.count(ParticleKind::Liquid);
            std::printf("%5d  %7.3f  %6zu  %9zu  %13.4f  %14.3f\n", f, solver.time(), liquid,
                        solver.count(ParticleKind::GhostAir), height / double(liquid), maxSpeed);
        }
        std::printf("total %.2f s, %.1f ms per step\n",
                    std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(),
                    1e3 * solver.timings().total / double(solver.timings().steps));
    } catch (const ghostfx::Error& e) { // libraries throw; only main exits (STYLE.md rule 7)
        std::fprintf(stderr, "embed_liquid: error: %s\n", e.what());
        return 1;
    }
    return 0;
}
