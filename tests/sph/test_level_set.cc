/// @file   test_level_set.cc
/// @brief  LevelSet queries against analytic signed distances (sphere, box, torus), world
///         transforms, surface cells, projection, and rejection of unusable grids.
/// @details Error model. The grids hold the exact signed distance phi at voxel centres (rounded
///          to float), and LevelSet::phi interpolates them trilinearly. For a C^2 function the
///          trilinear interpolation error is at most
///              E = h^2 / 8 * (max |phi_xx| + max |phi_yy| + max |phi_zz|)
///          over the interpolation cell (the 1-D bound h^2/8 |f''| once per axis). The Hessian of
///          a distance function has eigenvalues 0 along the normal and kappa_1, kappa_2 (the
///          principal curvatures of the level set through the point) across it, and
///          sum_a |H_aa| <= |kappa_1| + |kappa_2|. So E = h^2/8 (|kappa_1| + |kappa_2|), with
///          the curvatures taken at the worst point of the cell: 2/rho for a sphere at distance
///          rho from its centre, 1/d + 1/(R - d) for a torus at distance d from its core circle,
///          and 0 on the flat part of a box face. Float storage of the values and OpenVDB's
///          float arithmetic in index space add about 1e-6 voxel; the tolerances add 1e-4 voxel
///          for it. Query points are kept within 2 voxels of the surface and the grids are built
///          with a half width of 5 voxels, so every sample a query touches (up to 1 voxel away
///          for the gradient stencil, plus sqrt(3) voxels to the interpolation cell's corners)
///          lies inside the band where values are exact.
#include <ghostfx/sph/Exceptions.h>
#include <ghostfx/sph/LevelSetGrid.h>
#include <ghostfx/sph/Parallel.h>
#include <ghostfx/sph/RigidMotion.h>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <openvdb/math/Transform.h>
#include <openvdb/tools/Interpolation.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <functional>
#include <limits>
#include <random>
#include <set>
#include <string>
#include <vector>

