/// @file   SplitPatterns.h
/// @brief  Particle splitting patterns and their optimal mass ratios ([RYY15] Sec. 4.1, Eq. 18).
/// @details A split pattern replaces a mother particle N (position x_N, mass m_N, smoothing radius
///          h_N) by M daughters at x_N + epsilon h_N o_k with |o_k| = 1 (or o_k = 0 for a centre
///          daughter), smoothing radius alpha h_N and mass lambda_k m_N ([RYY15] Fig. 2). Here, as
///          in [RYY15] and the Mueller et al. 2003 kernels it uses, the "smoothing radius" h is the
///          kernel's support radius.
///
///          The mass ratios are chosen as in Feldman and Bonet 2007 ([RYY15] ref. 9): minimise the
///          L2 distance between the mother's density field and the daughters' sum,
///
///            E = int ( m_N W(x - x_N, h_N) - sum_k lambda_k m_N W(x - x_k, alpha h_N) )^2 dx
///              = m_N^2 / h_N^3 ( C - 2 lambda^T b + lambda^T A lambda )        ([RYY15] Eq. 18)
///
///          subject to sum_k lambda_k = 1. After the change of variable x = x_N + h_N s, with the
///          unit-support kernel w(s) and the daughter kernel w_k(s) = alpha^-3 w((s - epsilon o_k)
///          / alpha):  C = int w^2,  b_k = int w w_k,  A_kl = int w_k w_l.  ([RYY15] writes A_kl with
///          the factor alpha^-d after a second change of variable s = alpha t; the numbers are the
///          same.) This file reports the normalised error C - 2 lambda^T b + lambda^T A lambda
///          (E without the factor m_N^2 / h_N^3) and the same divided by C.
///
///          Quadrature. Every term is an overlap integral of two radial kernels whose centres are
///          a distance d apart. Integrating over spheres around one centre reduces it to 1-D:
///            I(d) = 2 pi / d int_0^R1 f1(r) r [ int_|r-d|^min(r+d,R2) f2(rho) rho drho ] dr,
///          (I(0) = 4 pi int f1 f2 r^2 dr). Both integrals are done by composite Gauss-Legendre on
///          sub-intervals split at every point where the integrand has a kink (kernel knots, the
///          ends of the support, r = d, r = |d - R2|, r = R2 - d), so on each sub-interval the
///          integrand is smooth; for the piecewise-polynomial kernels used here (poly6, M4 cubic
///          spline) it is a polynomial of degree <= 15 and the default rule (8 nodes, 2 panels) is
///          exact up to round-off. The refinement study in tests/gas/test_split_merge.cc measures
///          this against a 16-node, 4-panel reference: the default rule agrees to <= 1.2e-15
///          relative for both kernels, 4 nodes to <= 4e-5 (poly6) / 3e-7 (spline), 2 nodes to
///          <= 8e-3; the concentric poly6 term matches its closed form (a Beta function) to 6e-16,
///          and the 1-D reduction matches a brute-force 3-D Cartesian midpoint sum to 9e-10
///          (96^3 points).
///
///          Patterns used by [RYY15] Sec. 4.2: a regular icosahedron without centre daughter for
///          boiling, (epsilon, alpha) = (0.3, 0.9); a cube with centre daughter for evaporation,
///          (0.4, 0.9). Optimised patterns are memoised per (shape, epsilon, alpha, kernel) in a
///          thread-safe cache; `cachedPattern` returns a reference that stays valid for the life of
///          the program.
#pragma once

#include <ghostfx/sph/Types.h>

#include <string>
#include <vector>

