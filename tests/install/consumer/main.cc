// Drives the installed libraries the way a pipeline would: a liquid sphere in memory, one frame
// of Ghost SPH, the particles written as a points .vdb. Exit code 0 only if all of it worked.
#include <ghostfx/ghost/GhostSolver.h>
#include <ghostfx/sph/LevelSetGrid.h>
#include <ghostfx/vdbio/FrameFiles.h>

#include <cstdio>

int main(int argc, char** argv)
{
    if (argc != 2) return 2;
    openvdb::initialize();
    using namespace ghostfx;
    ghost::GhostSettings settings;
    settings.spacing = 0.02f;
    settings.substeps = 5;
    ghost::GhostSolver solver(settings);
    solver.addLiquid(
        sph::makeLevelSet(sph::makeSphereLevelSet(sph::Vec3(0), 0.08f, 0.01f), "ball"));
    solver.advanceFrame();
    vdbio::writePointsFile(argv[1], solver.particles(), vdbio::PointsOptions());
    std::printf("consumer: %zu liquid particles after one frame, written to %s\n",
                solver.count(sph::ParticleKind::Liquid), argv[1]);
    return solver.count(sph::ParticleKind::Liquid) > 0 ? 0 : 1;
}