namespace {

using namespace ghostfx::sph;
using ::testing::HasSubstr;

constexpr double HALF_WIDTH = 5.0;     ///< band half width of the test grids (voxels)
constexpr double SAMPLE_BAND = 2.0;    ///< query points lie within this many voxels of the surface
constexpr double STORAGE_ERROR = 1e-4; ///< float storage and index-space rounding (voxels)
/// Farthest a sample touched by phi or gradient can be from a query point (voxels): one step of
/// the gradient stencil plus the diagonal of an interpolation cell.
const double STENCIL_REACH = 1.0 + std::sqrt(3.0);

Vec3d toVec3d(const Vec3& x) { return Vec3d(double(x[0]), double(x[1]), double(x[2])); }

double angleDegrees(const Vec3d& a, const Vec3d& b)
{
    const double c = a.dot(b) / (a.length() * b.length());
    return std::acos(std::clamp(c, -1.0, 1.0)) * 180.0 / M_PI;
}

Vec3d randomDirection(std::mt19937& rng)
{
    std::normal_distribution<double> n(0.0, 1.0);
    for (;;) {
        const Vec3d d(n(rng), n(rng), n(rng));
        if (d.length() > 1e-3) return d / d.length();
    }
}

// Sphere --------------------------------------------------------------------------------------

struct Sphere
{
    Vec3d center;
    double radius;
    double sdf(const Vec3d& x) const { return (x - center).length() - radius; }
    Vec3d normal(const Vec3d& x) const { return (x - center) / (x - center).length(); }
    Vec3d closestPoint(const Vec3d& x) const { return center + radius * normal(x); }
};

/// Random world points within `band` voxels of the sphere surface, rounded to Real.
std::vector<Vec3> pointsNearSphere(const Sphere& s, double voxel, double band, int count,
                                   unsigned seed)
{
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> offset(-band * voxel, band * voxel);
    std::vector<Vec3> xs;
    for (int k = 0; k < count; ++k) {
        xs.push_back(toVec3(s.center + (s.radius + offset(rng)) * randomDirection(rng)));
    }
    return xs;
}

/// phi, gradient, normal and inBand of `ls` agree with the analytic sphere within the bounds of
/// the file's error model.
void expectMatchesSphere(const LevelSet& ls, const Sphere& s)
{
    const double h = ls.voxelSize();
    // Smallest distance from the centre of any sample touched by a query.
    const double rho = s.radius - (SAMPLE_BAND + STENCIL_REACH) * h;
    ASSERT_GT(rho, 0.5 * s.radius) << "sphere too small for its voxels";
    const double phiBound = h * h / 8.0 * (2.0 / rho) + STORAGE_ERROR * h;
    // Gradient by central differences exactly one voxel apart. The interpolation error at a
    // point is -(h^2/2) sum_a t_a (1 - t_a) phi_aa with t the position inside the cell, and x + h
    // and x - h sit at the same t, so to leading order the errors cancel up to the change of
    // phi_aa over 2 h, divided by 2 h: (h^2/8) |grad(trace H)| = h^2 / (4 rho^2) for a sphere
    // (trace H = 2 / rho). Add the truncation error of the central difference,
    // h^2/6 |phi'''| <= h^2 / (2 rho^2) (|phi'''| <= 3 / rho^2), and the storage error over 2 h:
    // each component is within 0.75 h^2 / rho^2 + 1e-4 of the unit normal, so |g - n| is within
    // sqrt(3) x that, which bounds the length error of g and, through asin, its angle (0.19
    // degrees at h / rho = 1/20; measured: 0.03 degrees).
    const double componentError = 0.75 * h * h / (rho * rho) + STORAGE_ERROR;
    const double gradientError = std::sqrt(3.0) * componentError;
    const double angleBound = std::asin(gradientError) * 180.0 / M_PI;

    double worstPhi = 0.0, worstAngle = 0.0, worstLength = 0.0;
    for (const Vec3& x : pointsNearSphere(s, h, SAMPLE_BAND, 2000, 21)) {
        const Vec3d xd = toVec3d(x);
        worstPhi = std::max(worstPhi, std::abs(double(ls.phi(x)) - s.sdf(xd)));
        const Vec3d g = toVec3d(ls.gradient(x));
        worstLength = std::max(worstLength, std::abs(g.length() - 1.0));
        worstAngle = std::max(worstAngle, angleDegrees(g, s.normal(xd)));
        worstAngle = std::max(worstAngle, angleDegrees(toVec3d(ls.normal(x)), s.normal(xd)));
        EXPECT_NEAR(ls.normal(x).length(), 1.0, 1e-5);
        EXPECT_TRUE(ls.inBand(x)); // 2 voxels from the surface, band 5
    }
    EXPECT_LT(worstPhi, phiBound) << "voxel " << h;
    EXPECT_LT(worstLength, gradientError) << "voxel " << h;
    EXPECT_LT(worstAngle, angleBound) << "voxel " << h;
}

/// inside() matches the analytic sign everywhere, in the band and far beyond it, wherever the
/// point is farther from the surface than the interpolation error.
void expectInsideMatchesSphere(const LevelSet& ls, const Sphere& s)
{
    const double h = ls.voxelSize();
    std::mt19937 rng(22);
    std::uniform_real_distribution<double> u(-3.0 * s.radius, 3.0 * s.radius);
    int in = 0, out = 0;
    for (int k = 0; k < 3000; ++k) {
        const Vec3 x = toVec3(s.center + Vec3d(u(rng), u(rng), u(rng)));
        const double d = s.sdf(toVec3d(x));
        if (std::abs(d) < 0.1 * h) continue; // closer than the error bound: either answer
        EXPECT_EQ(ls.inside(x), d < 0) << "x = " << x << ", distance " << d;
        (d < 0 ? in : out)++;
    }
    EXPECT_GT(in, 50);
    EXPECT_GT(out, 50);
    EXPECT_TRUE(ls.inside(toVec3(s.center))); // deep inside
    EXPECT_TRUE(ls.inside(toVec3(s.center + Vec3d(0, 0.5 * s.radius, 0))));
    EXPECT_FALSE(ls.inside(toVec3(s.center + Vec3d(0, 0, 10.0 * s.radius)))); // far outside
    EXPECT_FALSE(ls.inside(toVec3(s.center + Vec3d(1e4 * s.radius, 0, 0))));  // beyond the grid
    EXPECT_FALSE(ls.inBand(toVec3(s.center)));
}

LevelSet sphereLevelSet(const Sphere& s, double voxel, double halfWidth = HALF_WIDTH)
{
    return makeLevelSet(
        makeSphereLevelSet(toVec3(s.center), Real(s.radius), Real(voxel), Real(halfWidth)),
        "sphere");
}

TEST(LevelSet, SpherePhiAndGradientMatchAnalyticDistance)
{
    const Sphere s{Vec3d(0.13, -0.27, 0.41), 0.5}; // centre not on a voxel corner
    const LevelSet ls = sphereLevelSet(s, 0.02);
    EXPECT_EQ(ls.name(), "sphere");
    EXPECT_NEAR(ls.voxelSize(), 0.02, 1e-7);
    EXPECT_NEAR(ls.bandWidth(), 0.02 * HALF_WIDTH, 1e-7);
    expectMatchesSphere(ls, s);
    expectInsideMatchesSphere(ls, s);
}

TEST(LevelSet, UnitVoxelsAndOtherVoxelSizesGiveTheSameWorldAnswers)
{
    // The same sphere in world units, sampled with voxels of 1 m (index space = world space)
    // and 0.37 m: each matches the analytic distance within its own voxel's bound.
    expectMatchesSphere(sphereLevelSet({Vec3d(3.3, -2.1, 0.7), 25.0}, 1.0),
                        {Vec3d(3.3, -2.1, 0.7), 25.0});
    expectMatchesSphere(sphereLevelSet({Vec3d(3.3, -2.1, 0.7), 9.25}, 0.37),
                        {Vec3d(3.3, -2.1, 0.7), 9.25});
}

TEST(LevelSet, TranslatedTransformGivesTranslatedAnswers)
{
    const Sphere s{Vec3d(0), 0.5};
    const double h = 0.02;
    openvdb::FloatGrid::Ptr grid =
        makeSphereLevelSet(Vec3(0), Real(s.radius), Real(h), Real(HALF_WIDTH));
    const Vec3d t(0.1234, -5.3, 2.71); // not a whole number of voxels
    openvdb::FloatGrid::Ptr moved = grid->deepCopy();
    openvdb::math::Transform::Ptr xform = grid->transform().copy();
    xform->postTranslate(t);
    moved->setTransform(xform);
    const LevelSet base = makeLevelSet(grid, "base");
    const LevelSet shifted = makeLevelSet(moved, "moved");

    // Against the analytic sphere at the new centre.
    expectMatchesSphere(shifted, Sphere{t, s.radius});
    expectInsideMatchesSphere(shifted, Sphere{t, s.radius});

    // Against the untranslated grid at the untranslated point: the only difference is the
    // rounding of x + t to Real (eps (|x| + |t|) per component), which phi passes on with
    // Lipschitz constant 1 (sqrt(3) over three components), doubled for margin; plus the
    // float rounding of the interpolated value.
    const double eps = std::numeric_limits<Real>::epsilon();
    for (const Vec3& x : pointsNearSphere(s, h, SAMPLE_BAND, 500, 23)) {
        const Vec3 xt = x + toVec3(t);
        const double tol =
            2.0 * std::sqrt(3.0) * eps * (toVec3d(x).length() + t.length()) + STORAGE_ERROR * h;
        EXPECT_NEAR(double(shifted.phi(xt)), double(base.phi(x)), tol);
        EXPECT_LT(angleDegrees(toVec3d(shifted.normal(xt)), toVec3d(base.normal(x))), 0.1);
        EXPECT_EQ(shifted.inside(xt), base.inside(x));
    }
    // Bounds move with the transform.
    const Aabb b0 = base.bounds(), b1 = shifted.bounds();
    for (int a = 0; a < 3; ++a) {
        EXPECT_NEAR(double(b1.min[a]), double(b0.min[a]) + t[a], 1e-5 * (1.0 + t.length()));
        EXPECT_NEAR(double(b1.max[a]), double(b0.max[a]) + t[a], 1e-5 * (1.0 + t.length()));
    }
    // Index space is shared: the world point of index (0, 0, 0) is t.
    const Vec3 origin = shifted.indexToWorld(Vec3(0));
    for (int a = 0; a < 3; ++a) EXPECT_NEAR(double(origin[a]), t[a], 1e-6 * (1.0 + t.length()));
    const Vec3 back = shifted.worldToIndex(shifted.indexToWorld(Vec3(3, -4, 5)));
    for (int a = 0; a < 3; ++a) EXPECT_NEAR(double(back[a]), double(Vec3(3, -4, 5)[a]), 1e-3);
}

TEST(LevelSet, BoundsEncloseTheShape)
{
    const Sphere s{Vec3d(0.13, -0.27, 0.41), 0.5};
    const double h = 0.02;
    const LevelSet ls = sphereLevelSet(s, h);
    const Aabb b = ls.bounds();
    // The active voxels reach half_width voxels beyond the surface, and the bounds add half a
    // voxel around the voxel centres: c +/- (r + 5 h + h/2), up to one voxel of rounding.
    for (int a = 0; a < 3; ++a) {
        EXPECT_LE(double(b.min[a]), s.center[a] - s.radius);
        EXPECT_GE(double(b.max[a]), s.center[a] + s.radius);
        EXPECT_GE(double(b.min[a]), s.center[a] - s.radius - (HALF_WIDTH + 1.5) * h);
        EXPECT_LE(double(b.max[a]), s.center[a] + s.radius + (HALF_WIDTH + 1.5) * h);
    }
    for (const Vec3& x : pointsNearSphere(s, h, 0.0, 200, 24)) EXPECT_TRUE(b.contains(x));
}

TEST(LevelSet, ProjectToSurfaceConvergesOntoTheAnalyticClosestPoint)
{
    const Sphere s{Vec3d(0.13, -0.27, 0.41), 0.5};
    const double h = 0.01;
    const LevelSet ls = sphereLevelSet(s, h);
    // Start points within 1 voxel of the surface. A step moves the point by |phi| along the
    // estimated normal; whatever first-difference estimate of the gradient is used (central
    // differences one voxel apart, or the derivative of the trilinear interpolant), it is an
    // average of first differences of phi within sqrt(3) voxels of the point, so each component
    // is off by at most sqrt(3) h |H| = sqrt(3) h / rho and the direction by
    // delta <= 3 h / rho. The tangential drift over all steps is at most |phi_0| delta (the
    // steps shrink), the final |phi| is below the tolerance (1e-3 voxel by default) plus the
    // interpolation error E. Hence |p - closest(x)| <= 1e-3 h + E + 1 h x 3 h / rho: with
    // h / r = 1/50 that is about 0.07 voxel.
    const double rho = s.radius - (1.0 + std::sqrt(3.0)) * h;
    const double E = h * h / 8.0 * (2.0 / rho) + STORAGE_ERROR * h;
    const double bound = 1e-3 * h + E + 1.0 * h * (3.0 * h / rho);
    double worst = 0.0;
    int maxIterations = 0;
    for (const Vec3& x : pointsNearSphere(s, h, 1.0, 1000, 25)) {
        const SurfaceProjection p = ls.projectToSurface(x);
        ASSERT_TRUE(p.converged) << "from " << x << ": residual " << p.residual << " after "
                                 << p.iterations << " iterations";
        EXPECT_LE(double(p.residual), 1e-3 * h * (1.0 + 1e-6));
        EXPECT_NEAR(double(p.residual), std::abs(double(ls.phi(p.point))), 1e-6 * h);
        worst = std::max(worst, (toVec3d(p.point) - s.closestPoint(toVec3d(x))).length());
        maxIterations = std::max(maxIterations, p.iterations);
    }
    EXPECT_LT(worst, bound) << "worst " << worst / h << " voxel, bound " << bound / h;
    EXPECT_LE(maxIterations, 20);

    // Given phiAndGradient at the start, the projection takes the same steps.
    for (const Vec3& x : pointsNearSphere(s, h, 1.0, 200, 26)) {
        Vec3 g;
        const Real phi = ls.phiAndGradient(x, g);
        const SurfaceProjection a = ls.projectToSurface(x), b = ls.projectToSurface(x, phi, g);
        EXPECT_EQ(a.point, b.point);
        EXPECT_EQ(a.iterations, b.iterations);
        EXPECT_EQ(a.converged, b.converged);
        EXPECT_EQ(a.residual, b.residual);
    }

    // A looser tolerance stops earlier, and a point already on the surface takes no step.
    const Vec3 onSurface = toVec3(s.center + Vec3d(s.radius, 0, 0));
    const SurfaceProjection p0 = ls.projectToSurface(onSurface, Real(0.05 * h));
    EXPECT_TRUE(p0.converged);
    EXPECT_EQ(p0.iterations, 0);
    EXPECT_EQ(p0.point, onSurface);
}

TEST(LevelSet, LookupsReadTheSameValuesAsOpenVdbsSampler)
{
    // phi() reads the stencil from the leaves' buffers through a table of leaves; it must give
    // BoxSampler's value through a tree accessor everywhere: in one leaf, across leaf faces,
    // edges and corners, in the interior's tiles and outside the grid.
    const Sphere s{Vec3d(0.13, -0.27, 0.41), 0.5};
    const double h = 0.02;
    const LevelSet ls = sphereLevelSet(s, h);
    const openvdb::FloatGrid::ConstPtr grid = gridOf(ls);
    const openvdb::FloatGrid::ConstAccessor acc = grid->getConstAccessor();
    std::mt19937 rng(31);
    std::uniform_real_distribution<double> coordinate(-1.0, 1.0);
    int acrossLeaves = 0;
    for (int k = 0; k < 20000; ++k) {
        const Vec3d x =
            s.center + 1.2 * s.radius * Vec3d(coordinate(rng), coordinate(rng), coordinate(rng));
        const Vec3 xr = toVec3(x);
        const openvdb::Vec3d ijk = grid->transform().worldToIndex(toVec3d(xr));
        const float expected = openvdb::tools::BoxSampler::sample(acc, ijk);
        // Reading a wrong voxel puts an error of its weight times about a voxel; the two
        // interpolations, compiled in different units, round differently in the last bits
        // (measured up to 1.3e-6 voxel).
        ASSERT_NEAR(double(ls.phi(xr)), double(expected), 1e-5 * h) << "at " << x;
        const openvdb::Coord c = openvdb::Coord::floor(ijk);
        acrossLeaves += ((c.x() & 7) == 7) || ((c.y() & 7) == 7) || ((c.z() & 7) == 7);
    }
    EXPECT_GT(acrossLeaves, 4000); // about 1 - (7/8)^3 = 33 % of the stencils
    EXPECT_EQ(ls.phi(Vec3(1e5f, 0, 0)), Real(grid->background()));
}

TEST(LevelSet, ProjectToSurfaceFailsQuicklyBeyondTheBand)
{
    const Sphere s{Vec3d(0.13, -0.27, 0.41), 0.5};
    const double h = 0.02;
    const LevelSet ls = sphereLevelSet(s, h);
    // Outside beyond the band (8 voxels, band 5), far outside, deep inside, and beyond the grid.
    for (const Vec3d& x :
         {s.center + Vec3d(0, s.radius + 8 * h, 0), s.center + Vec3d(3.0, -2.0, 1.0), s.center,
          s.center + Vec3d(0, 0, 0.3 * s.radius), Vec3d(1e5, 0, 0)}) {
        const SurfaceProjection p = ls.projectToSurface(toVec3(x), Real(-1), 1000);
        EXPECT_FALSE(p.converged) << "from " << x;
        EXPECT_EQ(p.iterations, 0) << "from " << x << ": walked in a made-up direction";
        EXPECT_EQ(p.point, toVec3(x));
        EXPECT_NEAR(double(p.residual), double(ls.bandWidth()), 1e-6);
    }
}

TEST(LevelSet, SphereSurfaceCellsAreTheCellsTheSurfaceCrosses)
{
    const Sphere s{Vec3d(0.13, -0.27, 0.41), 0.5};
    const double h = 0.02;
    const LevelSet ls = sphereLevelSet(s, h, 3.0);
    const auto cells = ls.surfaceCells();
    EXPECT_TRUE(std::is_sorted(cells.begin(), cells.end()));
    EXPECT_EQ(std::adjacent_find(cells.begin(), cells.end()), cells.end()) << "duplicate cell";

    // A cell whose corner values (exact distances) change sign contains a surface point, so its
    // centre is within half its diagonal, sqrt(3)/2 h, of the surface (plus float rounding of
    // the corner values, < 1e-4 h).
    double worst = 0.0;
    for (const auto& c : cells) {
        const Vec3 centre =
            ls.indexToWorld(Vec3(Real(c[0] + 0.5), Real(c[1] + 0.5), Real(c[2] + 0.5)));
        worst = std::max(worst, std::abs(s.sdf(toVec3d(centre))));
    }
    EXPECT_LE(worst, (std::sqrt(3.0) / 2.0 + STORAGE_ERROR) * h);

    // Completeness: every cell of the bounding box whose corners, by the analytic distance,
    // change sign is listed, and no other. Corners closer to the surface than the float
    // rounding of the stored values (1e-4 voxel) could go either way and are skipped.
    const std::set<std::array<std::int32_t, 3>> listed(cells.begin(), cells.end());
    const Vec3 lo = ls.worldToIndex(toVec3(s.center - Vec3d(s.radius + 2 * h)));
    const Vec3 hi = ls.worldToIndex(toVec3(s.center + Vec3d(s.radius + 2 * h)));
    std::size_t missing = 0, extra = 0, crossed = 0;
    for (int i = int(std::floor(lo[0])); i <= int(std::ceil(hi[0])); ++i) {
        for (int j = int(std::floor(lo[1])); j <= int(std::ceil(hi[1])); ++j) {
            for (int k = int(std::floor(lo[2])); k <= int(std::ceil(hi[2])); ++k) {
                bool anyIn = false, anyOut = false, ambiguous = false;
                for (int c = 0; c < 8; ++c) {
                    const Vec3 corner(Real(i + (c & 1)), Real(j + ((c >> 1) & 1)),
                                      Real(k + ((c >> 2) & 1)));
                    const double d = s.sdf(toVec3d(ls.indexToWorld(corner)));
                    ambiguous = ambiguous || std::abs(d) < STORAGE_ERROR * h;
                    (d < 0 ? anyIn : anyOut) = true;
                }
                if (ambiguous) continue;
                const bool isListed = listed.count({i, j, k}) > 0;
                if (anyIn && anyOut) {
                    ++crossed;
                    if (!isListed) ++missing;
                } else if (isListed) {
                    ++extra;
                }
            }
        }
    }
    EXPECT_EQ(missing, 0u) << "of " << crossed << " cells the surface crosses";
    EXPECT_EQ(extra, 0u);

    // Scale: a plane with unit normal n crosses (|nx| + |ny| + |nz|) cells per h^2 of area, and
    // the mean of |nx| + |ny| + |nz| over a sphere is 3/2, so about 1.5 A / h^2 cells. Allow +/-5%
    // for curvature (corrections of order h / r = 4%) and the discreteness of the count.
    const double expected = 1.5 * 4.0 * M_PI * s.radius * s.radius / (h * h);
    EXPECT_GT(double(cells.size()), 0.95 * expected);
    EXPECT_LT(double(cells.size()), 1.05 * expected);
    EXPECT_GT(double(crossed), 0.95 * expected); // the completeness check saw them all
}

// Box and torus -------------------------------------------------------------------------------

TEST(LevelSet, BoxFacesAreExactAndInsideHoldsBeyondTheBand)
{
    const Vec3d lo(-0.5, -0.3, -0.4), hi(0.6, 0.5, 0.45);
    const double h = 0.025;
    const LevelSet ls =
        makeLevelSet(makeBoxLevelSet(toVec3(lo), toVec3(hi), Real(h), Real(HALF_WIDTH)), "box");
    // Points near the middle of each face, at least band + 2 voxels from every edge: there the
    // distance is linear (no curvature, no crease) across every sample the query touches, so
    // trilinear interpolation and central differences are exact up to float storage.
    std::mt19937 rng(31);
    std::uniform_real_distribution<double> u(0.0, 1.0), off(-SAMPLE_BAND * h, SAMPLE_BAND * h);
    const double margin = (HALF_WIDTH + 2.0) * h;
    double worstPhi = 0.0, worstNormal = 0.0;
    for (int k = 0; k < 1200; ++k) {
        const int axis = k % 3;
        const bool upper = (k / 3) % 2 == 1;
        Vec3d x, n(0);
        for (int a = 0; a < 3; ++a) x[a] = lo[a] + margin + (hi[a] - lo[a] - 2 * margin) * u(rng);
        const double d = off(rng);
        x[axis] = upper ? hi[axis] + d : lo[axis] - d;
        n[axis] = upper ? 1.0 : -1.0;
        const Vec3 xr = toVec3(x);
        const Vec3d xd = toVec3d(xr); // analytic values at the point actually queried
        const double exact = upper ? xd[axis] - hi[axis] : lo[axis] - xd[axis];
        worstPhi = std::max(worstPhi, std::abs(double(ls.phi(xr)) - exact));
        worstNormal = std::max(worstNormal, (toVec3d(ls.normal(xr)) - n).length());
    }
    EXPECT_LT(worstPhi, STORAGE_ERROR * h);
    EXPECT_LT(worstNormal, 1e-4);
    // Inside far beyond the band (the centre is 0.4 m = 16 voxels from the nearest face).
    EXPECT_TRUE(ls.inside(toVec3(0.5 * (lo + hi))));
    EXPECT_TRUE(ls.inside(toVec3(lo + Vec3d(0.2))));
    EXPECT_FALSE(ls.inside(toVec3(hi + Vec3d(0.3))));
    EXPECT_FALSE(ls.inside(Vec3(Real(100), Real(0), Real(0))));
    const Aabb b = ls.bounds();
    for (int a = 0; a < 3; ++a) {
        EXPECT_LE(double(b.min[a]), lo[a]);
        EXPECT_GE(double(b.max[a]), hi[a]);
    }
}

// An emitter's rate is rho0 |v| times the shadow of its shape along v (GhostSolver::
// addEmitter). Analytic shadows: a box along an axis casts its face; along the diagonal of two
// axes, a box a x b x c casts c (a + b) / sqrt(2); a ball of radius R casts pi R^2 in every
// direction. The rays' cells along the outline count in part, by the rays' least phi: exact
// where the outline comes from faces parallel to the rays (the box along an axis: 0.03 %, and
// a misaligned 6 cm box at 3.75 mm cells within 0.2 %, where whole cells were 3 % off), and a
// little short where it comes from edges seen across (the diagonal: a ray just inside crosses
// a wedge shallower than its distance from the outline, -0.8 %). Bounds 0.5 % along the axis,
// 1.5 % on the diagonal and 0.5 % on the ball, at 1 mm cells.
TEST(LevelSet, ShadowAreaIsTheCrossSectionAlongADirection)
{
    const double a = 0.08, b = 0.05, c = 0.03, cell = 1e-3;
    const LevelSet box = makeLevelSet(
        makeBoxLevelSet(Vec3(-0.04f, 0.47f, -0.025f), Vec3(0.04f, 0.5f, 0.025f), Real(2.5e-3)),
        "nozzle");
    const double down = box.shadowArea(Vec3(0, -1, 0), Real(cell));
    const double side = box.shadowArea(Vec3(Real(3), 0, 0), Real(cell));
    const double diagonal = box.shadowArea(Vec3(1, 0, 1), Real(cell));
    const LevelSet ball =
        makeLevelSet(makeSphereLevelSet(Vec3(0), Real(0.05), Real(2.5e-3)), "ball");
    const double round = ball.shadowArea(Vec3(1, 2, 3), Real(cell));
    std::printf("[measured] shadows: box down %.4e (%.4e), side %.4e (%.4e), diagonal %.4e "
                "(%.4e); ball %.4e (%.4e) m^2\n",
                down, a * b, side, b * c, diagonal, c * (a + b) / std::sqrt(2.0), round,
                std::acos(-1.0) * 0.05 * 0.05);
    EXPECT_NEAR(down / (a * b), 1.0, 0.005);
    EXPECT_NEAR(side / (b * c), 1.0, 0.005);
    EXPECT_NEAR(diagonal / (c * (a + b) / std::sqrt(2.0)), 1.0, 0.015);
    EXPECT_NEAR(round / (std::acos(-1.0) * 0.05 * 0.05), 1.0, 0.005);
    EXPECT_THROW(box.shadowArea(Vec3(0), Real(cell)), ghostfx::ValueError);
    EXPECT_THROW(box.shadowArea(Vec3(0, 1, 0), Real(0)), ghostfx::ValueError);
}

TEST(LevelSet, TorusPhiMatchesAnalyticDistance)
{
    const Vec3d c(0.05, 0.1, -0.2);
    const double R = 0.5, r = 0.15, h = 0.0125;
    const LevelSet ls = makeLevelSet(
        makeTorusLevelSet(toVec3(c), Real(R), Real(r), Real(h), Real(HALF_WIDTH)), "torus");
    auto sdf = [&](const Vec3d& x) {
        const Vec3d d = x - c;
        return std::hypot(std::hypot(d.x(), d.z()) - R, d.y()) - r;
    };
    // Curvatures of the level sets: 1/d around the tube (d = distance to the core circle) and
    // at most 1/(R - d) around the axis; worst over the samples touched, d in r +/- reach.
    const double reach = (SAMPLE_BAND + std::sqrt(3.0)) * h;
    const double E = h * h / 8.0 * (1.0 / (r - reach) + 1.0 / (R - r - reach)) + STORAGE_ERROR * h;
    std::mt19937 rng(41);
    std::uniform_real_distribution<double> angle(0.0, 2.0 * M_PI),
        off(-SAMPLE_BAND * h, SAMPLE_BAND * h);
    double worst = 0.0;
    for (int k = 0; k < 2000; ++k) {
        const double theta = angle(rng), psi = angle(rng), rho = r + off(rng);
        const Vec3d ring(std::cos(theta), 0.0, std::sin(theta));
        const Vec3 x =
            toVec3(c + (R + rho * std::cos(psi)) * ring + Vec3d(0.0, rho * std::sin(psi), 0.0));
        worst = std::max(worst, std::abs(double(ls.phi(x)) - sdf(toVec3d(x))));
    }
    EXPECT_LT(worst, E) << "bound " << E / h << " voxel";
    // The hole is outside (R - r = 0.35 m = 28 voxels from the tube: beyond the band), the
    // core circle inside.
    EXPECT_FALSE(ls.inside(toVec3(c)));
    EXPECT_TRUE(ls.inside(toVec3(c + Vec3d(R, 0, 0))));
    EXPECT_TRUE(ls.inside(toVec3(c + Vec3d(0, 0, -R))));
    EXPECT_FALSE(ls.inside(toVec3(c + Vec3d(0, 0.5, 0))));
}

TEST(LevelSet, LevelSetFromSdfRejectsBadArguments)
{
    const auto sdf = [](const openvdb::Vec3d& x) { return x.length() - 1.0; };
    Aabb b;
    b.expand(Vec3(-1));
    b.expand(Vec3(1));
    EXPECT_THROW(levelSetFromSdf(sdf, b, Real(0)), ghostfx::ValueError);
    EXPECT_THROW(levelSetFromSdf(sdf, b, Real(0.1), Real(0.5)), ghostfx::ValueError);
    EXPECT_THROW(levelSetFromSdf(sdf, Aabb(), Real(0.1)), ghostfx::ValueError);
    EXPECT_THROW(makeSphereLevelSet(Vec3(0), Real(-1), Real(0.1)), ghostfx::ValueError);
    EXPECT_THROW(makeBoxLevelSet(Vec3(1), Vec3(0), Real(0.1)), ghostfx::ValueError);
    EXPECT_THROW(makeTorusLevelSet(Vec3(0), Real(0.1), Real(0.2), Real(0.01)), ghostfx::ValueError);
}

TEST(LevelSet, QueriesFromManyThreadsAgreeWithSerialQueries)
{
    const Sphere s{Vec3d(0.13, -0.27, 0.41), 0.5};
    const LevelSet ls = sphereLevelSet(s, 0.02);
    const std::vector<Vec3> xs = pointsNearSphere(s, 0.02, 4.0, 20000, 51);
    std::vector<Real> serial(xs.size()), threaded(xs.size());
    for (std::size_t i = 0; i < xs.size(); ++i) serial[i] = ls.phi(xs[i]);
    ghostfx::parallel::forEach(
        0, xs.size(), [&](std::size_t i) { threaded[i] = ls.phi(xs[i]); }, 64);
    EXPECT_EQ(threaded, serial);
}

// Rejection of unusable grids ------------------------------------------------------------------

openvdb::FloatGrid::Ptr validSphereGrid()
{
    return makeSphereLevelSet(Vec3(0), Real(1), Real(0.1));
}

/// makeLevelSet(grid, name) throws GridError whose message contains every one of `parts`.
void expectGridError(openvdb::FloatGrid::ConstPtr grid, const std::string& name,
                     const std::vector<std::string>& parts)
{
    try {
        makeLevelSet(grid, name);
        ADD_FAILURE() << "grid accepted; expected an error mentioning '" << parts.front() << "'";
    } catch (const ghostfx::GridError& e) {
        for (const auto& part : parts) EXPECT_THAT(e.what(), HasSubstr(part));
    }
}

TEST(LevelSetGrid, RejectsFogVolume)
{
    // The exact text OpenVDB uses for the class.
    ASSERT_EQ(openvdb::GridBase::gridClassToString(openvdb::GRID_FOG_VOLUME), "fog volume");
    auto grid = validSphereGrid();
    grid->setGridClass(openvdb::GRID_FOG_VOLUME);
    expectGridError(grid, "density",
                    {"grid 'density'", "class is 'fog volume', expected 'level set'"});
    grid->setGridClass(openvdb::GRID_UNKNOWN);
    expectGridError(grid, "density", {"class is 'unknown', expected 'level set'"});
}

TEST(LevelSetGrid, RejectsNonUniformVoxels)
{
    auto scaled = validSphereGrid();
    openvdb::math::Transform::Ptr xform = scaled->transform().copy();
    xform->postScale(openvdb::Vec3d(1, 2, 1));
    scaled->setTransform(xform);
    expectGridError(scaled, "collider", {"grid 'collider'", "uniform", "(0.1, 0.2, 0.1)"});

    auto fromMatrix = validSphereGrid();
    openvdb::Mat4d m = openvdb::Mat4d::identity();
    m.setToScale(openvdb::Vec3d(0.1, 0.1, 0.3));
    fromMatrix->setTransform(openvdb::math::Transform::createLinearTransform(m));
    expectGridError(fromMatrix, "collider", {"uniform"});
}

TEST(LevelSetGrid, RejectsNonLinearTransform)
{
    auto grid = validSphereGrid();
    grid->setTransform(openvdb::math::Transform::createFrustumTransform(
        openvdb::BBoxd(openvdb::Vec3d(0), openvdb::Vec3d(100)), 0.5, 10.0, 0.1));
    expectGridError(grid, "frustum", {"grid 'frustum'", "linear"});
}

TEST(LevelSetGrid, RejectsEmptyGridNonPositiveBackgroundNaNAndNull)
{
    auto empty = openvdb::FloatGrid::create(0.3f);
    empty->setGridClass(openvdb::GRID_LEVEL_SET);
    empty->setTransform(openvdb::math::Transform::createLinearTransform(0.1));
    expectGridError(empty, "empty", {"grid 'empty'", "no active voxels"});

    auto negative = openvdb::FloatGrid::create(-0.3f);
    negative->setGridClass(openvdb::GRID_LEVEL_SET);
    negative->tree().setValue(openvdb::Coord(0), 0.1f);
    expectGridError(negative, "negative", {"background is -0.3"});

    auto withNaN = validSphereGrid();
    auto it = withNaN->tree().beginValueOn();
    ASSERT_TRUE(bool(it));
    it.setValue(std::numeric_limits<float>::quiet_NaN());
    expectGridError(withNaN, "broken", {"grid 'broken'", "value nan", "expected finite"});

    auto withInf = validSphereGrid();
    withInf->tree().beginValueOn().setValue(std::numeric_limits<float>::infinity());
    expectGridError(withInf, "broken", {"value inf"});

    expectGridError(nullptr, "", {"null grid"});
}

TEST(LevelSetGrid, AcceptsValidGridAndUsesItsNameByDefault)
{
    auto grid = validSphereGrid();
    grid->setName("collider");
    EXPECT_NO_THROW(validateLevelSetGrid(*grid, "collider"));
    const LevelSet ls = makeLevelSet(grid);
    EXPECT_EQ(ls.name(), "collider");
    EXPECT_EQ(gridOf(ls), grid);            // shared, not copied
    EXPECT_NEAR(ls.bandWidth(), 0.3, 1e-6); // default half width: 3 voxels
    // The default name also appears in errors.
    grid->setGridClass(openvdb::GRID_FOG_VOLUME);
    expectGridError(grid, "", {"grid 'collider'"});
}

} // namespace

