/// @file   PoissonSampler.cc
/// @brief  [SB12] Algorithms 1 and 2, seeded Bridson sampling, and the grid they search.
#include "ghostfx/sph/PoissonSampler.h"

#include "ghostfx/sph/Exceptions.h"
#include "ghostfx/sph/Parallel.h"
#include "ghostfx/sph/Random.h"
#include "ghostfx/sph/SettingCheck.h"

#include "SamplerGrids.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <memory>
#include <mutex>

#if defined(__SSE2__)
#include <xmmintrin.h>
#endif
#if defined(__GNUC__) && defined(__x86_64__) && !defined(GHOSTFX_DOUBLE)
#include <immintrin.h>
#define GHOSTFX_SAMPLER_AVX2 1
#endif

namespace ghostfx {
namespace sph {

using detail::CellLattice;
using detail::DepthLimit;
using detail::PointGrid;
using detail::samplingBounds;

namespace {

/// Streams of the random generator, one per phase, so phases do not share draws.
enum Stream : std::uint64_t {
    SURFACE = 1,
    INTERIOR = 2,
    SEEDED = 3,
    TILE_OFFSET = 4,
    TILE = 8,
    RELAX = 16
};
/// Side of the periodic interior tile, in Poisson radii: about 1,000 points, small enough to
/// relax in milliseconds, large enough that its period (11 spacings) is far beyond a kernel
/// radius.
constexpr Real TILE_RADII = Real(12);

/// The relaxation's search grid: cells of side `cellSize` stored one after another along x,
/// each with slots for the samples it holds plus `SLACK` more (cells next to a sample only;
/// far regions of the box cost a start index and a count), free slots holding a far-away
/// point. The cells a ball touches are then at most 9 runs of contiguous slots, read without
/// following links (a linked list per cell made every read wait for the one before). A cell
/// whose slots are full takes further samples in a spill list of its own.
///
/// Threads may move samples at once as long as no two touch the same cells, which the
/// relaxation's colouring ensures; the spill lists' table is shared, so it is locked.
class SlotGrid
{
public:
    static constexpr std::uint32_t SLACK = 4;

    /// A grid over `bounds` holding the points inside it; `entry[i]` becomes the entry id of
    /// point i (its index) or -1 when it lies outside.
    SlotGrid(const Aabb& bounds, Real cellSize, const std::vector<Vec3>& points,
             std::vector<int>& entry)
        : mCells(bounds, cellSize)
    {
        const std::size_t total = mCells.count;
        // Count the points per cell; cells next to a point get slack (a move stays within
        // one cell of where it starts).
        mCount.assign(total, 0);
        std::vector<std::uint8_t> active(total, 0);
        entry.assign(points.size(), -1);
        mCellOf.assign(points.size(), 0);
        mSlotOf.assign(points.size(), SPILLED);
        for (std::size_t i = 0; i < points.size(); ++i) {
            if (!contains(points[i])) continue;
            entry[i] = int(i);
            std::int64_t c[3];
            const std::int64_t cell = mCells.cellOf(points[i], c);
            mCellOf[i] = cell;
            ++mCount[cell];
            mCells.forNeighbourhood(c, [&active](std::size_t n) { active[n] = 1; });
        }
        mStart.resize(total + 1);
        std::size_t slots = 0;
        for (std::size_t c = 0; c < total; ++c) {
            mStart[c] = slots;
            slots += mCount[c] + (active[c] ? SLACK : 0);
        }
        mStart[total] = slots;
        // Four free slots after the last, for reads four at a time.
        mX.assign(slots + 4, FAR);
        mY.assign(slots + 4, FAR);
        mZ.assign(slots + 4, FAR);
        mId.assign(slots + 4, -1);
        std::fill(mCount.begin(), mCount.end(), 0);
        for (std::size_t i = 0; i < points.size(); ++i) {
            if (entry[i] >= 0) put(int(i), mCellOf[i], points[i]);
        }
        mSpilled.assign(total, 0);
    }

    bool contains(const Vec3& x) const { return mCells.contains(x); }

    /// Move entry `id` to x (inside the grid).
    void move(int id, const Vec3& x)
    {
        const std::int64_t cell = mCells.cellOf(x);
        if (cell == mCellOf[id] && mSlotOf[id] != SPILLED) {
            const std::size_t s = mSlotOf[id];
            mX[s] = x[0];
            mY[s] = x[1];
            mZ[s] = x[2];
            return;
        }
        take(id);
        put(id, cell, x);
    }

    /// Write the entries other than `ignore` closer than `radius` (<= the cell size) to p
    /// into x, y, z (grown as needed; room for 8 more is left after them); returns how many.
    std::size_t collect(const Vec3& p, Real radius, int ignore, std::vector<Real>& x,
                        std::vector<Real>& y, std::vector<Real>& z) const
    {
        const Real r2 = radius * radius;
        std::int64_t lo[3], hi[3];
        mCells.range(p, radius, lo, hi);
        const std::size_t room = roomFor(lo, hi);
        if (x.size() < room) {
            x.resize(2 * room);
            y.resize(2 * room);
            z.resize(2 * room);
        }
        std::size_t n = 0;
        for (std::int64_t k = lo[2]; k <= hi[2]; ++k) {
            for (std::int64_t j = lo[1]; j <= hi[1]; ++j) {
                const std::int64_t row = mCells.row(j, k);
                const std::size_t begin = mStart[std::size_t(row + lo[0])];
                const std::size_t end = mStart[std::size_t(row + hi[0] + 1)];
                n = collectSlots(begin, end, p, r2, ignore, x, y, z, n);
                for (std::int64_t i = lo[0]; i <= hi[0]; ++i) {
                    if (mSpilled[std::size_t(row + i)]) {
                        n = collectSpilled(row + i, p, r2, ignore, x, y, z, n);
                    }
                }
            }
        }
        return n;
    }

private:
    static constexpr std::uint32_t SPILLED = std::numeric_limits<std::uint32_t>::max();
    /// Coordinate of a free slot: far enough that it is never within reach, small enough
    /// that its square stays finite in float.
    static constexpr Real FAR = Real(1e18);

    struct Slot
    {
        Real x, y, z;
        int id;
    };

    /// Room for every slot collect() reads in the cells [lo, hi] (each could be a member)
    /// and the padding after them.
    std::size_t roomFor(const std::int64_t lo[3], const std::int64_t hi[3]) const
    {
        std::size_t room = 8;
        for (std::int64_t k = lo[2]; k <= hi[2]; ++k) {
            for (std::int64_t j = lo[1]; j <= hi[1]; ++j) {
                const std::int64_t row = mCells.row(j, k);
                room += mStart[std::size_t(row + hi[0] + 1)] - mStart[std::size_t(row + lo[0])];
                for (std::int64_t i = lo[0]; i <= hi[0]; ++i) {
                    if (mSpilled[std::size_t(row + i)]) room += spill(row + i).size();
                }
            }
        }
        return room;
    }

