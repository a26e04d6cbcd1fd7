/// @file   test_phase_transition.cc
/// @brief  Liquid-gas phase transition ([RYY15] Sec. 4): a Ghost SPH liquid [SB12] in a heated pan
///         coupled to the fast gas solver through gas::PhaseTransition. Boiling (vapour grows,
///         mass budget closes, the liquid at the heater reaches T_b), evaporation (mass loss
///         proportional to the rate parameter) and the 1000:1 density ratio under violent
///         boiling (finite or a clear NumericalError).
/// @details Scenes are small (a few hundred liquid particles, liquid spacing 1 cm) so the file
///          runs in well under a minute on one core. The liquid-gas density ratio is the paper's
///          1000:1 (water 1000 kg/m^3, vapour 1 kg/m^3, Sec. 6) in every test.
#include "GhostLiquidSide.h"

#include <ghostfx/gas/PhaseTransition.h>
#include <ghostfx/ghost/GhostSolver.h>
#include <ghostfx/sph/Exceptions.h>
#include <ghostfx/sph/LevelSetGrid.h>

#include "common/Shapes.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>
#include <unordered_map>
#include <vector>

using namespace ghostfx;
using namespace ghostfx::sph;

namespace {

constexpr Real H = Real(0.01);            ///< liquid spacing (m)
constexpr Real DT = Real(1) / Real(1200); ///< [SB12] k = 2000 Pa needs about 1/1200 s at 1 cm
constexpr Real A = Real(0.04);            ///< pan half width (m)
constexpr Real DEPTH = Real(0.04);        ///< water depth (m)

/// Open-top pan: walls 4 h thick around the inside [-a, a] x [0, top] x [-a, a].
LevelSet panLevelSet(Real a, Real top)
{
    return makeLevelSet(ghostfx::testing::openTankGrid(a, top, 4 * double(H), H / 2), "pan");
}

/// The pan's bottom plate as a heater.
LevelSet plateLevelSet(Real a)
{
    return makeLevelSet(makeBoxLevelSet(Vec3(-a - 4 * H, -4 * H, -a - 4 * H),
                                        Vec3(a + 4 * H, 0, a + 4 * H), H / 2, Real(8)),
                        "hot plate"); // band 4 cm: phi exact out to the heater band
}

/// Gas settings matched to the liquid: spacing so that a boiling daughter (1/12 of a liquid
/// particle) has about the gas reference mass at rho0 = 1 kg/m^3 (1/1000 of the water).
gas::GasSettings vapourSettings()
{
    gas::GasSettings g;
    g.spacing = H * Real(std::cbrt(1000.0 / 12.0));
    g.restDensity = Real(1);
    g.lifeStrength = Real(0); // nothing removed: the mass budget must close without a ledger
    g.seed = 3;
    return g;
}

struct Scene
{
    ghost::GhostSolver liquid;
    coupling::GhostLiquidSide side;
    gas::GasSolver vapour;
    std::unique_ptr<gas::PhaseTransition> coupler;

    Scene(const gas::PhaseSettings& phase, const gas::GasSettings& gasSettings)
        : liquid(liquidSettings())
        , side(liquid)
        , vapour(gasSettings)
    {
        liquid.addSolid(panLevelSet(A, Real(0.1)));
        liquid.addLiquid(
            makeLevelSet(makeBoxLevelSet(Vec3(-A, 0, -A), Vec3(A, DEPTH, A), H / 2), "water"));
        coupler = std::make_unique<gas::PhaseTransition>(vapour, side, phase);
    }

    static ghost::GhostSettings liquidSettings()
    {
        ghost::GhostSettings s;
        s.spacing = H;
        s.seed = 11;
        return s;
    }

    std::size_t liquidCount() const { return liquid.count(ParticleKind::Liquid); }
};

bool allGasFinite(const gas::GasSolver& g)
{
    const ParticleSet& p = g.particles();
    for (std::size_t i = 0; i < p.size(); ++i) {
        if (!isFinite(p.positions()[i]) || !isFinite(p.velocities()[i])
            || !std::isfinite(p.densities()[i])) {
            return false;
        }
    }
    return true;
}

} // namespace

// Test 6: boiling in a heated pan -------------------------------------------------------------------

