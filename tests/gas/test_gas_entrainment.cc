/// @file   test_gas_entrainment.cc
/// @brief  Ambient air entrained at the gas boundary (GasEntrainment.h): a steady plume widens
///         at Morton, Taylor and Turner's rate instead of rising as a column, at two spacings.
#include <ghostfx/gas/GasFlowStats.h>
#include <ghostfx/gas/GasSolver.h>
#include <ghostfx/sph/Exceptions.h>
#include <ghostfx/sph/LevelSetGrid.h>

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <string>
#include <utility>
#include <vector>

using namespace ghostfx;
using namespace ghostfx::sph;
using namespace ghostfx::gas;

namespace {

/// A steady plume from a burner: the examples/gas_plume scene (a sphere burner blowing 0.4 m/s,
/// its centre 12 cm above a floor) in a 3.4 m tall kill box, 5 s at 30 frames per second.
struct Plume
{
    Real spacing = Real(0.03);
    Real entrainment = Real(0.12);
    Real temperature = Real(600); ///< K
    Real radius = Real(0.1);      ///< of the burner (m)
    Method method = Method::Fast;
};

/// What a plume measured over the frames from 4 to 5 s, in 10 cm height bins from 1 to 3 m (5 to
/// 15 burner diameters): the top-hat radius b(z) = sqrt(2) r_rms (r_rms the mass-weighted RMS
/// distance from the bin's centre of mass in the horizontal plane: a uniform disc of radius b
/// has r_rms = b / sqrt(2)), the mass-weighted mean vertical velocity w and excess temperature
/// dT (the top-hat buoyancy is C_b dT); the slope db/dz and virtual origin z_v of the
/// least-squares line b = db/dz (z - z_v), and the exponents of w and dT in (z - z_v).
struct Spread
{
    std::vector<double> z, b, w, dT;
    double slope = 0, origin = 0, wExponent = 0, dTExponent = 0;
};

/// The least-squares slope and intercept of y over x.
std::pair<double, double> fitLine(const std::vector<double>& x, const std::vector<double>& y)
{
    double sx = 0, sy = 0, sxx = 0, sxy = 0;
    const double n = double(x.size());
    for (std::size_t k = 0; k < x.size(); ++k) {
        sx += x[k];
        sy += y[k];
        sxx += x[k] * x[k];
        sxy += x[k] * y[k];
    }
    const double slope = (n * sxy - sx * sy) / (n * sxx - sx * sx);
    return {slope, (sy - slope * sx) / n};
}

/// One frame's bins added to `sums` (b^2, w, dT for each bin, in that order).
void addBins(const ParticleSet& p, std::vector<double>& sums)
{
    const auto& T = p.scalarChannel(channel::TEMPERATURE);
    for (std::size_t k = 0; 3 * k < sums.size(); ++k) {
        const double lo = 1.0 + 0.1 * double(k), hi = lo + 0.1;
        double m = 0, mx = 0, mz = 0, mr2 = 0, mw = 0, mT = 0;
        for (int pass = 0; pass < 2; ++pass) {
            for (std::size_t i = 0; i < p.size(); ++i) {
                const Vec3& x = p.positions()[i];
                if (p.kinds()[i] != ParticleKind::Gas || x[1] < lo || x[1] >= hi) continue;
                const double w = double(p.masses()[i]);
                if (pass == 0) {
                    m += w;
                    mx += w * x[0];
                    mz += w * x[2];
                    mw += w * p.velocities()[i][1];
                    mT += w * (double(T[i]) - 293.15);
                    continue;
                }
                const double dx = x[0] - mx / m, dz = x[2] - mz / m;
                mr2 += w * (dx * dx + dz * dz);
            }
        }
        if (!(m > 0)) continue;
        sums[3 * k] += 2 * mr2 / m;
        sums[3 * k + 1] += mw / m;
        sums[3 * k + 2] += mT / m;
    }
}

Spread measure(const Plume& plume)
{
    GasSettings s;
    s.spacing = plume.spacing;
    s.substeps = 2;
    s.seed = 1;
    s.entrainment = plume.entrainment;
    s.method = plume.method;
    s.domain = Aabb{Vec3(-1.2f, -0.05f, -1.2f), Vec3(1.2f, 3.4f, 1.2f)};
    GasSolver solver(s);
    solver.addSolid(makeLevelSet(
        makeBoxLevelSet(Vec3(-1.2f, -0.15f, -1.2f), Vec3(1.2f, 0, 1.2f), plume.spacing / 2),
        "floor"));
    GasSource burner;
    burner.temperature = plume.temperature;
    burner.velocity = Vec3(0, Real(0.4), 0);
    solver.addSource(
        makeLevelSet(makeSphereLevelSet(Vec3(0, Real(0.12), 0), plume.radius, plume.spacing / 2),
                     "burner"),
        burner);
    constexpr int BINS = 20;
    std::vector<double> sums(3 * BINS, 0.0);
    int frames = 0;
    for (int f = 1; f <= 150; ++f) {
        solver.advanceFrame();
        if (f < 120) continue;
        addBins(solver.particles(), sums);
        ++frames;
    }
    Spread out;
    for (int k = 0; k < BINS; ++k) {
        out.z.push_back(1.05 + 0.1 * k);
        out.b.push_back(std::sqrt(sums[std::size_t(3 * k)] / frames));
        out.w.push_back(sums[std::size_t(3 * k + 1)] / frames);
        out.dT.push_back(sums[std::size_t(3 * k + 2)] / frames);
    }
    const auto [slope, intercept] = fitLine(out.z, out.b);
    out.slope = slope;
    out.origin = -intercept / slope;
    std::vector<double> lz, lw, lT;
    for (int k = 0; k < BINS; ++k) {
        lz.push_back(std::log(out.z[std::size_t(k)] - out.origin));
        lw.push_back(std::log(std::max(out.w[std::size_t(k)], 1e-9)));
        lT.push_back(std::log(std::max(out.dT[std::size_t(k)], 1e-9)));
    }
    out.wExponent = fitLine(lz, lw).first;
    out.dTExponent = fitLine(lz, lT).first;
    return out;
}

void print(const char* what, const Spread& s)
{
    std::printf("[measured] %s: db/dz = %.3f, virtual origin %.2f m, w ~ (z - z_v)^%.2f, dT ~ "
                "(z - z_v)^%.2f; z, b, w, dT:",
                what, s.slope, s.origin, s.wExponent, s.dTExponent);
    for (std::size_t k = 0; k < s.z.size(); k += 4)
        std::printf(" %.2f m %.3f m %.2f m/s %.0f K;", s.z[k], s.b[k], s.w[k], s.dT[k]);
    std::printf("\n");
}

} // namespace