TEST(RigidMotion, ConstantVelocityIsExactFarFromTheOrigin)
{
    // A body at 3 m/s: the velocity of a material point must be 3 m/s at any time. A central
    // difference of single-precision placements lost 0.5 % at t = 10 s and 4 % at t = 100 s
    // (issue 15); the rates of the motion are exact to rounding (bound 1e-6 relative).
    const Vec3 v(3, 0, -1);
    const MovingLevelSet body{
        makeLevelSet(makeSphereLevelSet(Vec3(0), Real(0.1), Real(0.02)), "ball"),
        constantVelocity(v)};
    for (double t : {0.0, 10.0, 100.0, 1000.0}) {
        const Vec3 u = body.velocity(Vec3(Real(0.05), 0, 0), t);
        EXPECT_NEAR((u - v).length() / v.length(), 0.0, 1e-6) << "t = " << t;
        // The placement itself: x(t) = v t, to single precision.
        EXPECT_NEAR(double(body.at(t).translation[0]), 3.0 * t, 3.0 * t * 1e-6 + 1e-9);
    }
    // A motion without rates still gets its velocity by the central difference.
    const MovingLevelSet lambda{body.shape, [](double t) {
                                    RigidTransform xf;
                                    xf.translation = Vec3(Real(2 * t), 0, 0);
                                    return xf;
                                }};
    EXPECT_NEAR(double(lambda.velocity(Vec3(0), 1.0)[0]), 2.0, 1e-3);
}

