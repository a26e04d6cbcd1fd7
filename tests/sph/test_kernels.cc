/// @file   test_kernels.cc
/// @brief  Property tests of the SPH smoothing kernels: normalisation, gradient against finite
///         differences, antisymmetry, compact support, Laplacian, argument validation.
/// @details STYLE.md rule 4: each kernel must integrate to one over its support, have a gradient
///          that is antisymmetric and equal to finite differences of W, and vanish outside the
///          support. The kernels are evaluated in `Real` (float by default, double with
///          GHOSTFX_DOUBLE=ON) and every tolerance below is written in terms of Real's epsilon so
///          the same tests hold in both builds. References: cubic spline [Monaghan 2005, Sec. 2.2]
///          with support 3h as in [SB12] Sec. 3; poly6, spiky and viscosity kernels
///          [Mueller, Charypar, Gross 2003].
#include <ghostfx/sph/Exceptions.h>
#include <ghostfx/sph/Kernels.h>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <random>
#include <string>

namespace {

using namespace ghostfx::sph;
using ::testing::HasSubstr;

constexpr double EPS = double(std::numeric_limits<Real>::epsilon());

// ---------------------------------------------------------------------------------------------
// Kernel cases. Each names a kernel, a support radius and the radius range (as a fraction of the
// support) where finite differences are meaningful: the spiky kernel has a cone point at r = 0
// and the viscosity kernel a 1/r singularity, so their finite-difference samples stay away from
// the centre.

struct CubicSB12
{
    using Kernel = CubicSplineKernel;
    static Kernel make() { return Kernel::fromSpacing(Real(0.025)); } // R = 3h = 0.075 m
    static constexpr double MIN_FD_RADIUS = 0.02;
};
struct CubicOther
{
    using Kernel = CubicSplineKernel;
    static Kernel make() { return Kernel(Real(0.3)); } // R = 0.3 m: 2/R does not round exactly
    static constexpr double MIN_FD_RADIUS = 0.02;
};
/// A kernel of support R = 0.1 m, finite differences from `MinFdPercent` % of R.
template <typename K, int MinFdPercent>
struct TenthMetre
{
    using Kernel = K;
    static Kernel make() { return Kernel(Real(0.1)); }
    static constexpr double MIN_FD_RADIUS = MinFdPercent / 100.0;
};
using Poly6 = TenthMetre<Poly6Kernel, 2>;
using Spiky = TenthMetre<SpikyKernel, 20>;
using Viscosity = TenthMetre<ViscosityKernel, 30>;

class CaseNames
{
public:
    template <typename T>
    static std::string GetName(int)
    {
        if (std::is_same_v<T, CubicSB12>) return "CubicSpline3h";
        if (std::is_same_v<T, CubicOther>) return "CubicSplineR03";
        if (std::is_same_v<T, Poly6>) return "Poly6";
        if (std::is_same_v<T, Spiky>) return "Spiky";
        return "Viscosity";
    }
};

template <typename Case>
class KernelTest : public ::testing::Test
{};

using KernelCases = ::testing::Types<CubicSB12, CubicOther, Poly6, Spiky, Viscosity>;
TYPED_TEST_SUITE(KernelTest, KernelCases, CaseNames);

/// Uniformly distributed direction on the unit sphere.
Vec3 randomDirection(std::mt19937& rng)
{
    std::normal_distribution<double> n(0.0, 1.0);
    for (;;) {
        const Vec3d d(n(rng), n(rng), n(rng));
        const double len = d.length();
        if (len > 1e-3) return toVec3(d / len);
    }
}

/// Points at radius r in [rMin, rMax) (m) with uniformly random direction.
template <typename Fn>
void forRandomPoints(int count, double rMin, double rMax, unsigned seed, Fn&& fn)
{
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> u(rMin, rMax);
    for (int n = 0; n < count; ++n) fn(Real(u(rng)) * randomDirection(rng));
}

// Finite differences -------------------------------------------------------------------------
//
// A central difference of f with step d has truncation error d^2/6 |f'''| and, when f is
// evaluated with relative rounding error about eps, a rounding error about eps |f| / d. With
// d = eps^(1/3) R both are of order eps^(2/3) times the kernel's natural gradient scale
// (W_max / R for the rounding part, R^2 |W'''| for the truncation part, both within a factor of
// about 20 of max |dW/dr| on the sampled radius range). FD_TOLERANCE allows a factor 100 on top
// of eps^(2/3): 2.4e-3 relative to max |dW/dr| in float, 3.7e-9 in double; the worst cases
// measured are below a quarter of that (the viscosity kernel near its 1/r centre). A wrong
// coefficient or sign in a gradient gives errors of order 1. The sampled radii start where the
// third derivative is still moderate: the spiky kernel has a cone point and the viscosity
// kernel a 1/r term at the centre, whose derivatives grow like r^-2 and r^-4.
const double FD_STEP_FACTOR = std::cbrt(EPS);
const double FD_TOLERANCE = 100.0 * std::pow(EPS, 2.0 / 3.0);

/// max |dW/dr| over [rMin, rMax], scanned finely: the gradient scale the FD errors are relative to.
template <typename Kernel>
double maxAbsDwdr(const Kernel& kernel, double rMin, double rMax)
{
    double m = 0.0;
    for (int s = 0; s <= 4000; ++s) {
        const double r = rMin + (rMax - rMin) * s / 4000.0;
        m = std::max(m, std::abs(double(kernel.dWdr(Real(r)))));
    }
    return m;
}

// ---------------------------------------------------------------------------------------------

/// 5-point Gauss-Legendre nodes and weights on [-1, 1].
constexpr std::array<double, 5> GL_NODES = {-0.9061798459386640, -0.5384693101056831, 0.0,
                                            0.5384693101056831, 0.9061798459386640};
constexpr std::array<double, 5> GL_WEIGHTS = {0.2369268850561891, 0.4786286704993665,
                                              0.5688888888888889, 0.4786286704993665,
                                              0.2369268850561891};

/// Integral over the ball of radius R of W(|x|), i.e. int_0^R 4 pi r^2 W(r) dr, by composite
/// 5-point Gauss-Legendre on `intervals` equal sub-intervals, in double.
template <typename Kernel>
double radialIntegral(const Kernel& kernel, int intervals)
{
    const double R = kernel.supportRadius();
    const double h = R / intervals;
    double total = 0.0;
    for (int k = 0; k < intervals; ++k) {
        const double mid = (k + 0.5) * h;
        double s = 0.0;
        for (int q = 0; q < 5; ++q) {
            const double r = mid + 0.5 * h * GL_NODES[q];
            s += GL_WEIGHTS[q] * 4.0 * M_PI * r * r * double(kernel.W(Real(r)));
        }
        total += 0.5 * h * s;
    }
    return total;
}

TYPED_TEST(KernelTest, IntegratesToOneOverTheBall)
{
    const auto kernel = TypeParam::make();
    // Composite 5-point Gauss-Legendre is exact for polynomials of degree <= 9 on each
    // sub-interval. Every integrand 4 pi r^2 W(r) here is a polynomial of degree <= 8 on pieces
    // whose breakpoints (r = R/2 for the cubic spline, an even number of intervals) are
    // sub-interval ends; the viscosity kernel's R/(2r) term times r^2 is the polynomial R r / 2,
    // and Gauss nodes never sit at r = 0. So the quadrature error is only the double round-off of
    // 2560 positive terms, < 1e-12. What remains is the rounding of W in Real: a few ulps of the
    // coefficient (pi, pow, division) and of the polynomial, plus cancellation near the support
    // (R^2 - r^2, the viscosity bracket). Measured: at most 2 eps (float) and 6 eps (double);
    // tolerance 32 eps + 1e-12 (3.8e-6 in float).
    const double tolerance = 32.0 * EPS + 1e-12;
    const double integral = radialIntegral(kernel, 512);
    EXPECT_NEAR(integral, 1.0, tolerance);
    // The quadrature is converged: 64 intervals give the same answer.
    EXPECT_NEAR(radialIntegral(kernel, 64), integral, tolerance);
}

TEST(CubicSplineKernel, IntegratesToOneOnCartesianMidpointGrid)
{
    // 3-D check that does not rely on the radial form: midpoint rule on n^3 cells covering
    // [-R, R]^3. The midpoint rule's leading error h^2/24 * int (Laplacian W) dV vanishes because
    // gradW = 0 on the support sphere (divergence theorem); what is left is of higher order in
    // h/R (the spline is C^2, with third-derivative jumps at r = R/2 and r = R): 3e-9 measured
    // in the double build with n = 80. In float, the rounding of each W (a few eps, partly
    // systematic) dominates: 1.6e-7 measured. Tolerance 1e-6 + 32 eps (4.8e-6 in float).
    const CubicSplineKernel kernel = CubicSplineKernel::fromSpacing(Real(0.02));
    const double R = kernel.supportRadius();
    const int n = 80;
    const double h = 2.0 * R / n;
    double total = 0.0;
    for (int i = 0; i < n; ++i) {
        for (int j = 0; j < n; ++j) {
            for (int k = 0; k < n; ++k) {
                const Vec3 x(Real(-R + (i + 0.5) * h), Real(-R + (j + 0.5) * h),
                             Real(-R + (k + 0.5) * h));
                total += double(kernel.W(x));
            }
        }
    }
    EXPECT_NEAR(total * h * h * h, 1.0, 1e-6 + 32.0 * EPS);
}

TYPED_TEST(KernelTest, GradientMatchesFiniteDifferences)
{
    const auto kernel = TypeParam::make();
    const double R = kernel.supportRadius();
    const Real d = Real(FD_STEP_FACTOR * R);
    const double rMin = TypeParam::MIN_FD_RADIUS * R;
    const double scale = maxAbsDwdr(kernel, rMin, R);
    ASSERT_GT(scale, 0.0);
    double worst = 0.0;
    forRandomPoints(2000, rMin, R, 1234u, [&](const Vec3& x) {
        const Vec3 g = kernel.gradW(x);
        for (int a = 0; a < 3; ++a) {
            Vec3 e(0);
            e[a] = d;
            const double fd = (double(kernel.W(x + e)) - double(kernel.W(x - e)))
                              / (double((x + e)[a]) - double((x - e)[a]));
            worst = std::max(worst, std::abs(fd - double(g[a])) / scale);
        }
    });
    EXPECT_LT(worst, FD_TOLERANCE);
}

TYPED_TEST(KernelTest, GradientIsConsistentWithRadialDerivative)
{
    // gradW(xij, r) = dW/dr(r) xij / r: the two entry points must agree (to rounding, a few eps).
    const auto kernel = TypeParam::make();
    const double R = kernel.supportRadius();
    forRandomPoints(500, 0.01 * R, R, 99u, [&](const Vec3& x) {
        const Real r = x.length();
        const Vec3 g = kernel.gradW(x, r);
        const Vec3 expected = x * (kernel.dWdr(r) / r);
        for (int a = 0; a < 3; ++a) {
            EXPECT_NEAR(g[a], expected[a], 8 * EPS * std::abs(kernel.dWdr(r)));
        }
    });
}

TYPED_TEST(KernelTest, GradientIsAntisymmetric)
{
    // gradW(-xij) = -gradW(xij) exactly: |-x| rounds like |x|, and negation is exact in IEEE
    // arithmetic, so any difference would be a real asymmetry (Newton's third law in SPH forces).
    const auto kernel = TypeParam::make();
    const double R = kernel.supportRadius();
    forRandomPoints(2000, 0.0, 1.2 * R, 7u, [&](const Vec3& x) {
        const Vec3 g = kernel.gradW(x);
        const Vec3 gm = kernel.gradW(-x);
        for (int a = 0; a < 3; ++a) EXPECT_EQ(gm[a], -g[a]) << "x = " << x;
    });
    // The self term (xij = 0) contributes nothing and is not NaN.
    const Vec3 g0 = kernel.gradW(Vec3(0));
    EXPECT_EQ(g0, Vec3(0));
}

TYPED_TEST(KernelTest, VanishesAtAndBeyondTheSupport)
{
    const auto kernel = TypeParam::make();
    const Real R = kernel.supportRadius();
    const Real inf = std::numeric_limits<Real>::infinity();
    for (Real r : {R, std::nextafter(R, inf), Real(1.0001) * R, Real(2) * R, Real(1e6) * R,
                   std::numeric_limits<Real>::max(), inf}) {
        EXPECT_EQ(kernel.W(r), Real(0)) << "r = " << r;
        EXPECT_EQ(kernel.dWdr(r), Real(0)) << "r = " << r;
    }
    // Along an axis |x| is computed exactly, so x = (R, 0, 0) is exactly on the support.
    for (int a = 0; a < 3; ++a) {
        for (Real s : {Real(1), Real(-1), Real(1.5), Real(-40)}) {
            Vec3 x(0);
            x[a] = s * R;
            EXPECT_EQ(kernel.W(x), Real(0)) << "x = " << x;
            EXPECT_EQ(kernel.gradW(x), Vec3(0)) << "x = " << x;
        }
    }
    // Random directions: wherever the computed |x| is >= R, W and gradW are exactly zero.
    int outside = 0;
    forRandomPoints(2000, 0.999 * double(R), 3.0 * double(R), 5u, [&](const Vec3& x) {
        if (x.length() < R) return;
        ++outside;
        EXPECT_EQ(kernel.W(x), Real(0)) << "x = " << x;
        EXPECT_EQ(kernel.gradW(x), Vec3(0)) << "x = " << x;
    });
    EXPECT_GT(outside, 1900);
    // ... and just inside, W is positive (the support is not smaller than claimed).
    EXPECT_GT(kernel.W(Real(0.99) * R), Real(0));
}

TEST(CubicSplineKernel, VanishesExactlyAtTheSupportForEverySupportRadius)
{
    // The spline is evaluated through q = r * (2 / R), and R * (2 / R) rounds below 2 for about
    // one support radius in seven. The contract is still W = dW/dr = 0 exactly for r >= R and
    // W >= 0 everywhere, whatever R is: sweep R over 0.5 mm .. 1 m.
    int failures = 0;
    for (int i = 1; i <= 2000; ++i) {
        const Real R = Real(0.0005) * Real(i);
        const CubicSplineKernel kernel(R);
        const Real below = std::nextafter(R, Real(0));
        if (kernel.W(R) != Real(0) || kernel.dWdr(R) != Real(0) || kernel.W(below) < Real(0)
            || kernel.dWdr(below) > Real(0)) {
            if (++failures <= 5) {
                ADD_FAILURE() << "R = " << R << ": W(R) = " << kernel.W(R)
                              << ", dW/dr(R) = " << kernel.dWdr(R)
                              << ", W(R - ulp) = " << kernel.W(below);
            }
        }
    }
    EXPECT_EQ(failures, 0);
}

template <typename Kernel>
void checkLaplacian(const Kernel& kernel, double rMinFraction)
{
    // Divergence of gradW by central differences of its components (same error model as
    // FD_TOLERANCE, now relative to max |laplacianW| on the sampled range).
    const double R = kernel.supportRadius();
    const Real d = Real(FD_STEP_FACTOR * R);
    double scale = 0.0;
    for (int s = 0; s <= 4000; ++s) {
        const double r = rMinFraction * R + (1.0 - rMinFraction) * R * s / 4000.0;
        scale = std::max(scale, std::abs(double(kernel.laplacianW(Real(r)))));
    }
    ASSERT_GT(scale, 0.0);
    double worst = 0.0;
    // gradW has a jump in its second derivative at r = R, which would make the central
    // difference error O(d) there: keep the stencil (reach sqrt(3) d) inside the support.
    forRandomPoints(2000, rMinFraction * R, R - 2.0 * double(d), 4321u, [&](const Vec3& x) {
        double div = 0.0;
        for (int a = 0; a < 3; ++a) {
            Vec3 e(0);
            e[a] = d;
            div += (double(kernel.gradW(x + e)[a]) - double(kernel.gradW(x - e)[a]))
                   / (double((x + e)[a]) - double((x - e)[a]));
        }
        worst = std::max(worst, std::abs(div - double(kernel.laplacianW(x.length()))) / scale);
    });
    EXPECT_LT(worst, FD_TOLERANCE);
}

TEST(Poly6Kernel, LaplacianMatchesDivergenceOfGradient)
{
    checkLaplacian(Poly6Kernel(Real(0.1)), 0.02);
    EXPECT_EQ(Poly6Kernel(Real(0.1)).laplacianW(Real(0.1)), Real(0));
}

TEST(ViscosityKernel, LaplacianMatchesDivergenceOfGradient)
{
    const ViscosityKernel kernel(Real(0.1));
    // The R/(2r) term is harmonic (no Laplacian) but its derivatives grow like r^-5, and so does
    // the finite-difference truncation error: from 0.6 R on it stays below a quarter of
    // FD_TOLERANCE.
    checkLaplacian(kernel, 0.6);
    // Mueller et al. chose this kernel because its Laplacian is >= 0 everywhere (viscosity only
    // damps), and zero from the support on.
    for (int s = 0; s < 100; ++s) EXPECT_GT(kernel.laplacianW(Real(0.001) * Real(s)), Real(0));
    EXPECT_EQ(kernel.laplacianW(Real(0.1)), Real(0));
    EXPECT_EQ(kernel.laplacianW(Real(0.2)), Real(0));
}

TEST(CubicSplineKernel, FromSpacingUsesSB12SupportFactor)
{
    const CubicSplineKernel kernel = CubicSplineKernel::fromSpacing(Real(0.02));
    EXPECT_EQ(CubicSplineKernel::SB12_SUPPORT_FACTOR, Real(3));
    EXPECT_EQ(kernel.supportRadius(), Real(0.02) * Real(3));
    EXPECT_EQ(CubicSplineKernel::fromSpacing(Real(0.02), Real(2)).supportRadius(),
              Real(0.02) * Real(2));
}

template <typename Kernel>
void checkRejectsSupport(Real support, const std::string& kernelName, const std::string& shown)
{
    try {
        Kernel kernel(support);
        ADD_FAILURE() << kernelName << " accepted support radius " << support;
    } catch (const ghostfx::ValueError& e) {
        EXPECT_THAT(e.what(), HasSubstr(kernelName));
        EXPECT_THAT(e.what(), HasSubstr("support radius = " + shown));
    }
}

TYPED_TEST(KernelTest, RejectsNonPositiveOrNonFiniteSupport)
{
    using Kernel = typename TypeParam::Kernel;
    const std::string name = std::is_same_v<Kernel, CubicSplineKernel> ? "cubic spline kernel"
                             : std::is_same_v<Kernel, Poly6Kernel>     ? "poly6 kernel"
                             : std::is_same_v<Kernel, SpikyKernel>     ? "spiky kernel"
                                                                       : "viscosity kernel";
    checkRejectsSupport<Kernel>(Real(0), name, "0 m");
    checkRejectsSupport<Kernel>(Real(-0.1), name, "-0.1 m");
    checkRejectsSupport<Kernel>(std::numeric_limits<Real>::quiet_NaN(), name, "nan m");
    checkRejectsSupport<Kernel>(std::numeric_limits<Real>::infinity(), name, "inf m");
    EXPECT_NO_THROW(Kernel(Real(1e-3)));
}

TEST(CubicSplineKernel, FromSpacingRejectsNegativeSpacing)
{
    EXPECT_THROW(CubicSplineKernel::fromSpacing(Real(-0.01)), ghostfx::ValueError);
    EXPECT_THROW(CubicSplineKernel::fromSpacing(Real(0.01), Real(0)), ghostfx::ValueError);
}

} // namespace