// Morton, Taylor and Turner (1956): a plume entraining still air at alpha w through its edge has
// a top-hat radius b = (6/5) alpha (z - z_v), a velocity w ~ (z - z_v)^(-1/3) and a buoyancy
// ~ (z - z_v)^(-5/3). The air-free gas without entrainment rises as a column. With alpha = 0.12
// (and so no boundary damping), over 5 to 15 burner diameters: db/dz within 0.08 to 0.16, the
// range of measured plumes; both exponents within 30 % of MTT's (the bounds); for three
// sources (600 K and 400 K from the 10 cm burner, 600 K from a 7 cm one) each at 4 and 3 cm
// spacing (2.4 times the particles), db/dz within 25 % of its value at the other spacing; and
// with the uncorrected baseline ([RYY15]'s ablation). Measured db/dz 0.083-0.126 (docs/study.md),
// below MTT's 0.144 at this alpha: a particle's own speed along the boundary, which draws the
// air in here, is below the plume's top-hat speed.
TEST(GasEntrainment, APlumeSpreadsAndSlowsAsMttSayWhateverTheSpacing)
{
    const Spread column = measure(Plume{Real(0.04), Real(0)});
    print("plume without entrainment, 4 cm", column);
    EXPECT_LT(std::abs(column.slope), 0.03);
    struct Run
    {
        const char* name;
        Plume plume;
    };
    const Real alpha = Real(0.12);
    const Run runs[] = {
        {"600 K, 10 cm burner, 4 cm", {Real(0.04), alpha}},
        {"600 K, 10 cm burner, 3 cm", {Real(0.03), alpha}},
        {"400 K, 10 cm burner, 4 cm", {Real(0.04), alpha, Real(400)}},
        {"400 K, 10 cm burner, 3 cm", {Real(0.03), alpha, Real(400)}},
        {"600 K, 7 cm burner, 4 cm", {Real(0.04), alpha, Real(600), Real(0.07)}},
        {"600 K, 7 cm burner, 3 cm", {Real(0.03), alpha, Real(600), Real(0.07)}},
        {"uncorrected, 600 K, 10 cm burner, 4 cm",
         {Real(0.04), alpha, Real(600), Real(0.1), Method::Uncorrected}}};
    std::vector<double> slopes;
    for (const Run& run : runs) {
        const Spread spread = measure(run.plume);
        print(run.name, spread);
        EXPECT_GE(spread.slope, 0.08) << run.name;
        EXPECT_LE(spread.slope, 0.16) << run.name;
        EXPECT_NEAR(spread.wExponent, -1.0 / 3, 0.3 / 3) << run.name;
        EXPECT_NEAR(spread.dTExponent, -5.0 / 3, 0.3 * 5 / 3) << run.name;
        slopes.push_back(spread.slope);
    }
    for (std::size_t k = 0; k < 6; k += 2) {
        const std::string source(runs[k].name);
        std::printf("[measured] %s: db/dz at 3 cm / at 4 cm = %.3f\n",
                    source.substr(0, source.rfind(',')).c_str(), slopes[k + 1] / slopes[k]);
        EXPECT_NEAR(slopes[k + 1] / slopes[k], 1.0, 0.25) << runs[k].name;
    }
}