    /// collect() over the slots [s, end): appends the members from index n on, returns the
    /// new count.
    std::size_t collectSlots(std::size_t s, std::size_t end, const Vec3& p, Real r2, int ignore,
                             std::vector<Real>& x, std::vector<Real>& y, std::vector<Real>& z,
                             std::size_t n) const
    {
#if defined(__SSE2__) && !defined(GHOSTFX_DOUBLE)
        // Four slots at a time; the slot arrays end with four free slots, and lanes past the
        // run are masked off.
        const __m128 px = _mm_set1_ps(p[0]), py = _mm_set1_ps(p[1]), pz = _mm_set1_ps(p[2]),
                     limit = _mm_set1_ps(r2);
        const __m128i self = _mm_set1_epi32(ignore);
        for (; s < end; s += 4) {
            const __m128 qx = _mm_loadu_ps(mX.data() + s);
            const __m128 qy = _mm_loadu_ps(mY.data() + s);
            const __m128 qz = _mm_loadu_ps(mZ.data() + s);
            const __m128 dx = _mm_sub_ps(qx, px), dy = _mm_sub_ps(qy, py), dz = _mm_sub_ps(qz, pz);
            const __m128 d2 =
                _mm_add_ps(_mm_add_ps(_mm_mul_ps(dx, dx), _mm_mul_ps(dy, dy)), _mm_mul_ps(dz, dz));
            const __m128i ids = _mm_loadu_si128(reinterpret_cast<const __m128i*>(mId.data() + s));
            const __m128 notSelf = _mm_castsi128_ps(_mm_cmpeq_epi32(ids, self));
            int mask = _mm_movemask_ps(_mm_andnot_ps(notSelf, _mm_cmplt_ps(d2, limit)));
            if (end - s < 4) mask &= (1 << (end - s)) - 1;
            while (mask != 0) {
                const int lane = __builtin_ctz(unsigned(mask));
                x[n] = mX[s + std::size_t(lane)];
                y[n] = mY[s + std::size_t(lane)];
                z[n] = mZ[s + std::size_t(lane)];
                ++n;
                mask &= mask - 1;
            }
        }
#else
        for (; s < end; ++s) {
            const Real dx = mX[s] - p[0], dy = mY[s] - p[1], dz = mZ[s] - p[2];
            x[n] = mX[s];
            y[n] = mY[s];
            z[n] = mZ[s];
            n += std::size_t((dx * dx + dy * dy + dz * dz < r2) & (mId[s] != ignore));
        }
#endif
        return n;
    }

    /// collect() over the spill list of `cell`, as collectSlots.
    std::size_t collectSpilled(std::int64_t cell, const Vec3& p, Real r2, int ignore,
                               std::vector<Real>& x, std::vector<Real>& y, std::vector<Real>& z,
                               std::size_t n) const
    {
        for (const Slot& q : spill(cell)) {
            const Real dx = q.x - p[0], dy = q.y - p[1], dz = q.z - p[2];
            if (dx * dx + dy * dy + dz * dz < r2 && q.id != ignore) {
                x[n] = q.x;
                y[n] = q.y;
                z[n] = q.z;
                ++n;
            }
        }
        return n;
    }

    /// The spill list of `cell` (which has one).
    std::vector<Slot>& spill(std::int64_t cell) const
    {
        std::lock_guard<std::mutex> lock(mSpillMutex);
        return mSpill[cell];
    }

    void put(int id, std::int64_t cell, const Vec3& x)
    {
        mCellOf[std::size_t(id)] = cell;
        const std::size_t c = std::size_t(cell);
        if (mStart[c] + mCount[c] < mStart[c + 1]) {
            const std::size_t s = mStart[c] + mCount[c]++;
            mX[s] = x[0];
            mY[s] = x[1];
            mZ[s] = x[2];
            mId[s] = id;
            mSlotOf[std::size_t(id)] = std::uint32_t(s);
            return;
        }
        mSlotOf[std::size_t(id)] = SPILLED;
        spill(cell).push_back({x[0], x[1], x[2], id});
        mSpilled[c] = 1;
    }

    /// Remove entry `id` from its cell, keeping the cell's slots packed.
    void take(int id)
    {
        const std::size_t c = std::size_t(mCellOf[std::size_t(id)]);
        if (mSlotOf[std::size_t(id)] == SPILLED) {
            std::vector<Slot>& list = spill(std::int64_t(c));
            auto it =
                std::find_if(list.begin(), list.end(), [id](const Slot& q) { return q.id == id; });
            *it = list.back();
            list.pop_back();
            if (list.empty()) mSpilled[c] = 0;
            return;
        }
        const std::size_t s = mSlotOf[std::size_t(id)];
        const std::size_t last = mStart[c] + --mCount[c];
        if (s != last) {
            mX[s] = mX[last];
            mY[s] = mY[last];
            mZ[s] = mZ[last];
            mId[s] = mId[last];
            mSlotOf[std::size_t(mId[s])] = std::uint32_t(s);
        }
        mX[last] = FAR;
        mY[last] = FAR;
        mZ[last] = FAR;
        mId[last] = -1;
    }

    CellLattice mCells;
    std::vector<std::size_t> mStart;    ///< first slot of each cell; mStart[cells] = slot count
    std::vector<std::uint32_t> mCount;  ///< entries in each cell's slots
    std::vector<Real> mX, mY, mZ;       ///< slots' coordinates
    std::vector<int> mId;               ///< slots' entries, -1 when free
    std::vector<std::int64_t> mCellOf;  ///< per entry: its cell
    std::vector<std::uint32_t> mSlotOf; ///< per entry: its slot, or SPILLED
    std::vector<std::uint8_t> mSpilled; ///< per cell: whether its spill list is in use
    mutable std::map<std::int64_t, std::vector<Slot>> mSpill;
    mutable std::mutex mSpillMutex;
};

#if GHOSTFX_SAMPLER_AVX2
/// The least of (x - X[k])^2 + (y - Y[k])^2 + (z - Z[k])^2 over k < n (a multiple of 8), eight
/// at a time, for processors with AVX2 (checked at run time: the build targets any x86-64).
/// The same float operations in the same order as four at a time, so the same result.
__attribute__((target("avx2"))) float minDistance2Avx2(const float* X, const float* Y,
                                                       const float* Z, std::size_t n, float x,
                                                       float y, float z)
{
    const __m256 cx = _mm256_set1_ps(x), cy = _mm256_set1_ps(y), cz = _mm256_set1_ps(z);
    __m256 best = _mm256_set1_ps(std::numeric_limits<float>::max());
    for (std::size_t k = 0; k < n; k += 8) {
        const __m256 dx = _mm256_sub_ps(cx, _mm256_loadu_ps(X + k));
        const __m256 dy = _mm256_sub_ps(cy, _mm256_loadu_ps(Y + k));
        const __m256 dz = _mm256_sub_ps(cz, _mm256_loadu_ps(Z + k));
        const __m256 q2 = _mm256_add_ps(_mm256_add_ps(_mm256_mul_ps(dx, dx), _mm256_mul_ps(dy, dy)),
                                        _mm256_mul_ps(dz, dz));
        best = _mm256_min_ps(best, q2);
    }
    const __m128 half = _mm_min_ps(_mm256_castps256_ps128(best), _mm256_extractf128_ps(best, 1));
    alignas(16) float lanes[4];
    _mm_store_ps(lanes, half);
    return std::min(std::min(lanes[0], lanes[1]), std::min(lanes[2], lanes[3]));
}

const bool HAS_AVX2 = __builtin_cpu_supports("avx2");
#endif

/// B(p) of Algorithm 2, the samples within 2r of p, as coordinate arrays padded to a multiple
/// of eight with far-away points, so the nearest-distance test of every candidate runs four
/// or eight samples at a time. The minimum is exact, so the result does not depend on the
/// lane order.
class Ball
{
public:
    void gather(const SlotGrid& grid, const Vec3& p, Real radius, int ignore)
    {
        std::size_t n = grid.collect(p, radius, ignore, mX, mY, mZ);
        mCount = n;
        mPadded = (n + 7) / 8 * 8;
        for (; n < mPadded; ++n) {
            mX[n] = FAR;
            mY[n] = FAR;
            mZ[n] = FAR;
        }
    }

    bool empty() const { return mCount == 0; }

    /// min over the ball of |x - q|^2.
    Real minDistance2(const Vec3& x) const
    {
        Real best = std::numeric_limits<Real>::max();
        beats(x, Real(-1), best);
        return best;
    }