TEST(PhaseTransition, BoilingPanMakesVapourConservesMassAndReachesBoilingPoint)
{
    gas::PhaseSettings phase;
    phase.initialTemperature = Real(368.15); // pre-heated to 95 C so the test boils in 0.3 s
    phase.latentHeat = Real(40);             // smaller L/c_p (water: 540 K) for the same reason
    phase.heatingTime = Real(0.05);
    phase.heaterBand = Real(1.5) * H;
    phase.evaporationRate = Real(0); // boiling only
    Scene scene(phase, vapourSettings());
    scene.coupler->addHeater(plateLevelSet(A), Real(393.15));

    scene.coupler->step(DT); // first step: the liquid's mass scaling ([SB12] Sec. 4.6)
    const gas::MassBudget start = scene.coupler->massBudget();
    const std::size_t liquid0 = scene.liquidCount();
    std::size_t vapourEarly = 0;
    const int steps = 360; // 0.3 s
    for (int k = 1; k < steps; ++k) {
        scene.coupler->step(DT);
        if (k == steps / 2) vapourEarly = scene.vapour.visibleGasCount();
    }
    const gas::MassBudget end = scene.coupler->massBudget();
    const std::size_t vapourLate = scene.vapour.visibleGasCount();

    // Temperature of the liquid near the plate.
    const ParticleSet& p = scene.liquid.particles();
    const auto& T = p.scalarChannel(gas::PhaseTransition::TEMPERATURE);
    const LevelSet plate = plateLevelSet(A);
    double maxNearT = 0, sumFarT = 0, nFar = 0;
    for (std::size_t i = 0; i < p.size(); ++i) {
        if (p.kinds()[i] != ParticleKind::Liquid) continue;
        if (plate.phi(p.positions()[i]) < phase.heaterBand)
            maxNearT = std::max(maxNearT, double(T[i]));
        else {
            sumFarT += T[i];
            nFar += 1;
        }
    }
    const double relMass = std::abs(end.total() - start.total()) / start.total();
    std::printf("[measured] boiling: liquid %zu -> %zu particles, boiled %zu, vapour particles "
                "%zu at 0.15 s, %zu at 0.3 s, vapour mass %.4e kg (%.2f %% of water), mass "
                "budget drift %.2e relative (liquid %.6e + gas %.6e kg), max T near plate "
                "%.3f K, mean T elsewhere %.2f K, coarse boundary %zu particles\n",
                liquid0, scene.liquidCount(), scene.coupler->boiledCount(), vapourEarly, vapourLate,
                end.gas, 100 * end.gas / start.total(), relMass, end.liquid, end.gas, maxNearT,
                nFar > 0 ? sumFarT / nFar : 0.0, scene.coupler->boundaryCount());

    EXPECT_GT(scene.coupler->boiledCount(), 0u);
    EXPECT_GT(vapourEarly, 0u);
    EXPECT_GT(scene.liquidCount(), 0u); // boiling takes time: the pan still holds water
    EXPECT_GT(vapourLate, vapourEarly); // vapour count grows over time
    // Mass conservation: every transfer moves Real masses whose rounding residual is put back on
    // a daughter (SplitMerge.h), and budgets are summed in double; a few thousand float
    // roundings of 6e-8 each stay far below 1e-5 relative. Float and double builds alike.
    EXPECT_LT(relMass, 1e-5);
    // Nothing leaves the domain in 0.3 s: the gas removed (kill box, life strength) is nil up to
    // round-off (the double build measured 6.8e-16 kg, i.e. 4e-15 relative).
    EXPECT_LT(end.gasRemoved, 1e-9 * start.total());
    // The liquid at the plate reaches T_b: heat above it is latent (T clamped at T_b exactly).
    EXPECT_NEAR(maxNearT, double(phase.boilingPoint), 1e-3);
    EXPECT_TRUE(allGasFinite(scene.vapour));
}

// Newborn vapour: a rest neighbour count at birth, then expansion to the gas density ---------------