TEST(KernelFunctions, PerPairSupportFormsAgreeWithTheKernelObjects)
{
    // The free functions (support as an argument, used by the gas solver's variable smoothing
    // lengths and the splitting integrals) and the kernel objects are one set of kernels: they
    // agree to a few float roundings (1e-5 relative of the kernel's peak) over the support.
    for (const Real R : {Real(0.01), Real(0.05), Real(1)}) {
        const Poly6Kernel poly6(R);
        const SpikyKernel spiky(R);
        const ViscosityKernel viscosity(R);
        for (int k = 0; k <= 40; ++k) {
            const Real r = R * Real(k) / Real(40);
            EXPECT_NEAR(poly6W(r, R), poly6.W(r), 1e-5 * poly6.W(Real(0)))
                << "R " << R << " r " << r;
            EXPECT_NEAR(spikySlope(r, R), -spiky.dWdr(r), 1e-5 * -spiky.dWdr(Real(0)));
            EXPECT_NEAR(viscosityLaplacian(r, R), viscosity.laplacianW(r),
                        1e-5 * viscosity.laplacianW(Real(0)));
            if (k > 0 && k < 40) {
                const Vec3 xij(r * Real(0.6), r * Real(0.8), 0);
                const Vec3 a = spikyGrad(xij, r, R), b = spiky.gradW(xij, r);
                EXPECT_NEAR((a - b).length(), 0.0, 1e-5 * -spiky.dWdr(Real(0)));
            }
        }
    }
    const Poly6Kernel poly6(1);
    const CubicSplineKernel spline(1);
    for (int k = 0; k <= 40; ++k) {
        const double q = k / 40.0;
        EXPECT_NEAR(unitPoly6(q), double(poly6.W(Real(q))), 1e-5 * double(poly6.W(0)));
        EXPECT_NEAR(unitCubicSpline(q), double(spline.W(Real(q))), 1e-5 * double(spline.W(0)));
    }
}