namespace ghostfx {
namespace gas {

using sph::Real;
using sph::Vec3d;

/// Radial kernel whose density field the refinement error compares. Poly6 is what [RYY15] uses
/// for densities (its ref. 20, Mueller et al. 2003); the M4 cubic spline is offered for
/// comparison with Feldman and Bonet 2007, who use a spline.
enum class SplitKernel {
    Poly6, ///< w(q) = 315 / (64 pi) (1 - q^2)^3, q = r / h (support radius h)
    CubicSpline ///< Monaghan M4 with support radius h (smoothing length h / 2), as sph::CubicSplineKernel
};

/// "poly6" or "cubic_spline".
const char* splitKernelName(SplitKernel kernel);

/// Unit-support kernel value w(q) in double precision (1 / unit volume), 0 for q >= 1.
double unitKernel(SplitKernel kernel, double q);

/// Composite Gauss-Legendre rule used for every overlap integral.
struct Quadrature
{
    int nodes = 8;  ///< Gauss-Legendre nodes per panel, 1..16 (exact for degree 2 nodes - 1)
    int panels = 2; ///< equal panels per smooth sub-interval, >= 1

    /// Throws ValueError naming the field if out of range.
    void validate() const;
};

/// Overlap integral int f1(|x|) f2(|x - d e|) dx of two unit-shape kernels scaled to support
/// radii r1, r2 (unit-normalised: f(r) = r^-3 w(r / R)), centres d apart.
/// @param d   distance between the centres (units of the mother's h)
/// @param r1  support radius of the first kernel (units of the mother's h), > 0
/// @param r2  support radius of the second kernel (units of the mother's h), > 0
double overlapIntegral(SplitKernel kernel, double d, double r1, double r2,
                       const Quadrature& quad = Quadrature());

/// The quadratic form of [RYY15] Eq. 18 for one pattern: E / (m_N^2 / h_N^3) =
/// C - 2 lambda^T b + lambda^T A lambda.
struct RefinementTerms
{
    double C = 0;          ///< int w^2 over the mother's kernel
    std::vector<double> b; ///< b_k = int w w_k, one per daughter
    std::vector<double> A; ///< A_kl = int w_k w_l, row-major M x M, symmetric positive definite

    std::size_t size() const { return b.size(); }
    /// Normalised error C - 2 lambda^T b + lambda^T A lambda (dimensionless, >= 0 up to round-off).
    double error(const std::vector<double>& lambda) const;
};

/// Assemble C, b and A for unit daughter offsets `offsets` (|o| = 1, or 0 for a centre daughter).
/// @param epsilon  daughter distance / mother's smoothing radius (> 0)
/// @param alpha    daughter smoothing radius / mother's smoothing radius (> 0)
RefinementTerms refinementTerms(const std::vector<Vec3d>& offsets, double epsilon, double alpha,
                                SplitKernel kernel = SplitKernel::Poly6,
                                const Quadrature& quad = Quadrature());

/// Normalised refinement error of [RYY15] Eq. 18 for given mass ratios (one per offset).
double refinementError(const std::vector<Vec3d>& offsets, const std::vector<double>& lambda,
                       double epsilon, double alpha, SplitKernel kernel = SplitKernel::Poly6,
                       const Quadrature& quad = Quadrature());

/// The shapes this library builds. Offsets of the outer daughters have unit length.
enum class PatternShape {
    Icosahedron,       ///< 12 vertices of a regular icosahedron, no centre ([RYY15] boiling)
    IcosahedronCentre, ///< the 12 vertices plus a centre daughter
    Cube,              ///< 8 corners (+-1, +-1, +-1) / sqrt(3), no centre
    CubeCentre,        ///< 8 corners plus a centre daughter ([RYY15] evaporation)
};

/// "icosahedron", "icosahedron+centre", "cube", "cube+centre".
const char* patternShapeName(PatternShape shape);

/// Unit offsets of a shape; a centre daughter, if any, comes last with offset (0, 0, 0).
std::vector<Vec3d> patternOffsets(PatternShape shape);

/// A split pattern with its optimal mass ratios.
struct SplitPattern
{
    std::string name;           ///< e.g. "cube+centre"
    std::vector<Vec3d> offsets; ///< daughter k at x_N + epsilon h_N offsets[k]; |o| = 1 or 0
    bool hasCentre = false;     ///< whether one daughter sits at the mother's position
    double epsilon = 0;         ///< daughter distance / mother's smoothing radius
    double alpha = 0;           ///< daughter smoothing radius / mother's smoothing radius
    SplitKernel kernel = SplitKernel::Poly6;
    std::vector<double> lambda; ///< mass ratio per daughter, sum = 1 ([RYY15] Sec. 4.1)
    double error = 0;           ///< normalised Eq. 18 error at lambda (see RefinementTerms)
    double relativeError = 0;   ///< error / C: squared L2 error relative to the mother's field