namespace {

/// Per gas particle of `g`: the particles (gas and boundary, itself included) within the pair
/// support (h_i + h_j) / 2, as the gas density sums them. Brute force.
std::vector<int> neighbourCounts(const gas::GasSolver& g)
{
    const ParticleSet& p = g.particles();
    const auto& h = p.scalarChannel(gas::channel::SUPPORT);
    std::vector<int> counts(p.size(), 0);
    for (std::size_t i = 0; i < p.size(); ++i) {
        if (p.kinds()[i] != ParticleKind::Gas) continue;
        for (std::size_t j = 0; j < p.size(); ++j) {
            const Real R = Real(0.5) * (h[i] + h[j]);
            counts[i] += (p.positions()[i] - p.positions()[j]).lengthSqr() < R * R;
        }
    }
    return counts;
}

double median(std::vector<double> v)
{
    if (v.empty()) return 0;
    std::nth_element(v.begin(), v.begin() + v.size() / 2, v.end());
    return v[v.size() / 2];
}

} // namespace

TEST(PhaseTransition, NewbornVapourHasARestNeighbourCountThenExpandsToTheGasDensity)
{
    // The reference: interior particles of a block of the same gas at rest.
    const gas::GasSettings gs = vapourSettings();
    double restCount = 0;
    {
        gas::GasSolver block(gs);
        const Real side = 10 * gs.spacing;
        block.addGas(makeLevelSet(makeBoxLevelSet(Vec3(0), Vec3(side), gs.spacing / 2), "block"),
                     Vec3(0), gs.ambientTemperature);
        block.step(Real(1e-5));
        const std::vector<int> counts = neighbourCounts(block);
        const ParticleSet& p = block.particles();
        const Real margin = gs.supportRadius(); // a full support inside
        double sum = 0, n = 0;
        for (std::size_t i = 0; i < p.size(); ++i) {
            const Vec3& x = p.positions()[i];
            bool inside = true;
            for (int a = 0; a < 3; ++a) inside = inside && x[a] > margin && x[a] < side - margin;
            if (!inside) continue;
            sum += counts[i];
            n += 1;
        }
        ASSERT_GT(n, 10);
        restCount = sum / n;
    }

    gas::PhaseSettings phase;
    phase.initialTemperature = Real(368.15); // the boiling pan of the test above
    phase.latentHeat = Real(40);
    phase.heatingTime = Real(0.05);
    phase.heaterBand = Real(1.5) * H;
    phase.evaporationRate = Real(0);
    Scene scene(phase, gs);
    scene.coupler->addHeater(plateLevelSet(A), Real(393.15));
    scene.coupler->step(DT);

    const double rho0 = double(gs.restDensity);
    const double hGas = double(gs.supportRadius());
    std::unordered_map<ParticleId, int> born; // id -> step of birth
    std::vector<double> birthCounts, birthRho, expandSteps;
    std::unordered_map<ParticleId, int> expanded; // id -> steps to reach h_rest
    double maxAllMean = 0;
    const int steps = 360;
    for (int k = 1; k < steps; ++k) {
        scene.coupler->step(DT);
        const ParticleSet& g = scene.vapour.particles();
        const auto& h = g.scalarChannel(gas::channel::SUPPORT);
        const double mRef = double(scene.vapour.referenceParticleMass());
        std::vector<int> counts;
        bool newborn = false;
        for (std::size_t i = 0; i < g.size(); ++i) {
            newborn = newborn || (g.kinds()[i] == ParticleKind::Gas && !born.count(g.ids()[i]));
        }
        if (newborn || k % 20 == 0) counts = neighbourCounts(scene.vapour);
        double sum = 0, n = 0;
        for (std::size_t i = 0; i < g.size(); ++i) {
            if (g.kinds()[i] != ParticleKind::Gas) continue;
            const ParticleId id = g.ids()[i];
            if (!counts.empty()) {
                sum += counts[i];
                n += 1;
            }
            auto b = born.find(id);
            if (b == born.end()) {
                // The density pass of this step saw the particle once: its count and density at
                // birth.
                born.emplace(id, k);
                birthCounts.push_back(counts[i]);
                birthRho.push_back(double(g.densities()[i]) / rho0);
                continue;
            }
            const double hRest = hGas * std::cbrt(double(g.masses()[i]) / mRef);
            if (!expanded.count(id) && double(h[i]) >= 0.999 * hRest) {
                expanded.emplace(id, k - b->second);
                expandSteps.push_back(k - b->second);
            }
        }
        if (n > 0) maxAllMean = std::max(maxAllMean, sum / n);
    }
    ASSERT_GT(birthCounts.size(), 100u);
    double meanBirth = 0, maxBirth = 0;
    for (double c : birthCounts) {
        meanBirth += c / double(birthCounts.size());
        maxBirth = std::max(maxBirth, c);
    }
    const double stillSmall = double(born.size() - expanded.size()) / double(born.size());
    std::printf("[measured] newborn vapour: %zu particles born; neighbours at birth mean %.1f, "
                "median %.0f, max %.0f (gas at rest: %.1f); density at birth median %.0f rho0; "
                "mean neighbours over all vapour at most %.1f; steps to reach the rest support: "
                "median %.0f (%.1f ms), %.1f %% not yet there after 0.3 s\n",
                born.size(), meanBirth, median(birthCounts), maxBirth, restCount, median(birthRho),
                maxAllMean, median(expandSteps), 1000 * median(expandSteps) * double(DT),
                100 * stillSmall);
    // Sized for its birth density (the liquid's), a newborn particle sees about the neighbours
    // of a gas at rest (measured 18.5 on average, at most 34, against 25.0). Bounds: mean within
    // 2x the rest count, every particle within 4x. Sized for the gas at rest, as before this
    // test, the same run measured 301 on average and 448 at most (and the boiling bench 1,321).
    EXPECT_LT(meanBirth, 2 * restCount);
    EXPECT_LT(maxBirth, 4 * restCount);
    EXPECT_LT(maxAllMean, 2 * restCount);
    // It is born at about the liquid's density (1000 rho0) and then expands: most vapour reaches
    // its rest support within the run.
    EXPECT_GT(median(birthRho), 100.0);
    EXPECT_LT(stillSmall, 0.5);
}