    /// Whether every member is farther than sqrt(d2) from x; if so, `c2` is the exact
    /// min over the ball of |x - q|^2 (otherwise it is set to d2).
    bool beats(const Vec3& x, Real d2, Real& c2) const
    {
        const std::size_t n = mPadded;
#if GHOSTFX_SAMPLER_AVX2
        if (HAS_AVX2) {
            c2 = minDistance2Avx2(mX.data(), mY.data(), mZ.data(), n, x[0], x[1], x[2]);
            if (c2 > d2) return true;
            c2 = d2;
            return false;
        }
#endif
#if defined(__SSE2__) && !defined(GHOSTFX_DOUBLE)
        const __m128 cx = _mm_set1_ps(x[0]), cy = _mm_set1_ps(x[1]), cz = _mm_set1_ps(x[2]);
        __m128 best = _mm_set1_ps(std::numeric_limits<float>::max());
        for (std::size_t k = 0; k < n; k += 4) {
            const __m128 dx = _mm_sub_ps(cx, _mm_loadu_ps(mX.data() + k));
            const __m128 dy = _mm_sub_ps(cy, _mm_loadu_ps(mY.data() + k));
            const __m128 dz = _mm_sub_ps(cz, _mm_loadu_ps(mZ.data() + k));
            const __m128 q2 =
                _mm_add_ps(_mm_add_ps(_mm_mul_ps(dx, dx), _mm_mul_ps(dy, dy)), _mm_mul_ps(dz, dz));
            best = _mm_min_ps(best, q2);
        }
        alignas(16) float lanes[4];
        _mm_store_ps(lanes, best);
        c2 = std::min(std::min(lanes[0], lanes[1]), std::min(lanes[2], lanes[3]));
#else
        Real best = std::numeric_limits<Real>::max();
        for (std::size_t k = 0; k < n; ++k) {
            const Real dx = x[0] - mX[k], dy = x[1] - mY[k], dz = x[2] - mZ[k];
            best = std::min(best, dx * dx + dy * dy + dz * dz);
        }
        c2 = best;
#endif
        if (c2 > d2) return true;
        c2 = d2;
        return false;
    }

private:
    /// Padding coordinate: far enough that its distance never wins, small enough that its
    /// square stays finite in float.
    static constexpr Real FAR = Real(1e18);

    std::vector<Real> mX, mY, mZ; ///< members in [0, mCount), then padding to mPadded
    std::size_t mCount = 0, mPadded = 0;
};

/// Random unit vector perpendicular to the unit normal n.
Vec3 randomTangent(Rng& rng, const Vec3& n)
{
    for (int attempt = 0; attempt < 8; ++attempt) {
        const Vec3 u = rng.unitVector();
        Vec3 d = u - n * u.dot(n);
        const Real len = d.length();
        if (len > Real(1e-3)) return d / len;
    }
    // n is (numerically) parallel to every draw: fall back to any perpendicular.
    Vec3 d = std::abs(n[0]) < Real(0.9) ? n.cross(Vec3(1, 0, 0)) : n.cross(Vec3(0, 1, 0));
    return d.unitSafe();
}

/// Bridson 2007 growth: pick a random active point, try up to `attempts` candidates at a
/// random direction and a distance uniform in [r, 2r); `tryAccept(q)` returns whether it took
/// q, which then becomes active too. An active point whose tries all fail retires.
template <typename TryAccept>
void growFromActive(std::vector<Vec3>& active, Rng& rng, Real r, int attempts,
                    TryAccept&& tryAccept)
{
    while (!active.empty()) {
        const std::uint32_t slot = rng.below(std::uint32_t(active.size()));
        const Vec3 p = active[slot];
        bool found = false;
        for (int a = 0; a < attempts && !found; ++a) {
            const Vec3 q = p + rng.unitVector() * (r * Real(1.0 + rng.uniform01()));
            if (tryAccept(q)) {
                active.push_back(q);
                found = true;
            }
        }
        if (!found) {
            active[slot] = active.back();
            active.pop_back();
        }
    }
}

/// Side of the tiles that Bridson's growth runs in, in Poisson radii: large enough that
/// few samples sit within 2r of a tile's faces (those a neighbour also grows from), small
/// enough for a few tiles of each colour on a small shape.
constexpr Real GROWTH_TILE_RADII = Real(16);

/// A random stream of one tile in one phase of a tiled phase `stream`.
std::uint64_t tileStream(Stream stream, int phase, std::size_t tile)
{
    return std::uint64_t(stream) << 56 | std::uint64_t(phase) << 32 | std::uint64_t(tile);
}

/// Cubic tiles over a box for sampling phases run in parallel: a tile's work writes inside the
/// tile and reads within one tile of it, so tiles of one colour (the parity of their
/// coordinates: 8 colours, tiles of one colour at least a tile apart) run at once.
class TileLattice
{
public:
    static constexpr int COLOURS = 8;

    TileLattice(const Aabb& bounds, Real side) : mCells(bounds, side), mSide(side) {}

    std::size_t count() const { return mCells.count; }
    /// The tile that holds x (clamped to the lattice).
    std::size_t tileOf(const Vec3& x) const { return std::size_t(mCells.cellOf(x)); }
    int colour(std::size_t tile) const
    {
        std::int64_t c[3];
        coords(tile, c);
        return int((c[0] & 1) | (c[1] & 1) << 1 | (c[2] & 1) << 2);
    }
    Aabb box(std::size_t tile) const
    {
        std::int64_t c[3];
        coords(tile, c);
        Aabb b;
        for (int a = 0; a < 3; ++a) {
            b.min[a] = mCells.origin[a] + Real(c[a]) * mSide;
            b.max[a] = b.min[a] + mSide;
        }
        return b;
    }
    /// fn(n) for the tile and its up to 26 neighbours, in index order.
    template <typename Fn>
    void forNeighbours(std::size_t tile, Fn&& fn) const
    {
        std::int64_t c[3];
        coords(tile, c);
        mCells.forNeighbourhood(c, fn);
    }

private:
    void coords(std::size_t tile, std::int64_t c[3]) const
    {
        const std::int64_t t = std::int64_t(tile);
        c[0] = t % mCells.dims[0];
        c[1] = (t / mCells.dims[0]) % mCells.dims[1];
        c[2] = t / (mCells.dims[0] * mCells.dims[1]);
    }

