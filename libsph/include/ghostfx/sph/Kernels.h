/// @file   Kernels.h
/// @brief  SPH smoothing kernels as small value objects (no static state).
/// @details Every kernel has the same interface so solvers take it as a template parameter and
///          the inner loops inline it:
///            - `supportRadius()`    radius beyond which W = 0 (m)
///            - `W(r)`               kernel value at distance r (1/m^3)
///            - `gradW(xij, r)`      gradient with respect to x_i, xij = x_i - x_j, r = |xij| (1/m^4)
///            - `dWdr(r)`            radial derivative (1/m^4)
///          All are normalised in 3-D: the volume integral of W is 1.
///
///          - CubicSplineKernel: Monaghan's M4 spline [Monaghan 2005, Sec. 2.2], used by [SB12]
///            with support radius 3h for particle spacing h (Sec. 3).
///          - Poly6Kernel, SpikyKernel, ViscosityKernel: Mueller, Charypar, Gross 2003, used by
///            [RYY15] for density (poly6), pressure gradient (spiky) and viscosity (Laplacian).
#pragma once

#include <algorithm>

#include "ghostfx/sph/Exceptions.h"
#include "ghostfx/sph/Types.h"

namespace ghostfx {
namespace sph {

namespace detail {
/// min and max by value: std::min / std::max return references, which keeps GCC from turning
/// them into vector min / max instructions inside neighbour loops.
inline Real lesser(Real a, Real b) { return b < a ? b : a; }
inline Real greater(Real a, Real b) { return a < b ? b : a; }

inline Real checkedSupport(Real supportRadius, const char* kernelName)
{
    if (!(supportRadius > Real(0)) || !std::isfinite(supportRadius)) {
        throw ValueError(msg(kernelName, " support radius = ", supportRadius,
                             " m: expected a finite value > 0"));
    }
    return supportRadius;
}
} // namespace detail

/// Monaghan's M4 cubic B-spline. With smoothing length s = R/2 and q = r/s:
///   W = 1/(pi s^3) * (1 - 3/2 q^2 + 3/4 q^3)  for 0 <= q < 1
///   W = 1/(pi s^3) * 1/4 (2 - q)^3            for 1 <= q < 2, and 0 beyond.
class CubicSplineKernel
{
    static Real lesser(Real a, Real b) { return detail::lesser(a, b); }
    static Real greater(Real a, Real b) { return detail::greater(a, b); }

public:
    /// Support factor of [SB12] Sec. 3: support radius = 3 x particle spacing.
    static constexpr Real SB12_SUPPORT_FACTOR = Real(3);

    /// @param supportRadius  radius of support R (m); W vanishes for r >= R
    explicit CubicSplineKernel(Real supportRadius)
        : mSupport(detail::checkedSupport(supportRadius, "cubic spline kernel"))
        , mInvS(Real(2) / supportRadius)
        , mSigma(Real(1) / (PI * cube(supportRadius / Real(2))))
        , mCut(Real(1e20) / supportRadius)
    {}

    /// Kernel for particle spacing h (m) with support radius `supportFactor` * h.
    static CubicSplineKernel fromSpacing(Real spacing, Real supportFactor = SB12_SUPPORT_FACTOR)
    {
        return CubicSplineKernel(spacing * supportFactor);
    }

    Real supportRadius() const { return mSupport; }

    // Branch-free forms, so neighbour loops vectorise and never mispredict (q < 1 holds for a
    // third of the pairs at random): with u = min(q, 1), v = max(q, 1) and t = max(2 - v, 0),
    // each piece is evaluated at its clamped argument, where the other piece is constant, and
    // the two are added:
    //   W     = sigma (0.75 (1 - 2 u^2 + u^3) + 0.25 t^3)
    //   dW/dr = sigma / s (u (2.25 u - 3) + 0.75 - 0.75 t^2)
    //   (dW/dr) / r = sigma / s^2 (2.25 (u - 1) - 0.75 t^2 / v)
    // which reduce to the two polynomials above on their intervals, to exactly 0 for q >= 2,
    // and keep each polynomial's accuracy near q = 0 and q = 1. t is also cut to 0 for r >= R
    // (the test is on r itself: r * (2 / R) can round below 2 at r = R, and W(R) must be 0)
    // through min(2 - v, (R - r) * big), which is negative exactly when r >= R.

    Real W(Real r) const
    {
        const Real q = r * mInvS;
        const Real u = lesser(q, Real(1));
        const Real t = cutoff(q, r);
        return mSigma
               * (Real(0.75) * (Real(1) - Real(2) * u * u + u * u * u) + Real(0.25) * t * t * t);
    }

