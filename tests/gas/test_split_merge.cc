/// @file   test_split_merge.cc
/// @brief  Split patterns (optimal mass ratios of [RYY15] Eq. 18, quadrature accuracy), particle
///         splitting (conservation, ids, geometry) and merging by mass decentration with
///         re-splitting ([RYY15] Eqs. 19-20, Fig. 3).
/// @details Tolerances: quadrature results are exact for these piecewise-polynomial kernels up to
///          double round-off, so pattern properties are checked at 1e-12 relative or tighter
///          unless stated. Particle quantities live in `Real` (float by default), so conservation
///          is checked against Real's epsilon times the number of roundings involved.
#include <ghostfx/gas/SplitMerge.h>
#include <ghostfx/gas/SplitPatterns.h>
#include <ghostfx/sph/Exceptions.h>
#include <ghostfx/sph/Kernels.h>
#include <ghostfx/sph/NeighborGrid.h>
#include <ghostfx/sph/ParticleSet.h>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <random>
#include <set>
#include <thread>

namespace {

using namespace ghostfx;
using namespace ghostfx::gas;
using ghostfx::sph::ParticleKind;
using ::testing::HasSubstr;

constexpr double REAL_EPS = double(std::numeric_limits<Real>::epsilon());
constexpr double PI_D = 3.14159265358979323846;

double sum(const std::vector<double>& v)
{
    double s = 0.0;
    for (double x : v) s += x;
    return s;
}

// ---------------------------------------------------------------------------------------------
// Quadrature

TEST(SplitQuadrature, UnitKernelsMatchLibsphKernels)
{
    // The pattern code evaluates kernels in double; they must be the libsph kernels (support 1).
    const sph::Poly6Kernel poly6(Real(1));
    const sph::CubicSplineKernel spline(Real(1));
    for (int k = 0; k <= 20; ++k) {
        const double q = 0.05 * k;
        EXPECT_NEAR(unitKernel(SplitKernel::Poly6, q), double(poly6.W(Real(q))),
                    8 * REAL_EPS * unitKernel(SplitKernel::Poly6, 0.0));
        EXPECT_NEAR(unitKernel(SplitKernel::CubicSpline, q), double(spline.W(Real(q))),
                    8 * REAL_EPS * unitKernel(SplitKernel::CubicSpline, 0.0));
    }
}

TEST(SplitQuadrature, ConcentricOverlapMatchesClosedForm)
{
    // int w^2 for poly6 = 4 pi (315 / 64 pi)^2 int_0^1 (1 - r^2)^6 r^2 dr, and that integral is
    // B(3/2, 7) / 2 = Gamma(3/2) Gamma(7) / (2 Gamma(17/2)).
    const double beta = std::tgamma(1.5) * std::tgamma(7.0) / (2.0 * std::tgamma(8.5));
    const double exact = 4.0 * PI_D * std::pow(315.0 / (64.0 * PI_D), 2) * beta;
    const double C = overlapIntegral(SplitKernel::Poly6, 0.0, 1.0, 1.0);
    std::printf("[measured] poly6 int w^2 = %.16f, closed form %.16f, rel diff %.2e\n", C, exact,
                std::abs(C - exact) / exact);
    EXPECT_NEAR(C, exact, 1e-13 * exact); // degree-14 integrand, 8-node Gauss rule: exact
}

TEST(SplitQuadrature, RefinementStudy)
{
    // Differences of each rule from a 16-node, 4-panel reference at several separations. For the
    // piecewise-polynomial kernels (degree <= 15 per smooth piece) an n-node rule is exact once
    // 2n - 1 >= degree, so the default (8 nodes, 2 panels) must agree with the reference to
    // round-off; coarser rules show the convergence.
    for (SplitKernel kernel : {SplitKernel::Poly6, SplitKernel::CubicSpline}) {
        for (double d : {0.0, 0.12, 0.3, 0.4 * std::sqrt(2.0), 0.9}) {
            const double ref = overlapIntegral(kernel, d, 1.0, 0.9, Quadrature{16, 4});
            std::printf("[measured] %s overlap d=%.3f ref=%.15f |rule-ref|/ref:",
                        splitKernelName(kernel), d, ref);
            double defaultErr = 0.0;
            for (int nodes : {2, 3, 4, 6, 8}) {
                const double v = overlapIntegral(kernel, d, 1.0, 0.9, Quadrature{nodes, 2});
                const double err = std::abs(v - ref) / ref;
                std::printf(" n%d:%.1e", nodes, err);
                if (nodes == Quadrature().nodes) defaultErr = err;
            }
            std::printf("\n");
            EXPECT_LT(defaultErr, 1e-13) << splitKernelName(kernel) << " d = " << d;
        }
    }
    // The 2-node rule is not exact: the study must actually resolve something.
    const double ref = overlapIntegral(SplitKernel::Poly6, 0.3, 1.0, 0.9, Quadrature{16, 4});
    EXPECT_GT(std::abs(overlapIntegral(SplitKernel::Poly6, 0.3, 1.0, 0.9, Quadrature{2, 1}) - ref),
              1e-6 * ref);
}

TEST(SplitQuadrature, RadialReductionMatchesCartesianSum)
{
    // Independent check of the 1-D reduction: a midpoint sum over an N^3 Cartesian grid of the
    // box enclosing both supports. Poly6 is C2 at the edge of its support, so the midpoint sum
    // converges fast (measured: 2.8e-8 relative at N = 48, 8.8e-10 at N = 96); the tolerance
    // 1e-7 at N = 96 is a hundred times the measurement, far below any error the reduction
    // formula could hide (a wrong factor or limit shows up at the 1e-2 level or above).
    const double d = 0.3, r1 = 1.0, r2 = 0.9;
    const double exact = overlapIntegral(SplitKernel::Poly6, d, r1, r2);
    double prevErr = 0.0;
    for (int N : {48, 96}) {
        const double lo = -1.0, hi = 1.0 + d, hy = 1.0; // x in [lo, hi], y, z in [-1, 1]
        const double dx = (hi - lo) / N, dy = 2.0 * hy / N;
        double s = 0.0;
        for (int i = 0; i < N; ++i) {
            const double x = lo + (i + 0.5) * dx;
            for (int j = 0; j < N; ++j) {
                const double y = -hy + (j + 0.5) * dy;
                for (int k = 0; k < N; ++k) {
                    const double z = -hy + (k + 0.5) * dy;
                    const double ra = std::sqrt(x * x + y * y + z * z);
                    const double rb = std::sqrt((x - d) * (x - d) + y * y + z * z);
                    s += unitKernel(SplitKernel::Poly6, ra / r1) / (r1 * r1 * r1)
                         * unitKernel(SplitKernel::Poly6, rb / r2) / (r2 * r2 * r2);
                }
            }
        }
        s *= dx * dy * dy;
        const double err = std::abs(s - exact) / exact;
        std::printf("[measured] Cartesian midpoint N=%d: %.8f vs radial %.8f, rel diff %.2e\n", N,
                    s, exact, err);
        if (N == 96) {
            EXPECT_LT(err, 1e-7);
            EXPECT_LT(err, prevErr); // converging towards the radial value
        }
        prevErr = err;
    }
}

// ---------------------------------------------------------------------------------------------
// Patterns

TEST(SplitPatterns, MassRatiosSumToOne)
{
    for (const SplitPattern* p :
         {&icosahedronPattern(), &cubePattern(), &defaultResplitPattern()}) {
        EXPECT_NEAR(sum(p->lambda), 1.0, 1e-14) << p->name; // renormalised: one double sum
        EXPECT_EQ(p->lambda.size(), p->childCount());
    }
    EXPECT_EQ(icosahedronPattern().childCount(), 12u);
    EXPECT_FALSE(icosahedronPattern().hasCentre);
    EXPECT_EQ(cubePattern().childCount(), 9u);
    EXPECT_TRUE(cubePattern().hasCentre);
    EXPECT_EQ(cubePattern().centreIndex(), 8u);
}

TEST(SplitPatterns, OptimalRatiosMinimiseErrorUnderPairPerturbations)
{
    // Moving delta of mass ratio from daughter l to daughter k keeps sum = 1 and changes the
    // quadratic error by 2 delta g_kl + delta^2 (A_kk + A_ll - 2 A_kl) with g the gradient
    // difference, which is zero at the constrained optimum. So the error must not decrease, and
    // the increase must equal the quadratic term (to round-off of the error, about 1e-16 C).
    for (const SplitPattern* p : {&icosahedronPattern(), &cubePattern()}) {
        const RefinementTerms t = refinementTerms(p->offsets, p->epsilon, p->alpha, p->kernel);
        const std::size_t n = t.size();
        const double e0 = t.error(p->lambda);
        EXPECT_NEAR(e0, p->error, 1e-14 * t.C);
        double worstRel = 0.0;
        for (std::size_t k = 0; k < n; ++k) {
            for (std::size_t l = 0; l < n; ++l) {
                if (k == l) continue;
                for (double delta : {1e-3, -1e-3}) {
                    std::vector<double> lam = p->lambda;
                    lam[k] += delta;
                    lam[l] -= delta;
                    const double e = t.error(lam);
                    const double quad =
                        delta * delta * (t.A[k * n + k] + t.A[l * n + l] - 2 * t.A[k * n + l]);
                    EXPECT_GE(e, e0 - 1e-15 * t.C) << p->name << " k=" << k << " l=" << l;
                    EXPECT_NEAR(e - e0, quad, 1e-6 * quad + 1e-14 * t.C);
                    worstRel = std::max(worstRel, std::abs((e - e0) - quad) / quad);
                }
            }
        }
        std::printf("[measured] %s: error %.6e (relative %.3e); pair perturbations +-1e-3 raise it "
                    "by the quadratic term to %.1e relative\n",
                    p->name.c_str(), p->error, p->relativeError, worstRel);
    }
}

TEST(SplitPatterns, IcosahedronRatiosEqualBySymmetry)
{
    // All 12 vertices are equivalent, and the optimum is unique (A positive definite), so it is
    // symmetric: every lambda is 1/12 up to the KKT solve's round-off.
    const SplitPattern& p = icosahedronPattern();
    double maxDev = 0.0;
    for (double l : p.lambda) maxDev = std::max(maxDev, std::abs(l - 1.0 / 12.0));
    std::printf("[measured] icosahedron (0.3, 0.9): lambda = 1/12 +- %.1e, relative Eq. 18 error "
                "%.3e\n",
                maxDev, p.relativeError);
    EXPECT_LT(maxDev, 1e-12);
    for (const auto& o : p.offsets) EXPECT_NEAR(o.length(), 1.0, 1e-15);
}

TEST(SplitPatterns, CubeCentreRatioVersusPaper)
{
    // [RYY15] Sec. 4.2 quotes lambda = 0.992 at the centre and 0.001 at the corners for the cube
    // pattern at (epsilon, alpha) = (0.4, 0.9). Minimising Eq. 18 does not give that: with the
    // poly6 kernel the optimum is 0.5346 at the centre and 0.0582 at each corner, with the M4
    // spline 0.632 / 0.046 (nor do the other readings tried: corners at half-side 0.4 give
    // centre 0.777 (poly6) / 0.808 (spline); the literal Eq. 18 with unscaled daughter positions
    // gives 0.372 / 0.487). A daughter narrower than its mother (alpha < 1) cannot carry nearly
    // all the mass without the sum being too peaked: the paper's ratios give 14 times the optimal
    // error, about as much as putting all the mass on the centre. They are the optimum only for
    // alpha close to 1 (solved below: alpha = 0.9985 at epsilon 0.4).
    const SplitPattern& opt = cubePattern();
    const SplitPattern& paper = paperCubePattern();
    const double centre = opt.lambda[opt.centreIndex()];
    std::printf("[measured] cube+centre (0.4, 0.9) poly6 optimum: centre %.5f, corners %.5f, "
                "relative error %.3e; paper ratios (0.992, 0.001): relative error %.3e\n",
                centre, opt.lambda[0], opt.relativeError, paper.relativeError);
    EXPECT_NEAR(centre, 0.5346, 1e-3); // value measured here; quadrature exact (see above)
    for (std::size_t k = 0; k < 8; ++k) EXPECT_NEAR(opt.lambda[k], opt.lambda[0], 1e-12);
    EXPECT_GT(paper.relativeError, 10.0 * opt.relativeError);

    const SplitPattern spline =
        optimisePattern("cube+centre", patternOffsets(PatternShape::CubeCentre), 0.4, 0.9,
                        SplitKernel::CubicSpline);
    std::printf(
        "[measured] cube+centre (0.4, 0.9) cubic spline optimum: centre %.5f, corners %.5f\n",
        spline.lambda[8], spline.lambda[0]);
    EXPECT_NEAR(spline.lambda[8], 0.632, 1e-3);

    // Reverse the process (Sec. 4.1): the alpha at which the optimal centre ratio is 0.992.
    double lo = 0.9, hi = 1.0;
    const auto offsets = patternOffsets(PatternShape::CubeCentre);
    for (int it = 0; it < 40; ++it) {
        const double mid = 0.5 * (lo + hi);
        (optimisePattern("c", offsets, 0.4, mid).lambda[8] < 0.992 ? lo : hi) = mid;
    }
    const SplitPattern at = optimisePattern("c", offsets, 0.4, lo);
    std::printf("[measured] optimal centre ratio 0.992 needs alpha = %.5f at epsilon 0.4 "
                "(corners %.5f)\n",
                lo, at.lambda[0]);
    EXPECT_NEAR(at.lambda[0], 0.001, 1e-5); // then the corners get the paper's 0.001 too
    EXPECT_GT(lo, 0.99);
}

TEST(SplitPatterns, CacheIsSharedAcrossThreads)
{
    const SplitPattern* seen[4] = {};
    std::vector<std::thread> threads;
    for (int t = 0; t < 4; ++t) {
        threads.emplace_back(
            [&seen, t] { seen[t] = &cachedPattern(PatternShape::Cube, 0.35, 0.8); });
    }
    for (auto& th : threads) th.join();
    for (int t = 1; t < 4; ++t) EXPECT_EQ(seen[t], seen[0]);
    EXPECT_NEAR(sum(seen[0]->lambda), 1.0, 1e-14);
}

TEST(SplitPatterns, BadArgumentsNameTheValue)
{
    try {
        optimisePattern("x", patternOffsets(PatternShape::Cube), -0.1, 0.9);
        FAIL() << "expected ValueError";
    } catch (const ValueError& e) {
        EXPECT_THAT(e.what(), HasSubstr("epsilon = -0.1"));
    }
    try {
        optimisePattern("x", {Vec3d(0.5, 0.0, 0.0)}, 0.3, 0.9);
        FAIL() << "expected ValueError";
    } catch (const ValueError& e) {
        EXPECT_THAT(e.what(), HasSubstr("length 0.5"));
    }
}

// ---------------------------------------------------------------------------------------------
// Splitting

struct Totals
{
    double mass = 0.0;
    sph::Vec3d momentum{0.0}, moment{0.0};
    double thermal = 0.0; // sum m T
};

Totals totals(const ParticleSet& p, std::optional<ParticleKind> kind = std::nullopt)
{
    Totals t;
    const auto& T = p.scalarChannel("temperature");
    for (std::size_t i = 0; i < p.size(); ++i) {
        if (kind && p.kinds()[i] != *kind) continue;
        const double m = double(p.masses()[i]);
        t.mass += m;
        t.momentum += sph::Vec3d(p.velocities()[i]) * m;
        t.moment += sph::Vec3d(p.positions()[i]) * m;
        t.thermal += m * double(T[i]);
    }
    return t;
}

/// A few liquid particles with varied masses, velocities, sizes and temperatures.
ParticleSet makeSet(std::size_t n, unsigned seed)
{
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    ParticleSet p;
    p.addScalarChannel("temperature", Real(300));
    for (std::size_t i = 0; i < n; ++i) {
        p.add(Vec3(Real(1 + u(rng)), Real(2 + u(rng)), Real(-3 + u(rng))),
              Vec3(Real(u(rng)), Real(u(rng)), Real(u(rng))), Real(1e-3 * (1.5 + u(rng))),
              ParticleKind::Liquid);
    }
    auto& h = addSplitChannels(p, Real(0.05));
    auto& T = p.scalarChannel("temperature");
    for (std::size_t i = 0; i < n; ++i) {
        h[i] = Real(0.05 * (1.0 + 0.3 * u(rng)));
        T[i] = Real(350 + 20 * u(rng));
    }
    return p;
}

TEST(SplitParticles, ConservesMassMomentumAndCentreOfMass)
{
    for (const SplitPattern* pattern :
         {&icosahedronPattern(), &cubePattern(), &paperCubePattern()}) {
        ParticleSet p = makeSet(6, 7);
        const Totals before = totals(p);
        const Index i = 2;
        const sph::Vec3d xN(p.positions()[i]);
        const sph::Vec3d vN(p.velocities()[i]);
        const double mN = p.masses()[i], hN = p.scalarChannel("h")[i];
        const Real TN = p.scalarChannel("temperature")[i];
        const sph::ParticleId motherId = p.ids()[i], firstNewId = p.nextId();
        std::set<sph::ParticleId> oldIds(p.ids().begin(), p.ids().end());

        SplitOptions opt;
        opt.outerKind = ParticleKind::Gas;
        const Index first = splitParticle(p, i, *pattern, opt);
        const std::size_t c = pattern->childCount();
        ASSERT_EQ(p.size(), 6 - 1 + c);
        ASSERT_EQ(std::size_t(first), 5u);
        const Totals after = totals(p);

        // Mass: the daughters' Real masses sum to the mother's to one rounding (heaviest daughter
        // absorbs the residual), plus the double sums' own round-off.
        const double massErr = std::abs(after.mass - before.mass);
        const double momErr = (after.momentum - before.momentum).length();
        // Centre of mass of the daughters vs the mother's position: positions are rounded to
        // Real once each (0.5 ulp of |x| + epsilon h), masses once.
        double dm = 0.0;
        sph::Vec3d dMoment(0.0);
        for (std::size_t k = 0; k < c; ++k) {
            dm += double(p.masses()[first + k]);
            dMoment += sph::Vec3d(p.positions()[first + k]) * double(p.masses()[first + k]);
        }
        const double comErr = (dMoment / dm - xN).length();
        std::printf("[measured] split by %s: |dM|/M = %.1e, |dP|/|P| = %.1e, centre of mass moved "
                    "%.1e m (h = %.3f m)\n",
                    pattern->name.c_str(), massErr / before.mass, momErr / before.momentum.length(),
                    comErr, hN);
        EXPECT_LE(std::abs(dm - mN), REAL_EPS * mN);
        EXPECT_LE(massErr, 2 * REAL_EPS * mN + 1e-15 * before.mass);
        EXPECT_LE((vN * dm - vN * mN).length(), REAL_EPS * mN * vN.length());
        EXPECT_LE(momErr, 2 * REAL_EPS * mN * vN.length() + 1e-14 * before.momentum.length());
        EXPECT_LE(comErr, 4 * REAL_EPS * (xN.length() + pattern->epsilon * hN));

        // Ids: mother's gone, daughters new and unique, others kept.
        std::set<sph::ParticleId> ids(p.ids().begin(), p.ids().end());
        EXPECT_EQ(ids.size(), p.size());
        EXPECT_EQ(ids.count(motherId), 0u);
        for (std::size_t k = 0; k < c; ++k) {
            EXPECT_GE(p.ids()[first + k], firstNewId);
            EXPECT_EQ(oldIds.count(p.ids()[first + k]), 0u);
        }

        // Geometry and channels: at epsilon h (or the centre), h scaled by alpha, channels copied.
        for (std::size_t k = 0; k < c; ++k) {
            const Index j = first + Index(k);
            const double r = (sph::Vec3d(p.positions()[j]) - xN).length();
            const double expected = pattern->epsilon * hN * pattern->offsets[k].length();
            EXPECT_NEAR(r, expected, 4 * REAL_EPS * (xN.length() + expected));
            EXPECT_NEAR(p.scalarChannel("h")[j], pattern->alpha * hN, 2 * REAL_EPS * hN);
            EXPECT_NEAR(p.masses()[j], pattern->lambda[k] * mN, 2 * REAL_EPS * mN);
            EXPECT_EQ(p.scalarChannel("temperature")[j], TN);
            EXPECT_EQ(p.scalarChannel("splits")[j], Real(1));
            EXPECT_EQ(p.velocities()[j], sph::toVec3(vN));
            const bool centre = k == pattern->centreIndex();
            EXPECT_EQ(p.kinds()[j], centre ? ParticleKind::Liquid : ParticleKind::Gas);
        }
    }
}

TEST(SplitParticles, BatchAndErrors)
{
    ParticleSet p = makeSet(5, 11);
    const Totals before = totals(p);
    const Index first = splitParticles(p, {4, 0, 2}, icosahedronPattern());
    EXPECT_EQ(p.size(), 2u + 36u);
    EXPECT_EQ(first, 2u);
    EXPECT_NEAR(totals(p).mass, before.mass, 4 * REAL_EPS * before.mass);

    try {
        splitParticles(p, {1, 1}, icosahedronPattern());
        FAIL() << "expected ValueError";
    } catch (const ValueError& e) {
        EXPECT_THAT(e.what(), HasSubstr("repeated"));
    }
    ParticleSet bare;
    bare.add(Vec3(0), Vec3(0), Real(1), ParticleKind::Liquid);
    try {
        splitParticle(bare, 0, cubePattern());
        FAIL() << "expected ValueError";
    } catch (const ValueError& e) {
        EXPECT_THAT(e.what(), HasSubstr("addSplitChannels"));
    }
}

// ---------------------------------------------------------------------------------------------
// Merging

TEST(MergeParticles, InertiaAndDecentrationOfKnownShapes)
{
    // Octahedron of 6 equal masses at distance a: I = 4 m a^2 Id, isotropic, eta = 0. A line of
    // masses along x: I = diag(0, S, S) with S = sum m x^2, so eta = (2 S / 3)^3.
    ParticleSet p;
    const Real m(2), a(0.5);
    p.add(Vec3(0), Vec3(0), m, ParticleKind::Liquid);
    for (int s : {-1, 1}) {
        p.add(Vec3(s * a, 0, 0), Vec3(0), m, ParticleKind::Liquid);
        p.add(Vec3(0, s * a, 0), Vec3(0), m, ParticleKind::Liquid);
        p.add(Vec3(0, 0, s * a), Vec3(0), m, ParticleKind::Liquid);
    }
    const auto I = inertiaMatrix(p, Vec3(0), {0, 1, 2, 3, 4, 5, 6});
    EXPECT_DOUBLE_EQ(I[0], 4.0 * m * a * a);
    EXPECT_DOUBLE_EQ(I[4], 4.0 * m * a * a);
    EXPECT_EQ(I[1], 0.0);
    EXPECT_NEAR(massDecentration(I), 0.0, 1e-12);
    const auto L = inertiaMatrix(p, Vec3(0), {0, 1, 4});
    const double S = 2.0 * m * a * a;
    EXPECT_NEAR(massDecentration(L), std::pow(2.0 * S / 3.0, 3), 1e-12);
}

/// Two candidates with six neighbours each, far apart: A's neighbours form an octahedron
/// (eta = 0), B's lie on a line (eta > 0).
ParticleSet makeTwoCandidates()
{
    ParticleSet p;
    p.addScalarChannel("temperature", Real(300));
    const Real m(1e-3), a(0.02);
    const Vec3 A(0), B(1, 0, 0);
    p.add(A, Vec3(0), m, ParticleKind::Liquid);
    for (int s : {-1, 1}) {
        p.add(A + Vec3(s * a, 0, 0), Vec3(0), m, ParticleKind::Liquid);
        p.add(A + Vec3(0, s * a, 0), Vec3(0), m, ParticleKind::Liquid);
        p.add(A + Vec3(0, 0, s * a), Vec3(0), m, ParticleKind::Liquid);
    }
    p.add(B, Vec3(0), m, ParticleKind::Liquid);
    for (int s : {-1, 1}) {
        for (Real f : {Real(1), Real(1.5), Real(2)}) {
            p.add(B + Vec3(s * f * a, 0, 0), Vec3(0), m, ParticleKind::Liquid);
        }
    }
    addSplitChannels(p, Real(0.05));
    auto& splits = p.scalarChannel("splits");
    splits[0] = Real(3);
    splits[7] = Real(3);
    return p;
}

TEST(MergeParticles, DecentrationPicksTheSphericalNeighbourhood)
{
    ParticleSet p = makeTwoCandidates();
    sph::NeighborGrid grid(Real(0.05));
    grid.build(p.positions());
    MergeSettings s;
    s.maxMerged = 7;        // the candidate and its six neighbours
    s.maxMergesPerCall = 1; // "the particle with the smallest mass decentration is merged"
    const auto plan = planMerges(p, grid, s);
    ASSERT_EQ(plan.size(), 1u);
    EXPECT_EQ(plan[0].candidate, 0u);
    EXPECT_EQ(plan[0].members.size(), 7u);
    EXPECT_EQ(plan[0].members[0], 0u);

    s.maxMergesPerCall = 0;
    const auto both = planMerges(p, grid, s);
    ASSERT_EQ(both.size(), 2u);
    EXPECT_EQ(both[1].candidate, 7u);
    std::printf("[measured] decentration: octahedron group eta = %.2e, line group eta = %.2e "
                "(kg^3 m^6)\n",
                both[0].eta, both[1].eta);
    EXPECT_LT(both[0].eta, 1e-6 * both[1].eta);
}

TEST(MergeParticles, ConservesMassMomentumAndCentreOfMass)
{
    // A jittered lattice of liquid particles, every one a candidate; merge with and without
    // re-split, both placements.
    for (bool resplit : {false, true}) {
        for (MergePlacement placement : {MergePlacement::CentreOfMass, MergePlacement::Candidate}) {
            std::mt19937 rng(3);
            std::uniform_real_distribution<double> u(-1.0, 1.0);
            ParticleSet p;
            p.addScalarChannel("temperature", Real(300));
            const double s = 0.02;
            for (int i = 0; i < 6; ++i) {
                for (int j = 0; j < 6; ++j) {
                    for (int k = 0; k < 6; ++k) {
                        p.add(Vec3(Real(s * (i + 0.2 * u(rng))), Real(s * (j + 0.2 * u(rng))),
                                   Real(s * (k + 0.2 * u(rng)))),
                              Vec3(Real(u(rng)), Real(u(rng)), Real(u(rng))),
                              Real(8e-6 * (1 + 0.2 * u(rng))), ParticleKind::Liquid);
                    }
                }
            }
            addSplitChannels(p, Real(2 * s));
            auto& T = p.scalarChannel("temperature");
            for (auto& t : T) t = Real(350 + 10 * u(rng));
            std::fill(p.scalarChannel("splits").begin(), p.scalarChannel("splits").end(), Real(3));
            const Totals before = totals(p);
            const std::size_t n0 = p.size();

            sph::NeighborGrid grid{Real(2 * s)};
            grid.build(p.positions());
            MergeSettings ms;
            ms.resplit = resplit;
            ms.placement = placement;
            const MergeResult r = mergeParticles(p, grid, ms);
            const Totals after = totals(p);
            const double massErr = std::abs(after.mass - before.mass) / before.mass;
            const double momErr =
                (after.momentum - before.momentum).length() / before.momentum.length();
            const double comShift =
                (after.moment / after.mass - before.moment / before.mass).length();
            const double thermalErr = std::abs(after.thermal - before.thermal) / before.thermal;
            std::printf("[measured] merge (resplit %d, %s): %zu groups, %zu -> %zu particles, "
                        "|dM|/M %.1e, |dP|/|P| %.1e, thermal %.1e, centre of mass moved %.2e m\n",
                        int(resplit),
                        placement == MergePlacement::CentreOfMass ? "com" : "candidate", r.merges,
                        n0, p.size(), massErr, momErr, thermalErr, comShift);
            EXPECT_GT(r.merges, 3u);
            EXPECT_EQ(p.size(), n0 - r.removed + r.added);
            // Each group: one Real rounding per new mass (plus velocity and channel roundings);
            // SUM_TOL covers the double sums over a few hundred particles in the double build.
            const double SUM_TOL = 1e-13;
            EXPECT_LT(massErr, 4 * REAL_EPS + SUM_TOL);
            EXPECT_LT(momErr, 8 * REAL_EPS * std::sqrt(double(n0)) + SUM_TOL);
            EXPECT_LT(thermalErr, 8 * REAL_EPS + SUM_TOL);
            if (placement == MergePlacement::CentreOfMass) {
                // round-off of positions ~ box size
                EXPECT_LT(comShift, (8 * REAL_EPS + SUM_TOL) * 6 * s);
            } else {
                EXPECT_GT(comShift, 100 * REAL_EPS * 6 * s); // the paper's placement moves it
            }
            for (Real sp : p.scalarChannel("splits")) EXPECT_TRUE(sp == Real(0) || sp == Real(3));
            std::set<sph::ParticleId> ids(p.ids().begin(), p.ids().end());
            EXPECT_EQ(ids.size(), p.size());
        }
    }
}

TEST(MergeParticles, SplitMergeResplitCycle)
{
    // Fig. 3 with evaporation: a block of liquid particles near a surface is split three times by
    // the paper's cube pattern (the centre stays liquid, the corners become gas). The centre
    // daughters reach the threshold, with h shrunk to 0.9^3 of the original. A merge pass then
    // takes the depleted liquid particles in groups of 12 (the default re-split's daughter
    // count), merges each group into M' and re-splits it into 12 equal daughters that start a
    // new split cycle. Gas particles are never merged with liquid (kind differs).
    const double s = 0.02, h0 = 2 * s;
    ParticleSet p;
    p.addScalarChannel("temperature", Real(300));
    for (int i = 0; i < 5; ++i) {
        for (int j = 0; j < 5; ++j) {
            for (int k = 0; k < 5; ++k) {
                p.add(Vec3(Real(s * i), Real(s * j), Real(s * k)), Vec3(0, Real(0.1), 0),
                      Real(8e-6), ParticleKind::Liquid);
            }
        }
    }
    addSplitChannels(p, Real(h0));
    const Totals start = totals(p);
    SplitOptions evaporate;
    evaporate.outerKind = ParticleKind::Gas;
    const SplitPattern& pattern = paperCubePattern();
    for (int round = 0; round < 3; ++round) {
        std::vector<Index> liquid;
        for (std::size_t i = 0; i < p.size(); ++i) {
            if (p.kinds()[i] == ParticleKind::Liquid) liquid.push_back(Index(i));
        }
        splitParticles(p, liquid, pattern, evaporate);
    }
    const std::size_t nLiquid = p.count(ParticleKind::Liquid), nGas = p.count(ParticleKind::Gas);
    const Totals liquidBefore = totals(p, ParticleKind::Liquid);
    const Totals gasBefore = totals(p, ParticleKind::Gas);
    EXPECT_EQ(nLiquid, 125u);
    EXPECT_EQ(nGas, 125u * 8u * 3u);
    // 3 splits leave 0.992^3 of the liquid mass (paper ratios)
    EXPECT_NEAR(liquidBefore.mass / start.mass, std::pow(0.992, 3), 32 * REAL_EPS + 1e-13);
    for (std::size_t i = 0; i < p.size(); ++i) {
        if (p.kinds()[i] != ParticleKind::Liquid) continue;
        EXPECT_EQ(p.scalarChannel("splits")[i], Real(3));
        EXPECT_NEAR(p.scalarChannel("h")[i], h0 * 0.729, 4 * REAL_EPS * h0);
    }

    sph::NeighborGrid grid{Real(h0)};
    grid.build(p.positions());
    MergeSettings ms; // threshold 3, groups of 12, default re-split, h' by volume sum
    const MergeResult r = mergeParticles(p, grid, ms);
    const Totals liquidAfter = totals(p, ParticleKind::Liquid);
    const Totals gasAfter = totals(p, ParticleKind::Gas);
    std::printf("[measured] split x3 -> merge -> resplit: %zu groups of 12; liquid %zu -> %zu "
                "particles, liquid |dM|/M %.1e, gas untouched %zu -> %zu\n",
                r.merges, nLiquid, p.count(ParticleKind::Liquid),
                std::abs(liquidAfter.mass - liquidBefore.mass) / liquidBefore.mass, nGas,
                p.count(ParticleKind::Gas));
    EXPECT_GE(r.merges, 3u);
    EXPECT_EQ(r.removed, 12 * r.merges);
    EXPECT_EQ(r.added, 12 * r.merges); // count-neutral merge-resplit
    EXPECT_EQ(p.count(ParticleKind::Liquid), nLiquid);
    EXPECT_EQ(p.count(ParticleKind::Gas), nGas);
    EXPECT_EQ(gasAfter.mass, gasBefore.mass);
    EXPECT_NEAR(liquidAfter.mass, liquidBefore.mass, (4 * REAL_EPS + 1e-13) * liquidBefore.mass);
    EXPECT_LT((liquidAfter.momentum - liquidBefore.momentum).length(),
              (8 * REAL_EPS + 1e-13) * liquidBefore.momentum.length());

    // The re-split daughters: splits reset, equal masses, h = alpha h' with h' the volume sum
    // of 12 particles of h = 0.729 h0, so h = 12^(-1/3) 12^(1/3) 0.729 h0 = 0.729 h0.
    const SplitPattern& rp = defaultResplitPattern();
    std::size_t fresh = 0;
    for (std::size_t i = 0; i < p.size(); ++i) {
        if (p.kinds()[i] != ParticleKind::Liquid || p.scalarChannel("splits")[i] != Real(0))
            continue;
        ++fresh;
        EXPECT_NEAR(p.scalarChannel("h")[i], 0.729 * h0, 8 * REAL_EPS * h0);
    }
    EXPECT_EQ(fresh, 12 * r.merges);
    std::printf("[measured] default re-split pattern: %s, epsilon %.4f, alpha %.4f, lambda %.5f, "
                "relative Eq. 18 error %.3e\n",
                rp.name.c_str(), rp.epsilon, rp.alpha, rp.lambda[0], rp.relativeError);

    // The next evaporation split of a fresh daughter starts its count again (Fig. 3 cycle).
    Index freshIndex = sph::INVALID_INDEX;
    for (std::size_t i = 0; i < p.size() && freshIndex == sph::INVALID_INDEX; ++i) {
        if (p.kinds()[i] == ParticleKind::Liquid && p.scalarChannel("splits")[i] == Real(0)) {
            freshIndex = Index(i);
        }
    }
    ASSERT_NE(freshIndex, sph::INVALID_INDEX);
    const Index first = splitParticle(p, freshIndex, pattern, evaporate);
    EXPECT_EQ(p.scalarChannel("splits")[first + pattern.centreIndex()], Real(1));
}

TEST(MergeParticles, ReferenceDensitySizeRuleAndValidation)
{
    ParticleSet p = makeTwoCandidates();
    sph::NeighborGrid grid(Real(0.05));
    grid.build(p.positions());
    MergeSettings ms;
    ms.maxMerged = 7;
    ms.resplit = false;
    ms.sizeRule = MergeSizeRule::ReferenceDensity;
    ms.referenceMass = Real(1e-3);
    ms.referenceRadius = Real(0.05);
    const MergeResult r = mergeParticles(p, grid, ms);
    ASSERT_EQ(r.merges, 2u);
    ASSERT_EQ(p.size(), 2u);
    for (std::size_t i = 0; i < 2; ++i) {
        // 7 particles of 1e-3 kg: h' = 0.05 * 7^(1/3)
        EXPECT_NEAR(p.scalarChannel("h")[i], 0.05 * std::cbrt(7.0), 4 * REAL_EPS);
        EXPECT_NEAR(p.masses()[i], 7e-3, 4 * REAL_EPS * 7e-3);
    }

    MergeSettings bad;
    bad.sizeRule = MergeSizeRule::ReferenceDensity;
    try {
        bad.validate();
        FAIL() << "expected ValueError";
    } catch (const ValueError& e) {
        EXPECT_THAT(e.what(), HasSubstr("referenceMass"));
    }
    bad = MergeSettings();
    bad.splitThreshold = 0;
    EXPECT_THROW(bad.validate(), ValueError);
}

} // namespace