// The ambient baseline simulates the air it would draw in: "auto" gives it no turbulence model,
// and entrainment is refused.
TEST(GasEntrainment, TheAmbientBaselineRefusesIt)
{
    GasSettings s;
    s.method = Method::Ambient;
    s.domain = Aabb{Vec3(-1), Vec3(1)};
    EXPECT_EQ(s.turbulenceInUse(), Turbulence::None); // "auto"
    EXPECT_EQ(s.entrainmentInUse(), Real(0));
    EXPECT_EQ(s.boundaryDamping(), Real(7));
    s.turbulence = Turbulence::Entrainment;
    try {
        s.validate();
        ADD_FAILURE() << "the ambient baseline took entrainment";
    } catch (const ValueError& e) {
        EXPECT_EQ(std::string(e.what()),
                  "gas setting turbulence = 'entrainment' with method 'ambient': expected 'none' "
                  "or 'auto' (the ambient baseline simulates the air it would draw in)");
    }
    GasSettings bad;
    bad.entrainment = Real(1.5);
    EXPECT_THROW(bad.validate(), ValueError);
}

namespace {

/// A thermal's centroid height (m) and radius R = sqrt(5/3 <|x - c|^2>) (m, mass-weighted: a
/// uniform ball of radius R has <|x - c|^2> = 3/5 R^2) at time t (s).
struct ThermalSample
{
    double t, z, R;
};

std::vector<ThermalSample> thermal(Real spacing, Real entrainment, Real temperature)
{
    GasSettings s;
    s.spacing = spacing;
    s.substeps = 2;
    s.seed = 1;
    s.entrainment = entrainment;
    s.domain = Aabb{Vec3(-1.5f, -0.05f, -1.5f), Vec3(1.5f, 5.0f, 1.5f)};
    GasSolver solver(s);
    solver.addGas(
        makeLevelSet(makeSphereLevelSet(Vec3(0, Real(0.3), 0), Real(0.1), spacing / 2), "thermal"),
        Vec3(0), temperature);
    std::vector<ThermalSample> out;
    for (int f = 1; f <= 66; ++f) {
        solver.advanceFrame();
        if (f % 6) continue;
        const ParticleSet& p = solver.particles();
        double m = 0;
        openvdb::math::Vec3<double> c(0.0);
        for (std::size_t i = 0; i < p.size(); ++i) {
            if (p.kinds()[i] != ParticleKind::Gas) continue;
            m += double(p.masses()[i]);
            c += openvdb::math::Vec3<double>(p.positions()[i]) * double(p.masses()[i]);
        }
        c /= m;
        double r2 = 0;
        for (std::size_t i = 0; i < p.size(); ++i) {
            if (p.kinds()[i] != ParticleKind::Gas) continue;
            r2 += double(p.masses()[i])
                  * (openvdb::math::Vec3<double>(p.positions()[i]) - c).lengthSqr();
        }
        out.push_back({solver.time(), c[1], std::sqrt(5.0 / 3.0 * r2 / m)});
    }
    return out;
}

} // namespace