    Real dWdr(Real r) const
    {
        const Real q = r * mInvS;
        const Real u = lesser(q, Real(1));
        const Real t = cutoff(q, r);
        return mSigma * mInvS * (u * (Real(2.25) * u - Real(3)) + Real(0.75) - Real(0.75) * t * t);
    }

    /// (dW/dr) / r (1/m^5): grad W = xij * gradFactor(r). Finite at r = 0 (where xij = 0) and
    /// zero for r >= R.
    Real gradFactor(Real r) const
    {
        const Real q = r * mInvS;
        const Real u = lesser(q, Real(1));
        const Real v = greater(q, Real(1));
        const Real t = cutoff(q, r);
        return mSigma * mInvS * mInvS * (Real(2.25) * (u - Real(1)) - Real(0.75) * t * t / v);
    }

    /// grad W = dW/dr x_ij / r; zero at r = 0 and for r >= R.
    Vec3 gradW(const Vec3& xij, Real r) const { return xij * gradFactor(r); }

    Real W(const Vec3& xij) const { return W(xij.length()); }
    Vec3 gradW(const Vec3& xij) const { return gradW(xij, xij.length()); }

private:
    /// t = max(2 - max(q, 1), 0), and 0 for r >= R.
    Real cutoff(Real q, Real r) const
    {
        return std::max(std::min(Real(2) - greater(q, Real(1)), (mSupport - r) * mCut), Real(0));
    }

    Real mSupport; ///< R (m)
    Real mInvS;    ///< 1 / s = 2 / R (1/m)
    Real mSigma;   ///< 1 / (pi s^3) (1/m^3)
    Real mCut;     ///< 1e20 / R (1/m): (R - r) * mCut exceeds 2 for any r below R
};

/// Mueller et al. 2003 poly6: W = 315 / (64 pi R^9) (R^2 - r^2)^3. Smooth at r = 0; used for
/// density sums. Its gradient vanishes at the centre, so it is not used for pressure.
class Poly6Kernel
{
public:
    explicit Poly6Kernel(Real supportRadius)
        : mSupport(detail::checkedSupport(supportRadius, "poly6 kernel"))
        , mR2(supportRadius * supportRadius)
        , mCoef(Real(315) / (Real(64) * PI * std::pow(supportRadius, Real(9))))
    {}

    Real supportRadius() const { return mSupport; }

    Real W(Real r) const
    {
        if (r >= mSupport) return Real(0);
        return mCoef * cube(mR2 - r * r);
    }

    Real dWdr(Real r) const
    {
        if (r >= mSupport) return Real(0);
        return Real(-6) * mCoef * r * sqr(mR2 - r * r);
    }

    Vec3 gradW(const Vec3& xij, Real r) const
    {
        if (r >= mSupport) return Vec3(0);
        return xij * (Real(-6) * mCoef * sqr(mR2 - r * r));
    }

    /// Laplacian: -6 c (R^2 - r^2)(3 R^2 - 7 r^2) with c = 315 / (64 pi R^9).
    Real laplacianW(Real r) const
    {
        if (r >= mSupport) return Real(0);
        const Real r2 = r * r;
        return Real(-6) * mCoef * (mR2 - r2) * (Real(3) * mR2 - Real(7) * r2);
    }

    Real W(const Vec3& xij) const { return W(xij.length()); }
    Vec3 gradW(const Vec3& xij) const { return gradW(xij, xij.length()); }

private:
    Real mSupport, mR2, mCoef;
};

/// Mueller et al. 2003 spiky: W = 15 / (pi R^6) (R - r)^3. Its gradient does not vanish at the
/// centre, so close particles still repel: used for the pressure force.
class SpikyKernel
{
public:
    explicit SpikyKernel(Real supportRadius)
        : mSupport(detail::checkedSupport(supportRadius, "spiky kernel"))
        , mCoef(Real(15) / (PI * std::pow(supportRadius, Real(6))))
    {}

    Real supportRadius() const { return mSupport; }

    Real W(Real r) const { return r >= mSupport ? Real(0) : mCoef * cube(mSupport - r); }

    Real dWdr(Real r) const
    {
        return r >= mSupport ? Real(0) : Real(-3) * mCoef * sqr(mSupport - r);
    }

    Vec3 gradW(const Vec3& xij, Real r) const
    {
        if (r <= Real(0) || r >= mSupport) return Vec3(0);
        return xij * (dWdr(r) / r);
    }