    CellLattice mCells;
    Real mSide;
};

void checkCount(std::size_t count, const PoissonSettings& s, const char* phase)
{
    if (count > s.maxSamples) {
        throw SamplingError(msg(phase, ": more than maxSamples = ", s.maxSamples,
                                " samples at Poisson radius ", s.radius,
                                " m: the spacing is too small for the shape"));
    }
}

} // namespace

// ---------------------------------------------------------------------------------------------

PoissonSettings PoissonSettings::forSpacing(Real spacing)
{
    if (!(spacing > Real(0)) || !std::isfinite(spacing)) {
        throw ValueError(msg("particle spacing = ", spacing, " m: expected a finite value > 0"));
    }
    PoissonSettings s;
    s.radius = SB12_RADIUS_FACTOR * spacing;
    return s;
}

void PoissonSettings::validate() const
{
    const SettingCheck check("sampler setting");
    check.require(radius > Real(0) && std::isfinite(radius), "radius", radius,
                  "a finite value > 0 (m)");
    check.require(surfaceAttempts >= 1, "surfaceAttempts", surfaceAttempts, ">= 1");
    check.require(surfaceStep > Real(1), "surfaceStep", surfaceStep,
                  "> 1 (steps of e r must clear r)");
    check.require(volumeAttempts >= 1, "volumeAttempts", volumeAttempts, ">= 1");
    check.require(relaxAttempts >= 1, "relaxAttempts", relaxAttempts, ">= 1");
    check.require(surfaceRelaxSweeps >= 0, "surfaceRelaxSweeps", surfaceRelaxSweeps, ">= 0");
    check.require(volumeRelaxSweeps >= 0, "volumeRelaxSweeps", volumeRelaxSweeps, ">= 0");
    check.require(packingIterations >= 0, "packingIterations", packingIterations, ">= 0");
    check.require(volumeRelaxation == Relaxation::Packing || volumeRelaxation == Relaxation::Sb12,
                  "volumeRelaxation", int(volumeRelaxation), "Packing or Sb12");
    check.require(bandDepth > Real(0), "bandDepth", bandDepth, "> 0 (m), or infinity");
    check.require(maxSamples >= 1, "maxSamples", double(maxSamples), ">= 1");
}

std::size_t SampleSet::surfaceCount() const
{
    return std::size_t(std::count(onSurface.begin(), onSurface.end(), std::uint8_t(1)));
}

PoissonDiskSampler::PoissonDiskSampler(const PoissonSettings& settings) : mSettings(settings)
{
    mSettings.validate();
}

SampleSet PoissonDiskSampler::sampleVolume(const LevelSet& shape) const
{
    if (mSettings.tiledInterior) return sampleVolumeTiled(shape);
    SampleSet samples = sampleSurface(shape);
    relax(samples, shape, mSettings.surfaceRelaxSweeps, 0);
    sampleInterior(samples, shape);
    relaxVolume(samples, shape);
    return samples;
}

// [SB12] Algorithm 1 ---------------------------------------------------------------------------

namespace {

/// The tiles of `colour` for which wanted(tile) holds, in index order: a batch that runs in
/// parallel.
template <typename Wanted>
std::vector<std::size_t> tilesOfColour(const TileLattice& tiles, int colour, Wanted&& wanted)
{
    std::vector<std::size_t> batch;
    for (std::size_t k = 0; k < tiles.count(); ++k) {
        if (wanted(k) && tiles.colour(k) == colour) batch.push_back(k);
    }
    return batch;
}

/// Add to `grid` the points held by `tile` and its neighbours that lie in `near`;
/// positionOf(h) is the position of a held entry h.
template <typename Held, typename PositionOf>
void addNeighbours(PointGrid& grid, const TileLattice& tiles, std::size_t tile, const Aabb& near,
                   const std::vector<std::vector<Held>>& held, PositionOf&& positionOf)
{
    tiles.forNeighbours(tile, [&](std::size_t n) {
        for (const Held& h : held[n]) {
            if (near.contains(positionOf(h))) grid.add(positionOf(h));
        }
    });
}

/// [SB12] Algorithm 1, run tile by tile, as the interior growth is (InteriorGrowth): a tile's
/// cells place samples only inside the tile and read only the samples within r of it, so the
/// tiles of one colour run in parallel and the samples do not depend on the thread count.
class SurfaceSampling
{
public:
    /// @param cells  the shape's voxels that hold a zero crossing
    SurfaceSampling(const LevelSet& shape, const PoissonSettings& settings,
                    const std::vector<std::array<std::int32_t, 3>>& cells)
        : mShape(shape)
        , mSettings(settings)
        , mR(settings.radius)
        , mCells(cells)
        , mDomain(samplingBounds(shape, mR), mR)
        , mTiles(samplingBounds(shape, mR), GROWTH_TILE_RADII * mR)
        , mCellsOf(mTiles.count())
        , mHeld(mTiles.count())
    {
        for (std::size_t c = 0; c < cells.size(); ++c) {
            const Vec3 centre = shape.indexToWorld(Vec3(Real(cells[c][0]) + Real(0.5),
                                                        Real(cells[c][1]) + Real(0.5),
                                                        Real(cells[c][2]) + Real(0.5)));
            if (mDomain.contains(centre)) mCellsOf[mTiles.tileOf(centre)].push_back(c);
        }
    }

    /// The surface samples, colour by colour.
    SampleSet run()
    {
        SampleSet samples;
        for (int colour = 0; colour < TileLattice::COLOURS; ++colour) {
            const std::vector<std::size_t> batch = tilesOfColour(
                mTiles, colour, [this](std::size_t k) { return !mCellsOf[k].empty(); });
            std::vector<std::vector<Vec3>> added(batch.size());
            parallel::forEach(
                0, batch.size(), [&](std::size_t b) { sampleTile(batch[b], colour, added[b]); }, 1);
            for (std::size_t b = 0; b < batch.size(); ++b) {
                mHeld[batch[b]] = added[b];
                samples.positions.insert(samples.positions.end(), added[b].begin(), added[b].end());
            }
            checkCount(samples.size(), mSettings, "surface sampling");
        }
        samples.onSurface.assign(samples.size(), 1);
        return samples;
    }

private:
    /// What one tile's sampling works on.
    struct Tile
    {
        std::size_t index;
        PointGrid grid; ///< the samples within r of the tile
        Rng rng;
        std::vector<Vec3>& added; ///< the samples the tile placed
    };

    /// Sample the cells of one tile into `added`.
    void sampleTile(std::size_t tile, int colour, std::vector<Vec3>& added) const
    {
        const Aabb near = mTiles.box(tile).padded(Real(1.01) * mR);
        Tile work{tile, PointGrid(near, mR), Rng(mSettings.seed, tileStream(SURFACE, colour, tile)),
                  added};
        addNeighbours(work.grid, mTiles, tile, near, mHeld, [](const Vec3& x) { return x; });
        for (const std::size_t c : mCellsOf[tile]) {
            Vec3 p;
            if (!seedCell(mCells[c], work, p)) continue;
            walkSurface(p, work);
            checkCount(added.size(), mSettings, "surface sampling");
        }
    }

    /// Lines 2-7: up to t random points of the cell projected to the surface; whether one was
    /// taken (then p).
    bool seedCell(const std::array<std::int32_t, 3>& cell, Tile& work, Vec3& p) const
    {
        bool found = false;
        for (int a = 0; a < mSettings.surfaceAttempts && !found; ++a) {
            Vec3 ijk;
            for (int axis = 0; axis < 3; ++axis)
                ijk[axis] = Real(cell[axis]) + Real(work.rng.uniform01());
            found = tryAdd(mShape.indexToWorld(ijk), work, p);
        }
        return found;
    }

    /// Lines 10-16: walk along the surface from p in steps of e r while new samples are found
    /// (each step has t tries at a random tangent direction).
    void walkSurface(Vec3 p, Tile& work) const
    {
        const int t = mSettings.surfaceAttempts;
        for (bool extended = true; extended;) {
            extended = false;
            const Vec3 n = mShape.normal(p);
            if (n.lengthSqr() == Real(0)) break;
            for (int a = 0; a < t && !extended; ++a) {
                const Vec3 q = p + randomTangent(work.rng, n) * (mSettings.surfaceStep * mR);
                extended = tryAdd(q, work, p);
            }
        }
    }

    /// Project x to the surface; take it (into `accepted`) if it lands in the tile and meets
    /// the Poisson-disk criterion.
    bool tryAdd(const Vec3& x, Tile& work, Vec3& accepted) const
    {
        const Real r = mR;
        // Cheap rejection first: projection moves x by about |phi|, so a sample closer than
        // r - |phi| to x is closer than r to the projected point.
        const Real p = std::abs(mShape.phi(x));
        if (p < r && work.grid.anyWithin(x, r - p)) return false;
        const SurfaceProjection proj = mShape.projectToSurface(x);
        if (!proj.converged || !mDomain.contains(proj.point)
            || mTiles.tileOf(proj.point) != work.index || work.grid.anyWithin(proj.point, r))
            return false;
        work.grid.add(proj.point);
        work.added.push_back(proj.point);
        accepted = proj.point;
        return true;
    }