TEST(SolidCollision, ProjectsRestoresOrReportsStuck)
{
    // A 2 m cube (solid) whose level set has a narrow band of 3 voxels of 1 cm.
    const Real voxel = Real(0.01);
    const MovingLevelSet cube{makeLevelSet(makeBoxLevelSet(Vec3(-1), Vec3(1), voxel), "cube"),
                              constantVelocity(Vec3(0))};
    const RigidTransform xf = cube.at(0);
    const Real band = cube.shape.bandWidth();
    // Just inside the top face, moving down: to the face, downward velocity removed.
    Vec3 x(Real(0.2), Real(1) - Real(0.5) * band, Real(0.1)), v(1, -2, 0);
    EXPECT_EQ(collideWithSolid(cube, xf, 0, x + Vec3(0, Real(0.01), 0), x, v),
              Collision::Projected);
    EXPECT_NEAR(double(x[1]), 1.0, 1e-3 * double(voxel));
    EXPECT_EQ(v, Vec3(1, 0, 0));
    // 0.5 m deep (far beyond the band, where phi is clamped), having started above the face:
    // back to the start, at the solid's velocity.
    const Vec3 start(Real(0.2), Real(1.05), Real(0.1));
    x = Vec3(Real(0.2), Real(0.5), Real(0.1));
    v = Vec3(0, -55, 0);
    EXPECT_EQ(collideWithSolid(cube, xf, 0, start, x, v), Collision::Restored);
    EXPECT_EQ(x, start);
    EXPECT_EQ(v, Vec3(0));
    // Deep, and deep before: nothing can be done; the caller stops.
    x = Vec3(0);
    v = Vec3(0, -1, 0);
    EXPECT_EQ(collideWithSolid(cube, xf, 0, Vec3(0, Real(0.1), 0), x, v), Collision::Stuck);
    EXPECT_EQ(x, Vec3(0));
    // Outside: untouched.
    x = Vec3(0, 2, 0);
    EXPECT_EQ(collideWithSolid(cube, xf, 0, x, x, v), Collision::None);
}