    Real W(const Vec3& xij) const { return W(xij.length()); }
    Vec3 gradW(const Vec3& xij) const { return gradW(xij, xij.length()); }

private:
    Real mSupport, mCoef;
};

/// Mueller et al. 2003 viscosity kernel:
///   W = 15 / (2 pi R^3) (-r^3 / (2 R^3) + r^2 / R^2 + R / (2 r) - 1),
/// whose Laplacian 45 / (pi R^6) (R - r) is positive everywhere, so the viscous force only ever
/// damps relative velocity. W itself is singular (integrably) at r = 0.
class ViscosityKernel
{
public:
    explicit ViscosityKernel(Real supportRadius)
        : mSupport(detail::checkedSupport(supportRadius, "viscosity kernel"))
        , mCoefW(Real(15) / (Real(2) * PI * cube(supportRadius)))
        , mCoefLap(Real(45) / (PI * std::pow(supportRadius, Real(6))))
    {}

    Real supportRadius() const { return mSupport; }

    Real W(Real r) const
    {
        if (r >= mSupport) return Real(0);
        const Real R = mSupport;
        return mCoefW
               * (-cube(r) / (Real(2) * cube(R)) + r * r / (R * R) + R / (Real(2) * r) - Real(1));
    }

    Real dWdr(Real r) const
    {
        if (r >= mSupport) return Real(0);
        const Real R = mSupport;
        return mCoefW
               * (Real(-1.5) * r * r / cube(R) + Real(2) * r / (R * R) - R / (Real(2) * r * r));
    }

    Vec3 gradW(const Vec3& xij, Real r) const
    {
        if (r <= Real(0) || r >= mSupport) return Vec3(0);
        return xij * (dWdr(r) / r);
    }

    Real laplacianW(Real r) const { return r >= mSupport ? Real(0) : mCoefLap * (mSupport - r); }

    Real W(const Vec3& xij) const { return W(xij.length()); }
    Vec3 gradW(const Vec3& xij) const { return gradW(xij, xij.length()); }

private:
    Real mSupport, mCoefW, mCoefLap;
};

// Kernels with the support radius R as an argument --------------------------------------------
// Mueller et al. 2003, as the classes above. With variable smoothing lengths ([RYY15]) every
// pair has its own R = (h_i + h_j) / 2, so a kernel object would be rebuilt per pair.

/// poly6: 315 / (64 pi R^9) (R^2 - r^2)^3 (1/m^3); Poly6Kernel(R).W(r).
inline Real poly6W(Real r, Real R)
{
    if (r >= R) return Real(0);
    const Real invR = Real(1) / R;
    const Real invR3 = invR * invR * invR;
    return Real(315.0 / (64.0 * 3.14159265358979323846)) * cube(R * R - r * r) * invR3 * invR3
           * invR3;
}

/// |dW/dr| of the spiky kernel 15 / (pi R^6) (R - r)^3: 45 / (pi R^6) (R - r)^2 (1/m^4);
/// -SpikyKernel(R).dWdr(r).
inline Real spikySlope(Real r, Real R)
{
    if (r >= R) return Real(0);
    const Real invR2 = Real(1) / (R * R);
    return Real(45.0 / 3.14159265358979323846) * sqr(R - r) * invR2 * invR2 * invR2;
}

/// Spiky gradient with respect to x_i, xij = x_i - x_j, r = |xij|; SpikyKernel(R).gradW(xij, r).
inline Vec3 spikyGrad(const Vec3& xij, Real r, Real R)
{
    if (r <= Real(0) || r >= R) return Vec3(0);
    return xij * (-spikySlope(r, R) / r);
}

/// Laplacian of the viscosity kernel: 45 / (pi R^6) (R - r) (1/m^5);
/// ViscosityKernel(R).laplacianW(r).
inline Real viscosityLaplacian(Real r, Real R)
{
    if (r >= R) return Real(0);
    const Real invR2 = Real(1) / (R * R);
    return Real(45.0 / 3.14159265358979323846) * (R - r) * invR2 * invR2 * invR2;
}

/// The poly6 and cubic-spline kernels with support 1, in double precision, for integrals over
/// kernel overlaps (particle splitting): poly6W(q, 1) and CubicSplineKernel(1).W(q).
inline double unitPoly6(double q)
{
    if (q >= 1.0 || q < 0.0) return 0.0;
    const double t = 1.0 - q * q;
    return 315.0 / (64.0 * 3.14159265358979323846) * t * t * t;
}

inline double unitCubicSpline(double q)
{
    if (q >= 1.0 || q < 0.0) return 0.0;
    // M4 spline with support 1: smoothing length s = 1/2, sigma = 1 / (pi s^3) = 8 / pi, u = 2 q.
    const double u = 2.0 * q;
    const double sigma = 8.0 / 3.14159265358979323846;
    if (u < 1.0) return sigma * (1.0 - 1.5 * u * u + 0.75 * u * u * u);
    const double t = 2.0 - u;
    return sigma * 0.25 * t * t * t;
}

} // namespace sph
} // namespace ghostfx