    const LevelSet& mShape;
    const PoissonSettings& mSettings;
    const Real mR; ///< Poisson radius (m)
    const std::vector<std::array<std::int32_t, 3>>& mCells;
    const CellLattice mDomain; ///< where samples may lie
    const TileLattice mTiles;
    std::vector<std::vector<std::size_t>> mCellsOf; ///< per tile: its cells
    std::vector<std::vector<Vec3>> mHeld;           ///< per tile: its samples
};

} // namespace

SampleSet PoissonDiskSampler::sampleSurface(const LevelSet& shape) const
{
    const auto cells = shape.surfaceCells();
    if (cells.empty()) {
        throw SamplingError(msg("level set '", shape.name(),
                                "' has no zero crossing: the shape "
                                "is empty or smaller than a voxel (",
                                shape.voxelSize(), " m)"));
    }
    SampleSet samples = SurfaceSampling(shape, mSettings, cells).run();
    if (samples.positions.empty()) {
        throw SamplingError(msg("level set '", shape.name(),
                                "': no surface sample could be "
                                "projected onto its zero crossing"));
    }
    return samples;
}

// [SB12] Sec. 4.5.2: Bridson 2007 seeded with the existing samples ------------------------------

void PoissonDiskSampler::sampleInterior(SampleSet& samples, const LevelSet& shape) const
{
    growInterior(samples, shape, {});
}

namespace {

/// Bridson's growth from seed samples, run tile by tile: a tile grows from the active samples
/// inside it, each as Bridson's algorithm does (candidates over its whole [r, 2r) shell until
/// t in a row fail), so it places samples at most 2r outside the tile and reads the samples at
/// most 3r outside it. Tiles of one colour, a tile (16r) apart, then grow in parallel; colours
/// run in order, and a tile grows again when samples were placed in it from a neighbour, until
/// no tile places any. Only the order in which samples grow differs from one sequential pass,
/// not how; but fronts of growth meet inside every tile, which leaves the unrelaxed samples
/// 1-2 % denser at tile faces than mid-tile (bench/history/diary-2026-11.md, "Sampler:
/// Algorithm 1 and Bridson's growth in parallel tiles"; the relaxations even most of it). The
/// samples depend on the seed and the tiles, never on the thread count.
class InteriorGrowth
{
public:
    /// Grow from the samples with seeds[i] (all when empty); the rest are obstacles.
    InteriorGrowth(SampleSet& samples, const LevelSet& shape, const PoissonSettings& settings,
                   const std::vector<std::uint8_t>& seeds)
        : mSamples(samples)
        , mShape(shape)
        , mSettings(settings)
        , mR(settings.radius)
        , mBand(samples, shape, settings.bandDepth, mR)
        , mDomain(samplingBounds(shape, mR), mR)
        , mTiles(samplingBounds(shape, mR), GROWTH_TILE_RADII * mR)
        , mHeld(mTiles.count())
        , mPending(mTiles.count(), 0)
        , mGrown(mTiles.count(), SEED - 1)
    {
        for (std::size_t i = 0; i < samples.size(); ++i) {
            const Vec3& x = samples.positions[i];
            if (!mDomain.contains(x)) continue;
            const bool seed = seeds.empty() || seeds[i];
            const std::size_t tile = mTiles.tileOf(x);
            mHeld[tile].push_back({x, seed ? SEED : OBSTACLE});
            if (seed) mPending[tile] = 1;
        }
    }

    /// Grow colour by colour until no tile has samples left to grow from; appends the new
    /// samples to the set.
    void run()
    {
        int phase = 0;
        for (bool grew = true; grew;) {
            grew = false;
            for (int colour = 0; colour < TileLattice::COLOURS; ++colour, ++phase) {
                if (growColour(colour, phase)) grew = true;
            }
        }
    }

private:
    /// A sample held by a tile, with the phase that placed it: SEED grows in its tile's first
    /// growth, OBSTACLE only keeps others away.
    struct Held
    {
        Vec3 x;
        int phase;
    };
    static constexpr int SEED = -1, OBSTACLE = std::numeric_limits<int>::min();

    /// A sample placed by a tile's growth, and whether it is still active (it left the tile's
    /// reach mid-growth: it goes on growing in its own tile).
    struct Placed
    {
        Vec3 x;
        bool active;
    };

    /// An active sample of a tile's growth: one in the tile not yet grown from (placed = -1),
    /// or one placed here (its index in the growth's `placed`).
    struct Active
    {
        Vec3 x;
        std::ptrdiff_t placed;
    };

    /// Grow the pending tiles of one colour in parallel, then hold what they placed; whether
    /// a sample still active made another tile pending.
    bool growColour(int colour, int phase)
    {
        const std::vector<std::size_t> batch =
            tilesOfColour(mTiles, colour, [this](std::size_t k) { return mPending[k] != 0; });
        if (batch.empty()) return false;
        std::vector<std::vector<Placed>> placed(batch.size());
        parallel::forEach(
            0, batch.size(), [&](std::size_t b) { growTile(batch[b], phase, placed[b]); }, 1);
        for (std::size_t b = 0; b < batch.size(); ++b) {
            mPending[batch[b]] = 0;
            mGrown[batch[b]] = phase;
        }
        const bool grew = holdPlaced(batch, placed, phase);
        checkCount(mSamples.size(), mSettings, "interior sampling");
        return grew;
    }

    /// Add the samples the batch placed to their tiles and to the set; a sample still active
    /// makes its tile grow again. Returns whether one did so for another tile.
    bool holdPlaced(const std::vector<std::size_t>& batch,
                    const std::vector<std::vector<Placed>>& placed, int phase)
    {
        bool grew = false;
        for (std::size_t b = 0; b < batch.size(); ++b) {
            for (const Placed& x : placed[b]) {
                const std::size_t tile = mTiles.tileOf(x.x);
                mHeld[tile].push_back({x.x, x.active ? phase : OBSTACLE});
                if (x.active && tile != batch[b]) {
                    mPending[tile] = 1;
                    grew = true;
                }
                mSamples.positions.push_back(x.x);
                mSamples.onSurface.push_back(0);
            }
        }
        return grew;
    }

    /// One growth of a tile in `phase`, from its active samples, into `placed`.
    void growTile(std::size_t tile, int phase, std::vector<Placed>& placed) const
    {
        // The tile's reach: the samples in it and the shells [r, 2r) about them. Samples
        // within r of the reach can reject a candidate (the margin covers round-off in which
        // tile a point falls).
        const Aabb reach = mTiles.box(tile).padded(Real(2.01) * mR),
                   near = reach.padded(Real(1.01) * mR);
        PointGrid grid(near, mR);
        addNeighbours(grid, mTiles, tile, near, mHeld, [](const Held& h) { return h.x; });
        std::vector<Active> active;
        for (const Held& h : mHeld[tile]) {
            if (h.phase > mGrown[tile]) active.push_back({h.x, -1});
        }
        if (active.empty()) return;
        Rng rng(mSettings.seed, tileStream(INTERIOR, phase, tile));
        growWithin(reach, grid, rng, active, placed);
    }

    /// Bridson's loop (growFromActive), up to the reach: a sample placed outside the tile grows
    /// here too until a candidate of it falls beyond the reach; it then stops here, still
    /// active, and its own tile's growth goes on from it. So every sample retires once, as in
    /// one sequential pass.
    void growWithin(const Aabb& reach, PointGrid& grid, Rng& rng, std::vector<Active>& active,
                    std::vector<Placed>& placed) const
    {
        const Real r = mR;
        const int t = mSettings.volumeAttempts;
        while (!active.empty()) {
            const std::uint32_t slot = rng.below(std::uint32_t(active.size()));
            const Active p = active[slot];
            bool found = false, beyond = false;
            for (int a = 0; a < t && !found; ++a) {
                const Vec3 q = p.x + rng.unitVector() * (r * Real(1.0 + rng.uniform01()));
                if (!mDomain.contains(q)) continue;
                if (!reach.contains(q)) {
                    beyond = true;
                    break;
                }
                if (!accepts(q, grid)) continue;
                grid.add(q);
                active.push_back({q, std::ptrdiff_t(placed.size())});
                placed.push_back({q, false});
                checkCount(mSamples.size() + placed.size(), mSettings, "interior sampling");
                found = true;
            }
            if (found) continue;
            if (beyond && p.placed >= 0) placed[std::size_t(p.placed)].active = true;
            active[slot] = active.back();
            active.pop_back();
        }
    }