TEST(LevelSet, ThinWallsAreFoundWhereAKernelRadiusDoesNotFit)
{
    // A closed tank (inner box 0.4 x 0.2 x 0.1 m) with walls w; boundary layers 0.03 m deep
    // (a kernel radius at 10 mm). Walls of 0.015 m are thin over the whole surface, inner and
    // outer faces alike, except at the outer corners and edges (the inward diagonal stays in
    // the wall); walls of 0.03 m (exactly the depth) and 0.05 m are not thin anywhere.
    const openvdb::Vec3d lo(0, 0, 0), hi(0.4, 0.2, 0.1);
    auto tank = [&](double w) {
        const openvdb::Vec3d d(w);
        return makeLevelSet(levelSetFromSdf(
                                [=](const openvdb::Vec3d& x) {
            return std::max(-boxSignedDistance(x, lo, hi), boxSignedDistance(x, lo - d, hi + d));
                                },
                                Aabb{Vec3(lo - d), Vec3(hi + d)}, Real(0.005)),
                            "tank");
    };
    const double thin = tank(0.015).fractionThinnerThan(Real(0.03));
    const double exact = tank(0.03).fractionThinnerThan(Real(0.03));
    const double thick = tank(0.05).fractionThinnerThan(Real(0.03));
    std::printf("[measured] thin-wall fraction at depth 0.03 m: wall 0.015 m %.3f, 0.03 m %.3f, "
                "0.05 m %.3f\n",
                thin, exact, thick);
    EXPECT_GT(thin, 0.8);
    EXPECT_EQ(exact, 0.0);
    EXPECT_EQ(thick, 0.0);
    // A sphere of radius 0.1 m is deeper than 0.03 m everywhere.
    EXPECT_EQ(makeLevelSet(makeSphereLevelSet(Vec3(0), Real(0.1), Real(0.005)), "ball")
                  .fractionThinnerThan(Real(0.03)),
              0.0);
}

