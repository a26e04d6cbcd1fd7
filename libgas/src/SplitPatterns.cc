/// @file   SplitPatterns.cc
/// @brief  Split patterns and their Eq. 18-optimal mass ratios ([RYY15] Sec. 4.1, Feldman and
///         Bonet 2007).
#include "ghostfx/gas/SplitPatterns.h"

#include <ghostfx/sph/EnumNames.h>
#include <ghostfx/sph/Exceptions.h>
#include <ghostfx/sph/Kernels.h>

#include <Eigen/Dense>

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <memory>
#include <mutex>
#include <tuple>

namespace ghostfx {
namespace gas {

namespace {

constexpr double PI_D = 3.14159265358979323846;
constexpr int MAX_GL_NODES = 16;

/// Gauss-Legendre nodes and weights on [-1, 1] for n = 1..MAX_GL_NODES, computed once by Newton
/// iteration on the Legendre recurrence (converges to round-off in a few steps from the
/// Chebyshev-like initial guess).
struct GaussLegendreTable
{
    std::array<std::vector<double>, MAX_GL_NODES + 1> x, w;

    GaussLegendreTable()
    {
        for (int n = 1; n <= MAX_GL_NODES; ++n) {
            x[n].resize(n);
            w[n].resize(n);
            for (int i = 0; i < n; ++i) {
                double z = std::cos(PI_D * (i + 0.75) / (n + 0.5));
                double dp = 1.0;
                for (int iter = 0; iter < 100; ++iter) {
                    double p0 = 1.0, p1 = z;
                    for (int k = 2; k <= n; ++k) {
                        const double p2 = ((2.0 * k - 1.0) * z * p1 - (k - 1.0) * p0) / k;
                        p0 = p1;
                        p1 = p2;
                    }
                    const double pn = n == 1 ? z : p1;
                    const double pm = n == 1 ? 1.0 : p0;
                    dp = n * (z * pn - pm) / (z * z - 1.0);
                    const double dz = pn / dp;
                    z -= dz;
                    if (std::abs(dz) < 1e-16) break;
                }
                x[n][i] = z;
                w[n][i] = 2.0 / ((1.0 - z * z) * dp * dp);
            }
        }
    }
};

const GaussLegendreTable& glTable()
{
    static const GaussLegendreTable table; // built once, thread-safe (C++11 static init)
    return table;
}

/// Kinks of the unit-support kernel inside (0, 1), as fractions of the support radius.
std::vector<double> kernelKnots(SplitKernel kernel)
{
    if (kernel == SplitKernel::CubicSpline) return {0.5};
    return {};
}

/// Kernel of support radius R evaluated at distance r: R^-3 w(r / R).
double scaledKernel(SplitKernel kernel, double r, double R)
{
    return unitKernel(kernel, r / R) / (R * R * R);
}

/// Composite Gauss-Legendre integral of fn over [a, b] split at the sorted `breaks` inside it.
template <typename Fn>
double integratePieces(double a, double b, std::vector<double> breaks, const Quadrature& quad,
                       Fn&& fn)
{
    if (!(b > a)) return 0.0;
    breaks.push_back(a);
    breaks.push_back(b);
    std::sort(breaks.begin(), breaks.end());
    const auto& gx = glTable().x[quad.nodes];
    const auto& gw = glTable().w[quad.nodes];
    double total = 0.0;
    double lo = a;
    for (double brk : breaks) {
        if (brk <= lo) continue;
        const double hi = std::min(brk, b);
        if (hi <= lo) continue;
        const double panel = (hi - lo) / quad.panels;
        for (int p = 0; p < quad.panels; ++p) {
            const double pa = lo + p * panel;
            const double half = 0.5 * panel, mid = pa + half;
            double s = 0.0;
            for (int k = 0; k < quad.nodes; ++k) s += gw[k] * fn(mid + half * gx[k]);
            total += half * s;
        }
        lo = hi;
        if (lo >= b) break;
    }
    return total;
}

void checkPatternArgs(const std::vector<Vec3d>& offsets, double epsilon, double alpha)
{
    if (!(epsilon > 0.0) || !std::isfinite(epsilon)) {
        throw ValueError(msg("split pattern epsilon = ", epsilon, ": expected a finite value > 0"));
    }
    if (!(alpha > 0.0) || !std::isfinite(alpha)) {
        throw ValueError(msg("split pattern alpha = ", alpha, ": expected a finite value > 0"));
    }
    if (offsets.empty()) throw ValueError("split pattern has no daughter offsets: expected >= 1");
    for (std::size_t k = 0; k < offsets.size(); ++k) {
        const double len = offsets[k].length();
        if (len > 1e-12 && std::abs(len - 1.0) > 1e-9) {
            throw ValueError(msg("split pattern offset ", k, " has length ", len,
                                 ": expected 1 (outer daughter) or 0 (centre daughter)"));
        }
    }
}

} // namespace

const char* splitKernelName(SplitKernel kernel)
{
    return kernel == SplitKernel::Poly6 ? "poly6" : "cubic_spline";
}

double unitKernel(SplitKernel kernel, double q)
{
    return kernel == SplitKernel::Poly6 ? sph::unitPoly6(q) : sph::unitCubicSpline(q);
}

void Quadrature::validate() const
{
    if (nodes < 1 || nodes > MAX_GL_NODES) {
        throw ValueError(msg("quadrature.nodes = ", nodes, ": expected 1..", MAX_GL_NODES));
    }
    if (panels < 1) throw ValueError(msg("quadrature.panels = ", panels, ": expected >= 1"));
}

double overlapIntegral(SplitKernel kernel, double d, double r1, double r2, const Quadrature& quad)
{
    quad.validate();
    if (!(r1 > 0.0) || !(r2 > 0.0)) {
        throw ValueError(msg("overlapIntegral: support radii ", r1, ", ", r2, ": expected > 0"));
    }
    d = std::abs(d);
    if (d >= r1 + r2) return 0.0;
    const std::vector<double> knots = kernelKnots(kernel);

    if (d < 1e-12) {
        // Concentric: 4 pi int f1 f2 r^2 dr.
        std::vector<double> breaks;
        for (double k : knots) {
            breaks.push_back(k * r1);
            breaks.push_back(k * r2);
        }
        return 4.0 * PI_D * integratePieces(0.0, std::min(r1, r2), breaks, quad, [&](double r) {
                   return scaledKernel(kernel, r, r1) * scaledKernel(kernel, r, r2) * r * r;
               });
    }

    // Radii where the inner limits |r - d|, min(r + d, R2) cross a kink of f2 or the end of its
    // support, where |r - d| itself kinks (r = d), and the kinks of f1.
    std::vector<double> fractions = knots;
    fractions.push_back(1.0);
    std::vector<double> breaks{d};
    for (double k : knots) breaks.push_back(k * r1);
    for (double k : fractions) {
        breaks.push_back(d + k * r2);
        breaks.push_back(d - k * r2);
        breaks.push_back(k * r2 - d);
    }
    breaks.erase(std::remove_if(breaks.begin(), breaks.end(),
                                [&](double x) { return !(x > 0.0 && x < r1); }),
                 breaks.end());

    auto shellIntegral = [&](double r) {
        // G(r) = int_{|r-d|}^{min(r+d, R2)} f2(rho) rho drho
        const double lo = std::abs(r - d);
        const double hi = std::min(r + d, r2);
        if (!(hi > lo)) return 0.0;
        std::vector<double> inner;
        for (double k : knots) inner.push_back(k * r2);
        return integratePieces(lo, hi, inner, quad,
                               [&](double rho) { return scaledKernel(kernel, rho, r2) * rho; });
    };
    const double outer = integratePieces(0.0, r1, breaks, quad, [&](double r) {
        return scaledKernel(kernel, r, r1) * r * shellIntegral(r);
    });
    return 2.0 * PI_D / d * outer;
}

double RefinementTerms::error(const std::vector<double>& lambda) const
{
    const std::size_t n = size();
    if (lambda.size() != n) {
        throw ValueError(msg("refinement error: ", lambda.size(), " mass ratios for ", n,
                             " daughters: expected one per daughter"));
    }
    double e = C;
    for (std::size_t k = 0; k < n; ++k) {
        e -= 2.0 * lambda[k] * b[k];
        for (std::size_t l = 0; l < n; ++l) e += lambda[k] * A[k * n + l] * lambda[l];
    }
    return e;
}

RefinementTerms refinementTerms(const std::vector<Vec3d>& offsets, double epsilon, double alpha,
                                SplitKernel kernel, const Quadrature& quad)
{
    checkPatternArgs(offsets, epsilon, alpha);
    quad.validate();
    const std::size_t n = offsets.size();
    RefinementTerms t;
    t.C = overlapIntegral(kernel, 0.0, 1.0, 1.0, quad);
    t.b.resize(n);
    t.A.assign(n * n, 0.0);
    // Overlaps depend only on the distance between centres: memoise them per distance (a
    // symmetric pattern has only a handful of distinct daughter-daughter distances).
    std::map<long long, double> byDistance;
    auto daughterOverlap = [&](double dist) {
        const long long key = std::llround(dist * 1e12);
        auto it = byDistance.find(key);
        if (it != byDistance.end()) return it->second;
        const double v = overlapIntegral(kernel, dist, alpha, alpha, quad);
        byDistance.emplace(key, v);
        return v;
    };
    for (std::size_t k = 0; k < n; ++k) {
        t.b[k] = overlapIntegral(kernel, epsilon * offsets[k].length(), 1.0, alpha, quad);
        for (std::size_t l = k; l < n; ++l) {
            const double v = daughterOverlap(epsilon * (offsets[k] - offsets[l]).length());
            t.A[k * n + l] = v;
            t.A[l * n + k] = v;
        }
    }
    return t;
}

double refinementError(const std::vector<Vec3d>& offsets, const std::vector<double>& lambda,
                       double epsilon, double alpha, SplitKernel kernel, const Quadrature& quad)
{
    return refinementTerms(offsets, epsilon, alpha, kernel, quad).error(lambda);
}

const char* patternShapeName(PatternShape shape)
{
    static const sph::EnumName<PatternShape> names[] = {
        {PatternShape::Icosahedron, "icosahedron"},
        {PatternShape::IcosahedronCentre, "icosahedron+centre"},
        {PatternShape::Cube, "cube"},
        {PatternShape::CubeCentre, "cube+centre"}};
    return sph::nameOf(names, shape);
}

std::vector<Vec3d> patternOffsets(PatternShape shape)
{
    std::vector<Vec3d> o;
    if (shape == PatternShape::Icosahedron || shape == PatternShape::IcosahedronCentre) {
        // Vertices (0, +-1, +-phi) and their cyclic permutations, phi the golden ratio.
        const double phi = 0.5 * (1.0 + std::sqrt(5.0));
        for (double s1 : {-1.0, 1.0}) {
            for (double s2 : {-1.0, 1.0}) {
                o.emplace_back(0.0, s1, s2 * phi);
                o.emplace_back(s1, s2 * phi, 0.0);
                o.emplace_back(s2 * phi, 0.0, s1);
            }
        }
    } else {
        for (double sx : {-1.0, 1.0}) {
            for (double sy : {-1.0, 1.0}) {
                for (double sz : {-1.0, 1.0}) o.emplace_back(sx, sy, sz);
            }
        }
    }
    for (auto& v : o) v.normalize();
    if (shape == PatternShape::IcosahedronCentre || shape == PatternShape::CubeCentre) {
        o.emplace_back(0.0, 0.0, 0.0);
    }
    return o;
}

std::size_t SplitPattern::centreIndex() const
{
    for (std::size_t k = 0; k < offsets.size(); ++k) {
        if (offsets[k].lengthSqr() == 0.0) return k;
    }
    return offsets.size();
}

namespace {

/// The pattern with mass ratios `lambda` scaled to sum to 1 (to the round-off of this one sum,
/// which keeps daughters' masses summing to the mother's), and its Eq. 18 error from `t`.
SplitPattern patternWith(const std::string& name, const std::vector<Vec3d>& offsets, double epsilon,
                         double alpha, SplitKernel kernel, std::vector<double> lambda,
                         const RefinementTerms& t)
{
    SplitPattern p;
    p.name = name;
    p.offsets = offsets;
    p.epsilon = epsilon;
    p.alpha = alpha;
    p.kernel = kernel;
    double sum = 0.0;
    for (double l : lambda) sum += l;
    for (double& l : lambda) l /= sum;
    p.lambda = std::move(lambda);
    p.hasCentre = p.centreIndex() < p.offsets.size();
    p.error = t.error(p.lambda);
    p.relativeError = p.error / t.C;
    return p;
}

} // namespace

SplitPattern optimisePattern(const std::string& name, const std::vector<Vec3d>& offsets,
                             double epsilon, double alpha, SplitKernel kernel,
                             const Quadrature& quad)
{
    const RefinementTerms t = refinementTerms(offsets, epsilon, alpha, kernel, quad);
    const int n = int(t.size());

    // KKT system of min C - 2 l.b + l.A.l subject to 1.l = 1 (Lagrange multiplier mu).
    Eigen::MatrixXd K = Eigen::MatrixXd::Zero(n + 1, n + 1);
    Eigen::VectorXd rhs(n + 1);
    for (int k = 0; k < n; ++k) {
        for (int l = 0; l < n; ++l) K(k, l) = 2.0 * t.A[std::size_t(k) * n + l];
        K(k, n) = 1.0;
        K(n, k) = 1.0;
        rhs(k) = 2.0 * t.b[k];
    }
    rhs(n) = 1.0;
    const Eigen::VectorXd sol = K.fullPivLu().solve(rhs);

    // patternWith removes the constraint residual of the solve (order 1e-15).
    std::vector<double> lambda(n);
    for (int k = 0; k < n; ++k) lambda[k] = sol(k);
    const SplitPattern p = patternWith(name, offsets, epsilon, alpha, kernel, lambda, t);
    if (!std::isfinite(p.error)) {
        throw NumericalError(msg("split pattern '", name, "' (epsilon ", epsilon, ", alpha ", alpha,
                                 "): the optimal mass ratios are not finite"));
    }
    return p;
}

SplitPattern evaluatePattern(const std::string& name, const std::vector<Vec3d>& offsets,
                             double epsilon, double alpha, const std::vector<double>& lambda,
                             SplitKernel kernel, const Quadrature& quad)
{
    const RefinementTerms t = refinementTerms(offsets, epsilon, alpha, kernel, quad);
    double sum = 0.0;
    for (double l : lambda) sum += l;
    if (lambda.size() != offsets.size() || !(std::abs(sum - 1.0) <= 1e-9)) {
        throw ValueError(msg("split pattern '", name, "': ", lambda.size(),
                             " mass ratios summing "
                             "to ",
                             sum, ": expected one per daughter (", offsets.size(),
                             ") summing to 1"));
    }
    return patternWith(name, offsets, epsilon, alpha, kernel, lambda, t);
}

const SplitPattern& paperCubePattern()
{
    static const SplitPattern pattern = [] {
        std::vector<double> lambda(9, 0.001);
        lambda[8] = 0.992; // the centre daughter comes last in patternOffsets
        return evaluatePattern("cube+centre (RYY15 ratios)",
                               patternOffsets(PatternShape::CubeCentre), 0.4, 0.9, lambda);
    }();
    return pattern;
}

const SplitPattern& cachedPattern(PatternShape shape, double epsilon, double alpha,
                                  SplitKernel kernel)
{
    using Key = std::tuple<int, double, double, int>;
    static std::mutex mutex;
    static std::map<Key, std::unique_ptr<const SplitPattern>> cache;
    const Key key{int(shape), epsilon, alpha, int(kernel)};
    std::lock_guard<std::mutex> lock(mutex);
    auto it = cache.find(key);
    if (it == cache.end()) {
        auto p = std::make_unique<const SplitPattern>(optimisePattern(
            patternShapeName(shape), patternOffsets(shape), epsilon, alpha, kernel));
        it = cache.emplace(key, std::move(p)).first;
    }
    return *it->second;
}

const SplitPattern& icosahedronPattern()
{
    return cachedPattern(PatternShape::Icosahedron, 0.3, 0.9);
}

const SplitPattern& cubePattern() { return cachedPattern(PatternShape::CubeCentre, 0.4, 0.9); }

double bestEpsilon(PatternShape shape, double alpha, double epsMin, double epsMax,
                   SplitKernel kernel, double tolerance)
{
    if (!(epsMin > 0.0) || !(epsMax > epsMin)) {
        throw ValueError(
            msg("bestEpsilon: range [", epsMin, ", ", epsMax, "]: expected 0 < epsMin < epsMax"));
    }
    const std::vector<Vec3d> offsets = patternOffsets(shape);
    auto f = [&](double eps) {
        return optimisePattern(patternShapeName(shape), offsets, eps, alpha, kernel).error;
    };
    const double g = 0.5 * (std::sqrt(5.0) - 1.0);
    double a = epsMin, b = epsMax;
    double c = b - g * (b - a), d = a + g * (b - a);
    double fc = f(c), fd = f(d);
    while (b - a > tolerance) {
        if (fc < fd) {
            b = d;
            d = c;
            fd = fc;
            c = b - g * (b - a);
            fc = f(c);
        } else {
            a = c;
            c = d;
            fc = fd;
            d = a + g * (b - a);
            fd = f(d);
        }
    }
    return 0.5 * (a + b);
}

} // namespace gas
} // namespace ghostfx