    /// Whether candidate q is at least r from every sample, inside the shape and in the band.
    /// The distance test comes before the level set: in a filled region most candidates fail
    /// it, and it is the cheaper.
    bool accepts(const Vec3& q, const PointGrid& grid) const
    {
        if (grid.anyWithin(q, mR)) return false;
        const Real phi = mShape.phi(q);
        return phi < Real(0) && mBand.accepts(q, phi);
    }

    SampleSet& mSamples;
    const LevelSet& mShape;
    const PoissonSettings& mSettings;
    const Real mR; ///< Poisson radius (m)
    const DepthLimit mBand;
    const CellLattice mDomain; ///< where samples may lie
    const TileLattice mTiles;
    std::vector<std::vector<Held>> mHeld; ///< per tile: its samples
    std::vector<std::uint8_t> mPending;   ///< per tile: whether it has samples to grow from
    std::vector<int>
        mGrown; ///< per tile: the phase it last grew in (a sample placed later is active)
};

} // namespace

void PoissonDiskSampler::growInterior(SampleSet& samples, const LevelSet& shape,
                                      const std::vector<std::uint8_t>& seeds) const
{
    InteriorGrowth(samples, shape, mSettings, seeds).run();
}

// Tiled interior ---------------------------------------------------------------------------------

namespace {

/// Points in the periodic cube [0, side)^3, in a grid of cells about r wide whose distances
/// wrap around, so copies of the cube laid side by side keep the Poisson radius across their
/// faces.
class PeriodicTile
{
public:
    PeriodicTile(Real side, Real r)
        : mSide(side)
        , mR(r)
        , mCells(std::max(3, int(std::floor(side / r))))
        , mCell(side / Real(mCells))
        , mGrid(std::size_t(mCells) * mCells * mCells)
    {}

    /// Bridson's growth from one random point, until no point can be added.
    void grow(Rng& rng, int attempts)
    {
        const Real side = mSide;
        const Vec3 first(Real(rng.uniform01()) * side, Real(rng.uniform01()) * side,
                         Real(rng.uniform01()) * side);
        add(first);
        std::vector<Vec3> active{first};
        growFromActive(active, rng, mR, attempts, [&](const Vec3& q) {
            const Vec3 w = wrap(q);
            if (anyWithin(w, mR, -1)) return false;
            add(w);
            return true;
        });
    }

    /// One sweep of Algorithm 2, periodic: every point in turn moves to the best of
    /// `attempts` candidates.
    void relaxSweep(std::uint64_t seed, int sweep, int attempts)
    {
        const Real r = mR;
        const int t = attempts;
        for (std::size_t i = 0; i < mPoints.size(); ++i) {
            const Vec3 p = mPoints[i];
            gatherBall(i);
            if (mBall.empty()) continue;
            Real d2 = minDistance2(p);
            Vec3 best = p;
            Rng step(seed, TILE + 1 + (std::uint64_t(sweep) << 32) + i);
            for (int a = 0; a < t; ++a) {
                const Vec3 cand = p + step.unitVector() * (r * Real(t - a) / Real(t));
                const Real c2 = minDistance2(cand);
                if (c2 > d2) {
                    d2 = c2;
                    best = cand;
                }
            }
            if (best != p) moveTo(i, wrap(best));
        }
    }

    std::vector<Vec3>& points() { return mPoints; }

private:
    /// x wrapped into the cube.
    Vec3 wrap(const Vec3& x) const
    {
        auto w = [this](Real v) { return v - mSide * std::floor(v / mSide); };
        return Vec3(w(x[0]), w(x[1]), w(x[2]));
    }

    std::size_t cellOf(const Vec3& x) const
    {
        auto c = [this](Real v) { return std::min(mCells - 1, int(v / mCell)); };
        const std::size_t cells = std::size_t(mCells);
        return (std::size_t(c(x[2])) * cells + std::size_t(c(x[1]))) * cells + std::size_t(c(x[0]));
    }

    /// The nearest periodic image of q - p.
    Vec3 offset(const Vec3& q, const Vec3& p) const
    {
        Vec3 d = q - p;
        for (int a = 0; a < 3; ++a) d[a] -= mSide * std::round(d[a] / mSide);
        return d;
    }

    /// fn(id) for the points within `reach` cells of x (reach <= cells / 2 keeps visits
    /// distinct).
    template <typename Fn>
    void forNear(const Vec3& x, int reach, Fn&& fn) const
    {
        const int cells = mCells;
        const int cx = std::min(cells - 1, int(x[0] / mCell)),
                  cy = std::min(cells - 1, int(x[1] / mCell)),
                  cz = std::min(cells - 1, int(x[2] / mCell));
        for (int k = -reach; k <= reach; ++k) {
            for (int j = -reach; j <= reach; ++j) {
                for (int i = -reach; i <= reach; ++i) {
                    const std::size_t c = (std::size_t((cz + k + cells) % cells) * cells
                                           + std::size_t((cy + j + cells) % cells))
                                              * cells
                                          + std::size_t((cx + i + cells) % cells);
                    for (int id : mGrid[c]) fn(id);
                }
            }
        }
    }

    bool anyWithin(const Vec3& x, Real radius, int ignore) const
    {
        bool found = false;
        forNear(x, 1, [&](int id) {
            if (id != ignore && offset(mPoints[id], x).lengthSqr() < radius * radius) found = true;
        });
        return found;
    }

    void add(const Vec3& x)
    {
        mGrid[cellOf(x)].push_back(int(mPoints.size()));
        mPoints.push_back(x);
    }

    /// Point i to w (in the cube).
    void moveTo(std::size_t i, const Vec3& w)
    {
        auto& from = mGrid[cellOf(mPoints[i])];
        from.erase(std::find(from.begin(), from.end(), int(i)));
        mPoints[i] = w;
        mGrid[cellOf(w)].push_back(int(i));
    }

    /// B(p) of point i into mBall: the nearest images of the other points within 2r.
    void gatherBall(std::size_t i)
    {
        const Real r = mR;
        const Vec3 p = mPoints[i];
        const int reach = int(std::ceil(Real(2) * r / mCell));
        mBall.clear();
        forNear(p, reach, [&](int id) {
            const Vec3 d = offset(mPoints[id], p);
            if (id != int(i) && d.lengthSqr() < Real(4) * r * r) mBall.push_back(p + d);
        });
    }

    /// min over B(p) of |x - q|^2.
    Real minDistance2(const Vec3& x) const
    {
        Real d2 = std::numeric_limits<Real>::max();
        for (const Vec3& q : mBall) d2 = std::min(d2, (x - q).lengthSqr());
        return d2;
    }