// Evaporation: a bath below boiling loses mass at a rate proportional to the parameter -----------

namespace {

struct EvaporationRun
{
    double vapourMass = 0; ///< kg handed to the gas
    double rate = 0;       ///< kg/s over the measured window
    double predicted = 0;  ///< kg/s from the surface count at the start of the window
    double liquidLoss = 0; ///< fraction of the water's mass lost
    double drift = 0;      ///< relative mass budget drift
    std::size_t splits = 0, merges = 0, vapourParticles = 0;
};

EvaporationRun runBath(Real rate)
{
    gas::PhaseSettings phase;
    phase.initialTemperature = Real(353.15); // 80 C: f(T) = (353.15 - 273.15) / 100 = 0.8
    phase.evaporationRate = rate;
    Scene scene(phase, vapourSettings());
    scene.coupler->step(DT);
    const gas::MassBudget start = scene.coupler->massBudget();
    const double created0 = scene.coupler->vapourMassCreated();
    const int steps = 480; // 0.4 s
    for (int k = 0; k < steps; ++k) scene.coupler->step(DT);
    const gas::MassBudget end = scene.coupler->massBudget();
    EvaporationRun r;
    r.vapourMass = scene.coupler->vapourMassCreated() - created0;
    r.rate = r.vapourMass / (steps * double(DT));
    r.liquidLoss = (start.liquid - end.liquid) / start.liquid;
    r.drift = std::abs(end.total() - start.total()) / start.total();
    r.splits = scene.coupler->evaporatedCount();
    r.merges = scene.coupler->mergeCount();
    r.vapourParticles = scene.vapour.visibleGasCount();
    return r;
}

} // namespace