// A thermal (a 10 cm ball of gas at 600 K released at rest) entraining air grows with its radius
// proportional to its height, R = e (z - z_v), and rises as (t - t_v)^(1/2) (MTT 1956: its
// buoyancy is conserved, so w ~ (z - z_v)^-1). Scorer 1957 measured e about 0.25: the bound is a
// factor 1.5 either way, that constant being less certain than the exponents; the time exponent
// (from w ~ (z - z_v)^n: z ~ t^(1 / (1 - n))) within 30 % of 1/2. Fitted from 0.8 to 2 s (the
// ball rolls up into a thermal in the first 0.6 s), at 3 and 2 cm spacing. Measured e 0.184 and
// 0.207, z ~ t^0.56 at both. Without entrainment it keeps its size.
TEST(GasEntrainment, AThermalGrowsWithItsHeightAndRisesAsTheSquareRootOfTime)
{
    for (Real spacing : {Real(0.03), Real(0.02)}) {
        const std::vector<ThermalSample> column = thermal(spacing, Real(0), Real(600));
        const std::vector<ThermalSample> grown = thermal(spacing, Real(0.12), Real(600));
        std::vector<double> z, R, logZ, logW;
        for (std::size_t k = 1; k + 1 < grown.size(); ++k) {
            if (grown[k].t < 0.79 || grown[k].t > 2.01) continue;
            z.push_back(grown[k].z);
            R.push_back(grown[k].R);
        }
        const auto [e, intercept] = fitLine(z, R);
        const double zv = -intercept / e;
        for (std::size_t k = 1; k + 1 < grown.size(); ++k) {
            if (grown[k].t < 0.79 || grown[k].t > 2.01) continue;
            const double w = (grown[k + 1].z - grown[k - 1].z) / (grown[k + 1].t - grown[k - 1].t);
            logZ.push_back(std::log(grown[k].z - zv));
            logW.push_back(std::log(w));
        }
        const double n = fitLine(logZ, logW).first, timeExponent = 1 / (1 - n);
        std::printf("[measured] thermal, %.0f cm: dR/dz = %.3f (virtual origin %.2f m), w ~ "
                    "(z - z_v)^%.2f: z ~ t^%.2f; R from %.3f to %.3f m while z rose from %.2f to "
                    "%.2f m; without entrainment R %.3f to %.3f m\n",
                    100 * double(spacing), e, zv, n, timeExponent, R.front(), R.back(), z.front(),
                    z.back(), column[3].R, column[9].R);
        EXPECT_GE(e, 0.25 / 1.5);
        EXPECT_LE(e, 0.25 * 1.5);
        EXPECT_NEAR(timeExponent, 0.5, 0.15);
        // Over the same frames (0.8 to 2 s) it doubles its radius; the ball without entrainment
        // grows 6 to 11 % (its particles spreading, not air drawn in).
        EXPECT_GT(R.back() / R.front(), 1.5);
        EXPECT_LT(column[9].R / column[3].R, 1.2);
    }
}