    const Real mSide, mR;                ///< the cube's side and the Poisson radius (m)
    const int mCells;                    ///< cells per axis
    const Real mCell;                    ///< a cell's side (m)
    std::vector<std::vector<int>> mGrid; ///< per cell: its points
    std::vector<Vec3> mPoints;
    std::vector<Vec3> mBall;
};

} // namespace

std::vector<Vec3> PoissonDiskSampler::periodicTile(Real side) const
{
    PeriodicTile tile(side, mSettings.radius);
    Rng rng(mSettings.seed, TILE);
    tile.grow(rng, mSettings.volumeAttempts);
    for (int sweep = 0; sweep < mSettings.volumeRelaxSweeps; ++sweep)
        tile.relaxSweep(mSettings.seed, sweep, mSettings.relaxAttempts);
    return std::move(tile.points());
}

SampleSet PoissonDiskSampler::sampleVolumeTiled(const LevelSet& shape) const
{
    const Real r = mSettings.radius;
    SampleSet samples = sampleSurface(shape);
    relax(samples, shape, mSettings.surfaceRelaxSweeps, 0);
    const std::size_t surface = samples.size();

    // 1. Deeper than 2r: copies of a relaxed periodic tile, shifted by a random offset.
    const Real depth = Real(2) * r;
    const Real side = TILE_RADII * r;
    const std::vector<Vec3> tile = periodicTile(side);
    const DepthLimit band(samples, shape, mSettings.bandDepth, r);
    Rng rng(mSettings.seed, TILE_OFFSET);
    const Vec3 shift(Real(rng.uniform01()) * side, Real(rng.uniform01()) * side,
                     Real(rng.uniform01()) * side);
    const Aabb bounds = shape.bounds();
    const auto first = [&](int a) { return std::floor((bounds.min[a] - shift[a]) / side); };
    const auto last = [&](int a) { return std::floor((bounds.max[a] - shift[a]) / side); };
    std::vector<Vec3> tiled;
    for (Real k = first(2); k <= last(2); k += 1) {
        for (Real j = first(1); j <= last(1); j += 1) {
            for (Real i = first(0); i <= last(0); i += 1) {
                const Vec3 base = shift + Vec3(i, j, k) * side;
                for (const Vec3& p : tile) tiled.push_back(base + p);
            }
        }
    }
    checkCount(tiled.size(), mSettings, "tiled interior");
    // Depth from the surface samples (about r apart): phi is clamped a few voxels inside.
    PointGrid near(samplingBounds(shape, r), depth + Real(2) * r);
    for (std::size_t i = 0; i < surface; ++i) {
        if (near.contains(samples.positions[i])) near.add(samples.positions[i]);
    }
    // 0: not kept; 1: kept; 2: kept, next to the gap (it seeds the growth into it).
    std::vector<std::uint8_t> keep(tiled.size(), 0);
    parallel::forEach(
        0, tiled.size(),
        [&](std::size_t k) {
        const Vec3& x = tiled[k];
        if (!bounds.contains(x)) return;
        const Real phi = shape.phi(x);
        if (!(phi < Real(0)) || near.anyWithin(x, depth) || !band.accepts(x, phi)) return;
        keep[k] = near.anyWithin(x, depth + Real(2) * r) ? 2 : 1;
        },
        1024);
    std::vector<std::uint8_t> seeds(surface, 1);
    for (std::size_t k = 0; k < tiled.size(); ++k) {
        if (!keep[k]) continue;
        samples.positions.push_back(tiled[k]);
        samples.onSurface.push_back(0);
        seeds.push_back(keep[k] == 2);
    }
    const std::size_t fixed = samples.size();
    checkCount(fixed, mSettings, "tiled interior");

    // 2. Between the surface and 2r deep: Bridson's growth from the surface samples and the
    //    tile points along the gap, then Algorithm 2 for the samples placed so far by sampling
    //    (the tile points hold still: they are relaxed already, in the tile).
    growInterior(samples, shape, seeds);
    std::vector<std::uint8_t> movable(samples.size(), 1);
    std::fill(movable.begin() + std::ptrdiff_t(surface), movable.begin() + std::ptrdiff_t(fixed),
              0);
    relaxVolumeSome(samples, shape, movable);
    return samples;
}

// [SB12] Algorithm 2 ---------------------------------------------------------------------------

void PoissonDiskSampler::relax(SampleSet& samples, const LevelSet& shape, int sweeps,
                               int pass) const
{
    relaxSome(samples, shape, sweeps, pass, {});
}

void PoissonDiskSampler::relaxVolume(SampleSet& samples, const LevelSet& shape) const
{
    relaxVolumeSome(samples, shape, {});
}

void PoissonDiskSampler::relaxVolumeSome(SampleSet& samples, const LevelSet& shape,
                                         const std::vector<std::uint8_t>& movable) const
{
    switch (mSettings.volumeRelaxation) {
    case PoissonSettings::Relaxation::Packing:
        packSome(samples, shape, mSettings.packingIterations, movable);
        return;
    case PoissonSettings::Relaxation::Sb12:
        relaxSome(samples, shape, mSettings.volumeRelaxSweeps, 1, movable);
        return;
    }
}

namespace {

/// Algorithm 2 over a sample set: Gauss-Seidel sweeps, each sample in turn moved to the best of
/// t candidates within r, by the distance to its nearest neighbour in B(p).
///
/// The sweeps run in parallel by colouring: samples are grouped into blocks of side 8r and the
/// blocks into 8 colours by the parity of their coordinates. A sample reads and writes the
/// grid within 3r of where it starts (B(p) reaches 2r, a candidate moves at most r plus a
/// projection of at most r), so two blocks of one colour, at least a block apart, never touch
/// the same data. Blocks of a colour run in parallel, samples within a block in index order,
/// colours in order: the result does not depend on the thread count.
class Relaxation
{
public:
    Relaxation(SampleSet& samples, const LevelSet& shape, const PoissonSettings& settings, int pass)
        : mSamples(samples)
        , mShape(shape)
        , mR(settings.radius)
        , mAttempts(settings.relaxAttempts)
        , mSeed(settings.seed)
        , mPass(pass)
        , mBand(samples, shape, settings.bandDepth, mR)
        , mBounds(samplingBounds(shape, mR))
        // Cells of side 2r: B(p) (radius 2r) lies in the 27 cells around p, not in 125 of side r.
        , mGrid(mBounds, Real(2) * mR, samples.positions, mEntry)
    {}

    /// One sweep over the samples with movable[i] (all when empty).
    void sweep(int sweep, const std::vector<std::uint8_t>& movable)
    {
        orderByBlock(movable);
        for (std::size_t first = 0; first + 1 < mBlockStart.size();) {
            // Blocks [first, last) share a colour.
            const std::uint64_t colour = mOrder[mBlockStart[first]].key >> 60;
            std::size_t last = first + 1;
            while (last + 1 < mBlockStart.size() && mOrder[mBlockStart[last]].key >> 60 == colour)
                ++last;
            parallel::forEach(
                first, last, [&](std::size_t block) { relaxBlock(block, sweep); }, 1);
            first = last;
        }
    }

private:
    /// A sample in the sweep's order: its block's colour and coordinates, then its index.
    struct Item
    {
        std::uint64_t key;
        std::uint32_t index;
    };

    /// One sample's search for a better place: B(p), what is known of p, the best so far.
    struct Move
    {
        const Ball& ball; ///< B(p): the samples within 2r of p
        Vec3 p;
        bool surface;
        Real phiP; ///< phi(p), 0 for a surface sample
        /// p is deeper than r and the sampling is not band-limited: no candidate can leave
        /// the shape, and phi need not be looked up per candidate.
        bool deep;
        /// Band-limited and deeper than the Lipschitz bound: no candidate is outside the
        /// shape, so none is projected, and only one that beats the best needs the band test.
        bool inside;
        Real d2;   ///< squared distance from `best` to B(p)
        Vec3 best; ///< the best place so far
        /// A surface sample within the band's reach of the last candidate tested against it.
        Vec3 hint{std::numeric_limits<Real>::max()};
    };

    /// Lipschitz bound of the interpolated distance: trilinear interpolation of a distance
    /// sampled on a grid changes by at most one voxel per voxel along each axis, so by at most
    /// sqrt(3) times the distance moved; 2 leaves room for grids that are only nearly
    /// distances. It only decides which candidates can skip a phi lookup, never a result.
    static constexpr Real LIPSCHITZ = Real(2);

    /// The samples to move (entry >= 0, movable) sorted by block colour, block, index, into
    /// mOrder, with where each block starts in mBlockStart.
    void orderByBlock(const std::vector<std::uint8_t>& movable)
    {
        const Real blockSize = Real(8) * mR;
        mOrder.clear();
        for (std::size_t i = 0; i < mSamples.size(); ++i) {
            if (mEntry[i] < 0 || (!movable.empty() && !movable[i])) continue;
            std::uint64_t b[3];
            for (int a = 0; a < 3; ++a) {
                b[a] = std::uint64_t((mSamples.positions[i][a] - mBounds.min[a]) / blockSize);
            }
            const std::uint64_t colour = (b[0] & 1) | (b[1] & 1) << 1 | (b[2] & 1) << 2;
            mOrder.push_back({colour << 60 | b[2] << 40 | b[1] << 20 | b[0], std::uint32_t(i)});
        }
        std::sort(mOrder.begin(), mOrder.end(), [](const Item& a, const Item& b) {
            return a.key != b.key ? a.key < b.key : a.index < b.index;
        });
        mBlockStart.clear();
        for (std::size_t k = 0; k < mOrder.size(); ++k) {
            if (k == 0 || mOrder[k].key != mOrder[k - 1].key) mBlockStart.push_back(k);
        }
        mBlockStart.push_back(mOrder.size());
    }