    std::size_t childCount() const { return offsets.size(); }
    /// Index of the centre daughter, or childCount() if there is none.
    std::size_t centreIndex() const;
};

/// Minimise Eq. 18 over lambda with sum(lambda) = 1: the KKT system
///   [ 2A  1 ] [lambda]   [2b]
///   [ 1^T 0 ] [  mu  ] = [ 1]
/// solved with Eigen (full-pivot LU). A is positive definite, so the minimiser is unique and
/// inherits the pattern's symmetry (equal lambda on symmetric daughters) without imposing it.
/// Throws ValueError for epsilon or alpha <= 0, no offsets, or an offset whose length is not 0 or 1.
SplitPattern optimisePattern(const std::string& name, const std::vector<Vec3d>& offsets,
                             double epsilon, double alpha, SplitKernel kernel = SplitKernel::Poly6,
                             const Quadrature& quad = Quadrature());

/// A pattern with prescribed mass ratios (one per offset, summing to 1 within 1e-9; they are
/// renormalised to sum exactly): its Eq. 18 error is evaluated, nothing is optimised. For
/// patterns chosen by other criteria, such as the paper's evaporation ratios below.
SplitPattern evaluatePattern(const std::string& name, const std::vector<Vec3d>& offsets,
                             double epsilon, double alpha, const std::vector<double>& lambda,
                             SplitKernel kernel = SplitKernel::Poly6,
                             const Quadrature& quad = Quadrature());

/// Optimised pattern for a shape, computed once per (shape, epsilon, alpha, kernel) and memoised
/// (thread-safe; the reference stays valid for the life of the program).
const SplitPattern& cachedPattern(PatternShape shape, double epsilon, double alpha,
                                  SplitKernel kernel = SplitKernel::Poly6);

/// [RYY15] Sec. 4.2 boiling pattern: icosahedron without centre, (epsilon, alpha) = (0.3, 0.9).
const SplitPattern& icosahedronPattern();
/// [RYY15] Sec. 4.2 evaporation pattern: cube with centre, (epsilon, alpha) = (0.4, 0.9), with
/// the Eq. 18-optimal ratios (poly6: centre 0.535, corners 0.058; see paperCubePattern for the
/// paper's 0.992 / 0.001 and why they differ).
const SplitPattern& cubePattern();

/// The cube-with-centre pattern at (0.4, 0.9) with the mass ratios [RYY15] Sec. 4.2 states
/// (centre 0.992, corners 0.001 each) instead of the Eq. 18 optimum. At (0.4, 0.9) the optimum
/// puts 0.535 (poly6) or 0.632 (cubic spline) on the centre, see cubePattern(); the paper's
/// ratios are the optimum only for alpha close to 1 (0.9985 with poly6 at epsilon 0.4) and
/// have 14 times the optimal Eq. 18 error at alpha = 0.9 (relative 5.6e-2 against 4.0e-3).
/// They transfer only 0.8 % of the liquid's mass to gas per split, which is what the paper's
/// evaporation wants ("a small fraction of liquid mass turned into gas phase in each splitting").
const SplitPattern& paperCubePattern();

/// The epsilon in [epsMin, epsMax] minimising the optimal Eq. 18 error of a shape at a fixed
/// alpha (golden-section search to `tolerance`; [RYY15] Sec. 4.1 suggests tabulating (E, lambda)
/// over (epsilon, alpha) to choose patterns: this is the 1-D slice of that chart).
double bestEpsilon(PatternShape shape, double alpha, double epsMin, double epsMax,
                   SplitKernel kernel = SplitKernel::Poly6, double tolerance = 1e-4);

} // namespace gas
} // namespace ghostfx