TEST(LevelSet, ThinFractionOfAPartOfAUnionCountsItsNeighbours)
{
    // A 1 cm plate lying on a 10 cm floor, depth 3 cm: alone, its top and bottom faces (most
    // of its surface) are thin; beside the floor, its underside is buried and the point 3 cm
    // under its top lies in the floor, so only its 1 cm high edges could be thin, and they
    // are deep along the plate. A plate held 5 cm above the floor stays thin.
    const Real voxel = Real(0.0025);
    const LevelSet floor = makeLevelSet(
        makeBoxLevelSet(Vec3(-0.3f, -0.1f, -0.3f), Vec3(0.3f, 0.0f, 0.3f), voxel), "floor");
    const LevelSet lying = makeLevelSet(
        makeBoxLevelSet(Vec3(-0.1f, 0.0f, -0.1f), Vec3(0.1f, 0.01f, 0.1f), voxel), "lying");
    const LevelSet held = makeLevelSet(
        makeBoxLevelSet(Vec3(-0.1f, 0.05f, -0.1f), Vec3(0.1f, 0.06f, 0.1f), voxel), "held");
    const double alone = lying.fractionThinnerThan(Real(0.03));
    const double onFloor = lying.fractionThinnerThan(Real(0.03), {&floor});
    const double above = held.fractionThinnerThan(Real(0.03), {&floor});
    std::printf("[measured] thin fraction of a 1 cm plate: alone %.3f, on the floor %.3f, 5 cm "
                "above it %.3f\n",
                alone, onFloor, above);
    EXPECT_GT(alone, 0.9);
    EXPECT_EQ(onFloor, 0.0);
    EXPECT_GT(above, 0.9);
    // The floor itself, 10 cm deep, is not thin beside the plate either.
    EXPECT_EQ(floor.fractionThinnerThan(Real(0.03), {&lying}), 0.0);
}