    /// Relax the samples of one block in index order.
    void relaxBlock(std::size_t block, int sweep)
    {
        Ball ball;
        std::vector<Vec3> directions(std::size_t(mAttempts), Vec3(0)); // the candidates'
        for (std::size_t k = mBlockStart[block]; k < mBlockStart[block + 1]; ++k) {
            relaxOne(mOrder[k].index, sweep, ball, directions);
        }
    }

    /// Move sample i to the best of its candidates, if one beats where it is.
    void relaxOne(std::size_t i, int sweep, Ball& ball, std::vector<Vec3>& directions)
    {
        const Vec3 p = mSamples.positions[i];
        const bool surface = mSamples.onSurface[i] != 0;
        ball.gather(mGrid, p, Real(2) * mR, mEntry[i]);
        if (ball.empty()) return;
        const Real d2 = ball.minDistance2(p);
        // Candidates lie within r of p.
        const Real phiP = surface ? Real(0) : mShape.phi(p);
        const bool deep = !surface && !mBand.limited() && phiP < -Real(1.01) * mR;
        const bool inside = !surface && mBand.limited() && phiP < -LIPSCHITZ * mR;
        Move m{ball, p, surface, phiP, deep, inside, d2, p};
        // One random stream per (pass, sweep, sample).
        Rng rng(mSeed, RELAX + (std::uint64_t(mPass) << 40) + (std::uint64_t(sweep) << 32) + i);
        rng.unitVectors(directions.data(), mAttempts);
        const int t = mAttempts;
        for (int a = 0; a < t; ++a) {
            const Real tau = Real(t - a) / Real(t);
            const Vec3 cand = p + directions[a] * (mR * tau);
            if (m.inside) {
                tryInside(cand, m);
            } else if (m.deep) {
                tryPlain(cand, m);
            } else {
                tryNearSurface(cand, tau, m);
            }
        }
        if (m.best != p) {
            mGrid.move(mEntry[i], m.best);
            mSamples.positions[i] = m.best;
        }
    }

    /// A lazy phi(x) for the band test.
    auto phiOf(const Vec3& x) const
    {
        return [this, x] { return mShape.phi(x); };
    }

    /// Take cand if it beats the best so far.
    static void tryPlain(const Vec3& cand, Move& m)
    {
        Real c2;
        if (m.ball.beats(cand, m.d2, c2)) {
            m.d2 = c2;
            m.best = cand;
        }
    }

    /// Take cand, certainly inside the shape and so never projected, if it beats the best so
    /// far, is within the band and within the grid (the cheap test first).
    void tryInside(const Vec3& cand, Move& m) const
    {
        Real c2;
        if (!m.ball.beats(cand, m.d2, c2)) return;
        if (mBand.limited() && !mBand.accepts(cand, phiOf(cand), m.hint)) return;
        if (!mGrid.contains(cand)) return;
        m.d2 = c2;
        m.best = cand;
    }

    /// A candidate at tau r from a sample that is not deep: inside (tryInside), or projected
    /// onto the surface when it is a surface sample's or outside, then taken if it beats the
    /// best so far.
    void tryNearSurface(Vec3 cand, Real tau, Move& m) const
    {
        // phi(cand) <= phi(p) + L |cand - p| (phi(p) = 0 on the surface).
        const Real reachOut = LIPSCHITZ * mR * tau;
        if (!m.surface && m.phiP + reachOut < Real(0)) return tryInside(cand, m);
        // A projection moves cand by about |phi|, and cand is projected when it is a surface
        // sample's (|phi| <= L r tau) or outside (0 < phi <= phi(p) + L r tau). Skip it without
        // looking phi up when even the largest such move could not beat the best distance so
        // far: then the tests below, on the actual phi, would skip it too (if it is not
        // projected, it is no farther from B(p) than the best). Most candidates of samples
        // just inside the surface end here.
        const Real c2 = m.ball.minDistance2(cand);
        const Real largestMove = m.surface ? reachOut : m.phiP + reachOut;
        const Real bound = std::sqrt(c2) + Real(1.05) * largestMove;
        if (bound * bound <= m.d2) return;
        // A surface sample's candidate is always projected: one stencil gives phi and the
        // projection's first step.
        Vec3 grad(0);
        const Real phi = m.surface ? mShape.phiAndGradient(cand, grad) : mShape.phi(cand);
        if (m.surface || phi > Real(0)) {
            // The projection moves cand by about |phi|: skip it when even that much could not
            // beat the best distance so far.
            const Real reach = std::sqrt(c2) + Real(1.05) * std::abs(phi);
            if (reach * reach <= m.d2) return;
            const SurfaceProjection proj = m.surface ? mShape.projectToSurface(cand, phi, grad)
                                                     : mShape.projectToSurface(cand);
            // A projection that lands more than 2r away left the neighbourhood this step may
            // touch (see the colouring): reject it.
            if (!proj.converged || (proj.point - m.p).lengthSqr() > Real(4) * mR * mR) return;
            cand = proj.point;
        } else if (!mBand.accepts(
                       cand, [phi] { return phi; }, m.hint)) {
            return;
        }
        if (!mGrid.contains(cand)) return;
        tryPlain(cand, m);
    }

    SampleSet& mSamples;
    const LevelSet& mShape;
    const Real mR; ///< Poisson radius (m)
    const int mAttempts;
    const std::uint64_t mSeed;
    const int mPass;
    const DepthLimit mBand;
    const Aabb mBounds;
    std::vector<int> mEntry; ///< per sample: its entry in mGrid, or -1 outside it
    SlotGrid mGrid;
    std::vector<Item> mOrder;
    std::vector<std::size_t> mBlockStart;
};

} // namespace

void PoissonDiskSampler::relaxSome(SampleSet& samples, const LevelSet& shape, int sweeps, int pass,
                                   const std::vector<std::uint8_t>& movable) const
{
    if (sweeps <= 0 || samples.size() < 2) return;
    Relaxation relaxation(samples, shape, mSettings, pass);
    for (int sweep = 0; sweep < sweeps; ++sweep) relaxation.sweep(sweep, movable);
}

// [SB12] Sec. 4.5.2: seeded sampling for air layers and emission ------------------------------

std::vector<Vec3> PoissonDiskSampler::sampleFromSeeds(
    const std::vector<Vec3>& seeds, const std::vector<Vec3>& obstacles,
    const std::function<bool(const Vec3&)>& accept, const Aabb& bounds,
    const std::function<bool(const Vec3&)>& where) const
{
    std::vector<Vec3> added;
    if (seeds.empty() || bounds.empty()) return added;
    const Real r = mSettings.radius;
    const Aabb gridBounds = bounds.padded(Real(2) * r);
    PointGrid grid(gridBounds, r);
    for (const Vec3& x : obstacles) {
        if (grid.contains(x)) grid.add(x);
    }
    std::vector<Vec3> active;
    for (const Vec3& x : seeds) {
        if (grid.contains(x)) {
            grid.add(x);
            active.push_back(x);
        }
    }
    Rng rng(mSettings.seed, SEEDED);
    growFromActive(active, rng, r, mSettings.volumeAttempts, [&](const Vec3& q) {
        if (!bounds.contains(q) || (where && !where(q)) || grid.anyWithin(q, r) || !accept(q))
            return false;
        grid.add(q);
        added.push_back(q);
        checkCount(added.size(), mSettings, "seeded sampling");
        return true;
    });
    return added;
}

} // namespace sph
} // namespace ghostfx