// The flow statistics against fields with known answers: a rigid translation has no enstrophy;
// a rigid rotation at Omega has vorticity 2 Omega, so enstrophy (1/2) V (2 Omega)^2 inside the
// gas (its boundary particles miss neighbours, so the whole ball reads less: measured 0.78 of
// it); kinetic energy is exact; a stack of uniform discs of radius 0.05 + 0.1 z spreads at 0.1.
TEST(GasFlowStats, MatchFieldsWithKnownAnswers)
{
    GasSettings s;
    s.spacing = Real(0.02);
    ParticleSet p;
    p.addScalarChannel(channel::SUPPORT, s.supportRadius());
    const Real m = s.restDensity * s.spacing * s.spacing * s.spacing;
    for (int i = -10; i <= 10; ++i)
        for (int j = -10; j <= 10; ++j)
            for (int k = -10; k <= 10; ++k) {
                const Vec3 x = Vec3(Real(i), Real(j), Real(k)) * s.spacing;
                if (x.length() <= Real(0.2)) p.add(x, Vec3(0), m, ParticleKind::Gas);
            }
    p.densities().assign(p.size(), s.restDensity);
    const double omega = 2, volume = double(p.size()) * double(m) / double(s.restDensity);
    for (std::size_t i = 0; i < p.size(); ++i) p.velocities()[i] = Vec3(1, 0, 0);
    const GasFlowStats moving = gasFlowStats(p, s);
    double energy = 0;
    for (std::size_t i = 0; i < p.size(); ++i) {
        const Vec3& x = p.positions()[i];
        p.velocities()[i] = Vec3(-Real(omega) * x[2], 0, Real(omega) * x[0]);
        energy += 0.5 * double(m) * double(p.velocities()[i].lengthSqr());
    }
    const GasFlowStats turning = gasFlowStats(p, s);
    const double expected = 0.5 * volume * (2 * omega) * (2 * omega);
    std::printf("[measured] flow stats: translation enstrophy %.3g; rotation enstrophy %.4f of "
                "(1/2) V (2 Omega)^2 = %.4f, kinetic energy %.6g J against %.6g J\n",
                moving.enstrophy, turning.enstrophy / expected, expected, turning.kineticEnergy,
                energy);
    EXPECT_LT(moving.enstrophy, 1e-9 * expected);
    EXPECT_GT(turning.enstrophy / expected, 0.6);
    EXPECT_LT(turning.enstrophy / expected, 1.05);
    EXPECT_NEAR(turning.kineticEnergy / energy, 1.0, 1e-9);

    ParticleSet cone;
    cone.addScalarChannel(channel::SUPPORT, s.supportRadius());
    for (int layer = 0; layer <= 50; ++layer) {
        const double z = 0.02 * layer, b = 0.05 + 0.1 * z;
        for (double x = -b; x <= b; x += 0.01)
            for (double y = -b; y <= b; y += 0.01)
                if (x * x + y * y <= b * b)
                    cone.add(Vec3(Real(x), Real(z), Real(y)), Vec3(0), m, ParticleKind::Gas);
    }
    cone.densities().assign(cone.size(), s.restDensity);
    const double rate = gasFlowStats(cone, s).spreadRate;
    std::printf("[measured] flow stats: cone of spread 0.1: %.4f\n", rate);
    EXPECT_NEAR(rate, 0.1, 0.005);
}

// The entrained air dilutes the smoke: each particle's smoke share c falls as air joins it, so
// the smoke's mass sum m c stays the mass released (to float rounding: 1e-5 over 60 steps) while
// the gas's mass grows by the air drawn in, and the "smoke" grid thins the plume as it spreads.
TEST(GasEntrainment, TheSmokeIsDilutedNotLost)
{
    GasSettings s;
    s.spacing = Real(0.03);
    s.substeps = 2;
    s.entrainment = Real(0.12);
    GasSolver solver(s);
    solver.addGas(makeLevelSet(makeSphereLevelSet(Vec3(0, Real(0.3), 0), Real(0.1), s.spacing / 2),
                               "thermal"),
                  Vec3(0), Real(600));
    auto sums = [&](double& mass, double& smoke) {
        const ParticleSet& p = solver.particles();
        const auto& c = p.scalarChannel(channel::SMOKE);
        mass = smoke = 0;
        for (std::size_t i = 0; i < p.size(); ++i) {
            if (p.kinds()[i] != ParticleKind::Gas) continue;
            mass += double(p.masses()[i]);
            smoke += double(p.masses()[i]) * double(c[i]);
        }
    };
    solver.advanceFrame(); // the first step sets the particles' mass
    double mass0, smoke0, mass1, smoke1;
    sums(mass0, smoke0);
    for (int f = 0; f < 30; ++f) solver.advanceFrame();
    sums(mass1, smoke1);
    std::printf("[measured] smoke: gas mass x%.3f in 1 s, smoke mass %.3g relative change\n",
                mass1 / mass0, smoke1 / smoke0 - 1);
    EXPECT_GT(mass1 / mass0, 1.5);
    EXPECT_NEAR(smoke1 / smoke0, 1.0, 1e-5);
}