// erodedLevelSet: a sphere of radius R eroded by d is the sphere of radius R - d. OpenVDB's
// rebuild meshes the isosurface and measures distances to the triangles; near the new surface
// phi differs from |x| - (R - d) by the source grid's trilinear error where the isosurface was
// found (h^2/8 * 2/rho: 0.014 h at 18 voxels), the vertices' linear placement along the edges
// and the chords' sagitta (h / (8 * 18) = 0.007 h each), and the new grid's own trilinear
// error where it is queried (0.014 h): about 0.04 h. Measured 0.060 h; bound 0.1 h. A shape no
// thicker than twice the depth leaves nothing and is a one-line error naming it.
TEST(LevelSet, ErodedSphereIsTheSphereOfTheSmallerRadius)
{
    const Real h = Real(0.005), R = Real(0.1), d = Real(0.01);
    const LevelSet sphere = makeLevelSet(makeSphereLevelSet(Vec3(0), R, h, Real(3)), "ball");
    const LevelSet eroded = erodedLevelSet(sphere, d);
    EXPECT_EQ(eroded.name(), "ball");
    EXPECT_NEAR(double(eroded.voxelSize()), double(h), 1e-9);
    double worst = 0;
    for (int k = 0; k < 200; ++k) {
        const double theta = 0.031 * k, phiAngle = 0.17 * k;
        const Vec3d dir(std::sin(theta) * std::cos(phiAngle), std::cos(theta),
                        std::sin(theta) * std::sin(phiAngle));
        for (const double offset : {-1.5, -0.5, 0.0, 0.5, 1.5}) {
            const double r = double(R - d) + offset * double(h);
            const Vec3 x(dir * r);
            worst = std::max(worst, std::abs(double(eroded.phi(x)) - (r - double(R - d))));
        }
    }
    std::printf("[measured] eroded sphere: largest |phi - (|x| - (R - d))| %.4f voxels\n",
                worst / double(h));
    EXPECT_LT(worst, 0.1 * double(h));
    const LevelSet thin =
        makeLevelSet(makeSphereLevelSet(Vec3(0), Real(0.008), h, Real(3)), "bead");
    try {
        erodedLevelSet(thin, d);
        ADD_FAILURE() << "a bead of 8 mm eroded by 10 mm was taken";
    } catch (const ghostfx::ValueError& e) {
        EXPECT_EQ(std::string(e.what()), "level set 'bead': nothing is left of it 0.01 m inside "
                                         "its surface: expected a shape thicker than 0.02 m");
    }
}