TEST(PhaseTransition, EvaporationRateIsProportionalToTheParameter)
{
    const EvaporationRun slow = runBath(Real(5));
    const EvaporationRun fast = runBath(Real(10));
    const double ratio = fast.rate / slow.rate;
    std::printf("[measured] evaporation at 80 C: rate 5 /s -> %.3e kg/s (%zu splits, %zu merges, "
                "%zu vapour particles, liquid lost %.3f %%, drift %.1e); rate 10 /s -> %.3e kg/s "
                "(%zu splits, %zu merges, liquid lost %.3f %%, drift %.1e); ratio %.3f\n",
                slow.rate, slow.splits, slow.merges, slow.vapourParticles, 100 * slow.liquidLoss,
                slow.drift, fast.rate, fast.splits, fast.merges, 100 * fast.liquidLoss, fast.drift,
                ratio);
    EXPECT_GT(slow.splits, 0u);
    // Deterministic accumulators: each surface particle splits floor(rate f t) times, so doubling
    // the rate doubles the splits up to one split per surface particle of quantisation and the
    // slowly changing surface set; 10 % covers both (measured ratio printed above).
    EXPECT_NEAR(ratio, 2.0, 0.2);
    // Slow: with the paper's 0.8 % of a particle per split the bath loses a few per cent at most.
    EXPECT_LT(fast.liquidLoss, 0.05);
    EXPECT_GT(slow.liquidLoss, 0.0);
    EXPECT_LT(slow.drift, 1e-5);
    EXPECT_LT(fast.drift, 1e-5);
}

// Test 7 (extremes): 1000:1 at the phase change under violent boiling -----------------------------

TEST(PhaseTransition, ViolentBoilingAtDensityRatio1000StaysFiniteOrFailsClearly)
{
    gas::PhaseSettings phase;
    phase.initialTemperature = Real(373.15); // the whole pan at T_b
    phase.latentHeat = Real(0);              // every particle that reaches T_b boils at once
    phase.heatingTime = Real(0.01);
    phase.heaterBand = Real(3) * H;
    phase.evaporationRate = Real(20);
    Scene scene(phase, vapourSettings());
    scene.coupler->addHeater(plateLevelSet(A), Real(473.15));
    scene.coupler->step(DT);
    const double m0 = scene.coupler->massBudget().total();
    double maxRatio = 0, maxSpeed = 0;
    int done = 0;
    std::string error;
    try {
        for (; done < 240; ++done) {
            scene.coupler->step(DT);
            const ParticleSet& g = scene.vapour.particles();
            for (std::size_t i = 0; i < g.size(); ++i) {
                if (g.kinds()[i] == ParticleKind::Gas) {
                    maxRatio =
                        std::max(maxRatio, double(g.densities()[i])
                                               / double(scene.vapour.settings().restDensity));
                    maxSpeed = std::max(maxSpeed, double(g.velocities()[i].length()));
                }
            }
        }
    } catch (const NumericalError& e) {
        error = e.what();
    }
    const double drift = std::abs(scene.coupler->massBudget().total() - m0) / m0;
    std::printf("[measured] violent boiling 1000:1: %d steps, boiled %zu of the liquid, %zu "
                "vapour particles, max gas rho / rho0 %.1f, max vapour speed %.2f m/s, mass "
                "drift %.1e, %s\n",
                done, scene.coupler->boiledCount(), scene.vapour.visibleGasCount(), maxRatio,
                maxSpeed, drift, error.empty() ? "no error" : error.c_str());
    if (!error.empty()) {
        // A blow-up must say where and what to change.
        EXPECT_NE(error.find("blew up"), std::string::npos) << error;
    } else {
        EXPECT_TRUE(allGasFinite(scene.vapour));
        EXPECT_GT(scene.coupler->boiledCount(), 0u);
        EXPECT_LT(drift, 1e-5);
        // Plausible, not only finite (issue 18): a liquid particle turning into vapour at
        // 1000:1 swells from one liquid spacing to about ten; spread over the heating time
        // that is (10 - 1) H / 0.01 s = 9 m/s. Measured 4.5 m/s; bound 10 m/s. (The newborn
        // vapour has the liquid's density, up to 2,117 rho0 here, with a support sized for it:
        // the test above.)
        EXPECT_LT(maxSpeed, 10.0);
    }
}

TEST(PhaseTransition, SettingsAreValidated)
{
    gas::PhaseSettings s;
    s.heatingTime = Real(0);
    EXPECT_THROW(s.validate(), ValueError);
    s = gas::PhaseSettings();
    s.evaporationOnset = Real(400);
    EXPECT_THROW(s.validate(), ValueError);
    s = gas::PhaseSettings();
    s.evaporationPattern = gas::icosahedronPattern(); // no centre daughter to stay liquid
    EXPECT_THROW(s.validate(), ValueError);
}
