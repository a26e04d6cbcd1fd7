/// @file   NeighborLists.cc
/// @brief  The search behind NeighborLists::build: cached stencils, per-query cell culling and a
///         branch-free distance filter.
#include "ghostfx/sph/NeighborLists.h"

#include "ghostfx/sph/Exceptions.h"
#include "ghostfx/sph/Parallel.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstring>
#include <limits>

#if defined(__x86_64__)
#include <immintrin.h>
#endif

namespace ghostfx {
namespace sph {

namespace {

/// Candidates per distance batch (the width of a hit mask).
constexpr std::uint32_t BATCH = 64;

/// Left-packing table for `Lanes` lanes: for a hit mask of that many bits, the lane numbers of
/// its set bits in increasing order (unused entries 0), and how many there are.
template <int Lanes>
struct PackTable
{
    static constexpr int MASKS = 1 << Lanes;
    alignas(4 * Lanes) std::int32_t lanes[MASKS][Lanes];
    std::uint8_t count[MASKS];
    constexpr PackTable() : lanes(), count()
    {
        for (int m = 0; m < MASKS; ++m) {
            int c = 0;
            for (int b = 0; b < Lanes; ++b) {
                if (m & (1 << b)) lanes[m][c++] = b;
            }
            count[m] = std::uint8_t(c);
        }
    }
};
constexpr PackTable<4> PACK;

/// Append `first + k` to dst (from index `used`) for every k < len with r2[k] < radius2, in
/// increasing k; returns the new count. Branch-free: with SSE2 and float, four lanes are
/// compared at a time and their hits left-packed through a 16-entry table (an unconditional
/// 4-wide store, advanced by the hit count); otherwise a scalar compaction. dst must have room
/// for len + 3 more entries, and r2 for a multiple of four (the caller pads with zeros; lanes
/// at or beyond len are masked off).
inline std::size_t appendHits(const Real* r2, std::size_t len, Real radius2, std::uint32_t first,
                              Index* dst, std::size_t used)
{
#if defined(__SSE2__) && !defined(GHOSTFX_DOUBLE)
    const __m128 limit = _mm_set1_ps(radius2);
    for (std::size_t k = 0; k < len; k += 4) {
        int mask = _mm_movemask_ps(_mm_cmplt_ps(_mm_load_ps(r2 + k), limit));
        if (len - k < 4) mask &= (1 << (len - k)) - 1;
        const __m128i lanes = _mm_load_si128(reinterpret_cast<const __m128i*>(PACK.lanes[mask]));
        const __m128i index = _mm_add_epi32(lanes, _mm_set1_epi32(std::int32_t(first + k)));
        _mm_storeu_si128(reinterpret_cast<__m128i*>(dst + used), index);
        used += PACK.count[mask];
    }
#else
    for (std::size_t k = 0; k < len; ++k) {
        dst[used] = first + Index(k);
        used += std::size_t(r2[k] < radius2);
    }
#endif
    return used;
}

#if defined(__x86_64__) && !defined(GHOSTFX_DOUBLE)
/// The eight-lane table (AVX2).
constexpr PackTable<8> PACK8;

/// Append first + l to dst (from index `used`) for each lane l set in the eight-bit `mask`
/// and below `left`, in increasing l, with one unconditional eight-wide store; returns the
/// new count.
__attribute__((target("avx2"))) inline std::size_t packLanes8(int mask, std::size_t left,
                                                              std::uint32_t first,
                                                              std::uint32_t* dst, std::size_t used)
{
    if (left < 8) mask &= (1 << left) - 1;
    const __m256i lanes = _mm256_load_si256(reinterpret_cast<const __m256i*>(PACK8.lanes[mask]));
    const __m256i index = _mm256_add_epi32(lanes, _mm256_set1_epi32(std::int32_t(first)));
    _mm256_storeu_si256(reinterpret_cast<__m256i*>(dst + used), index);
    return used + PACK8.count[mask];
}

/// The same search as the portable path (the same products and sums in the same order, no
/// fused multiply-add, so the same hits), eight candidates at a time. Compiled for AVX2 and
/// called only where the processor has it. Reads up to seven slots past `end` (the grid pads
/// its coordinate arrays) and writes up to eight entries past the hits.
__attribute__((target("avx2"))) std::size_t searchRangeAvx2(const float* X, const float* Y,
                                                            const float* Z, std::uint32_t begin,
                                                            std::uint32_t end, const float q[3],
                                                            float radius2, Index* dst,
                                                            std::size_t used)
{
    const __m256 cx = _mm256_set1_ps(q[0]), cy = _mm256_set1_ps(q[1]), cz = _mm256_set1_ps(q[2]);
    const __m256 limit = _mm256_set1_ps(radius2);
    for (std::uint32_t s = begin; s < end; s += 8) {
        const __m256 dx = _mm256_sub_ps(cx, _mm256_loadu_ps(X + s));
        const __m256 dy = _mm256_sub_ps(cy, _mm256_loadu_ps(Y + s));
        const __m256 dz = _mm256_sub_ps(cz, _mm256_loadu_ps(Z + s));
        const __m256 r2 = _mm256_add_ps(_mm256_add_ps(_mm256_mul_ps(dx, dx), _mm256_mul_ps(dy, dy)),
                                        _mm256_mul_ps(dz, dz));
        const int mask = _mm256_movemask_ps(_mm256_cmp_ps(r2, limit, _CMP_LT_OQ));
        used = packLanes8(mask, end - s, s, dst, used);
    }
    return used;
}

/// Where the runs of a list start (where the window src[k] >> 8 changes), eight entries at a
/// time: the positions k of the changes are left-packed into runStart through the same table.
/// Reads up to seven entries past `hits` and writes up to eight past the runs.
__attribute__((target("avx2"))) std::size_t findRunsAvx2(const Index* src, std::size_t hits,
                                                         std::uint32_t* runStart)
{
    runStart[0] = 0;
    std::size_t runs = 1;
    for (std::size_t k = 1; k < hits; k += 8) {
        const __m256i here =
            _mm256_srli_epi32(_mm256_loadu_si256(reinterpret_cast<const __m256i*>(src + k)), 8);
        const __m256i before =
            _mm256_srli_epi32(_mm256_loadu_si256(reinterpret_cast<const __m256i*>(src + k - 1)), 8);
        const int mask =
            ~_mm256_movemask_ps(_mm256_castsi256_ps(_mm256_cmpeq_epi32(here, before))) & 0xff;
        runs = packLanes8(mask, hits - k, std::uint32_t(k), runStart, runs);
    }
    return runs;
}

bool haveAvx2()
{
    static const bool yes = __builtin_cpu_supports("avx2");
    return yes;
}
#endif

std::atomic<bool> gWideSimd{true};

/// The occupied cells of the 3 x 3 x 3 block around one cell: their slot ranges and their
/// offset (di, dj, dk) + 1 from the centre.
struct Stencil
{
    NeighborGrid::Cell centre{std::numeric_limits<std::int32_t>::min(), 0, 0};
    int count = 0;
    NeighborGrid::SlotRange range[27];
    std::uint8_t offset[27][3];

    void lookUp(const NeighborGrid& grid, const NeighborGrid::Cell& c)
    {
        centre = c;
        count = 0;
        for (int di = 0; di < 3; ++di) {
            for (int dj = 0; dj < 3; ++dj) {
                for (int dk = 0; dk < 3; ++dk) {
                    const NeighborGrid::SlotRange r =
                        grid.cellSlots({c.i + di - 1, c.j + dj - 1, c.k + dk - 1});
                    if (r.empty()) continue;
                    range[count] = r;
                    offset[count][0] = std::uint8_t(di);
                    offset[count][1] = std::uint8_t(dj);
                    offset[count][2] = std::uint8_t(dk);
                    ++count;
                }
            }
        }
    }
};

/// The sum of count(list) over the lists of `lists`.
template <typename Count>
std::size_t sumOverLists(const NeighborLists& lists, Count&& count)
{
    std::size_t total = 0;
    for (std::size_t q = 0; q < lists.size(); ++q) total += count(lists[q]);
    return total;
}

} // namespace

/// Fills the lists of one chunk of queries. Per query the reachable cells of the stencil are
/// searched into a buffer of 32-bit hits (so the chunk needs room for the lists only, not for
/// a search's candidates), which is then written to the chunk in its final form: runs, or
/// 32-bit indices.
class NeighborLists::ChunkBuilder
{
public:
    /// What every chunk of one build reads.
    struct Input
    {
        const NeighborGrid& targets;
        const Vec3* queries;
        std::size_t count;
        Real radius;                ///< m
        const std::uint8_t* select; ///< see buildSelected
        int match;
        const Real* supports; ///< per particle (m), or null: see build()
        bool avx2;               ///< whether to search with searchRangeAvx2
    };

    explicit ChunkBuilder(const Input& in)
        : mIn(in)
        , mX(in.targets.sortedX())
        , mY(in.targets.sortedY())
        , mZ(in.targets.sortedZ())
    {}

    /// Build the lists of queries [qFirst, qEnd) into `out` and fit it to them.
    void fill(Chunk& out, std::size_t qFirst, std::size_t qEnd)
    {
        End ends[CHUNK];
        std::size_t used = 0; // bytes of the chunk
        for (std::size_t q = qFirst; q < qEnd; ++q) {
            if (!wanted(q) || !isFinite(mIn.queries[q])) {
                ends[q - qFirst] = {std::uint32_t(used), 0};
                continue;
            }
            std::size_t hits = searchStencil(mIn.queries[q], radius2Of(q));
            if (mIn.supports) hits = keepPairSupports(q, hits);
            toParticleIndices(hits);
            const Index window = hits > 0 ? store(hits, out, used) : 0;
            if (used >= std::size_t(std::numeric_limits<std::uint32_t>::max())) {
                throw ValueError("neighbour lists: more than 2^32 entries in one chunk");
            }
            ends[q - qFirst] = {std::uint32_t(used), window};
        }
        finish(out, ends, qEnd - qFirst, used);
    }

private:
    /// Whether query q gets a list (buildSelected's `select` and `match`).
    bool wanted(std::size_t q) const
    {
        const std::uint8_t* select = mIn.select;
        return !select || (mIn.match < 0 ? select[q] != 0 : int(select[q]) == mIn.match);
    }

    /// The squared search radius of query q (m^2): the build's, or with supports, the largest
    /// pair support of q, (h_q + radius) / 2.
    Real radius2Of(std::size_t q) const
    {
        if (!mIn.supports) return mIn.radius * mIn.radius;
        const Real rq = std::min(Real(0.5) * (mIn.supports[q] + mIn.radius), mIn.radius);
        return rq > Real(0) ? rq * rq : Real(0);
    }

    /// Keep, of query q's `hits` (slots, in order), those within their pair support (with a
    /// margin of 1e-4 of it, above float rounding, so no pair a pass would use is dropped);
    /// returns how many are kept. A particle grown among small ones (an entraining gas) makes
    /// every query near it search its wide support, most of which lies beyond the pairs'.
    std::size_t keepPairSupports(std::size_t q, std::size_t hits)
    {
        constexpr Real MARGIN = Real(1.0001);
        const Vec3& x = mIn.queries[q];
        const Real hq = mIn.supports[q];
        const bool sorted = mIn.targets.identityOrder();
        Index* found = mFound.data();
        std::size_t kept = 0;
        for (std::size_t k = 0; k < hits; ++k) {
            const Index s = found[k];
            const Real dx = x[0] - mX[s], dy = x[1] - mY[s], dz = x[2] - mZ[s];
            const Real ht = mIn.supports[sorted ? s : mIn.targets.particleAt(s)];
            const Real R = Real(0.5) * (hq + ht) * MARGIN;
            found[kept] = s;
            kept += std::size_t(dx * dx + dy * dy + dz * dz < R * R);
        }
        return kept;
    }

    /// Search the cells around x that its ball of squared radius `radius2` reaches. Reachable
    /// cells whose slots follow each other (neighbours along z usually do: z is the lowest
    /// Morton bit) are searched as one range. Returns the number of hits.
    std::size_t searchStencil(const Vec3& x, Real radius2)
    {
        const NeighborGrid::Cell c = mIn.targets.cellOf(x);
        if (c != mStencil.centre) mStencil.lookUp(mIn.targets, c);
        Real axis2[3][3];
        reachPerAxis(x, c, axis2);
        const Real q[3] = {x[0], x[1], x[2]};
        std::size_t hits = 0;
        NeighborGrid::SlotRange run;
        for (int n = 0, cells = mStencil.count; n < cells; ++n) {
            const std::uint8_t* o = mStencil.offset[n];
            if (axis2[0][o[0]] + axis2[1][o[1]] + axis2[2][o[2]] >= radius2) continue;
            const NeighborGrid::SlotRange range = mStencil.range[n];
            if (!run.empty() && range.begin == run.end) {
                run.end = range.end;
                continue;
            }
            if (!run.empty()) hits = searchRange(run, q, radius2, hits);
            run = range;
        }
        if (!run.empty()) hits = searchRange(run, q, radius2, hits);
        return hits;
    }

    /// Squared distance from x (in cell c) to the slab of each neighbouring cell, per axis: 0
    /// for its own cell, the distance to the lower / upper face for the others. A cell is
    /// reachable when the sum over the axes is below R^2. The faces are moved out by a small
    /// slack, so float rounding in the cell assignment never drops a neighbour.
    void reachPerAxis(const Vec3& x, const NeighborGrid::Cell& c, Real axis2[3][3]) const
    {
        const Real cellSize = mIn.targets.cellSize();
        const Real cell[3] = {Real(c.i), Real(c.j), Real(c.k)};
        for (int a = 0; a < 3; ++a) {
            const Real slack = Real(1e-3) * cellSize + Real(1e-5) * std::abs(x[a]);
            const Real lo = x[a] - cell[a] * cellSize;
            const Real below = std::max(Real(0), lo - slack);
            const Real above = std::max(Real(0), cellSize - lo - slack);
            axis2[a][0] = below * below;
            axis2[a][1] = 0;
            axis2[a][2] = above * above;
        }
    }

    /// Append the slots of `range` closer than sqrt(radius2) to q to the `hits` so far;
    /// returns the new count.
    std::size_t searchRange(NeighborGrid::SlotRange range, const Real q[3], Real radius2,
                            std::size_t hits)
    {
        const std::size_t room = hits + (range.end - range.begin) + 8;
        if (mFound.size() < room) {
            mFound.resize(std::max(room, 2 * mFound.size()));
            mRunStart.resize(mFound.size() + 9);
        }
        Index* dst = mFound.data();
#if defined(__x86_64__) && !defined(GHOSTFX_DOUBLE)
        if (mIn.avx2)
            return searchRangeAvx2(mX, mY, mZ, range.begin, range.end, q, radius2, dst, hits);
#endif
        const Real qx = q[0], qy = q[1], qz = q[2];
        for (std::uint32_t s0 = range.begin; s0 < range.end; s0 += BATCH) {
            const std::size_t len = std::min<std::size_t>(BATCH, range.end - s0);
            const std::size_t padded = (len + 3) & ~std::size_t(3);
            const Real* xs = mX + s0;
            const Real* ys = mY + s0;
            const Real* zs = mZ + s0;
            // Distances first (vectorises; the grid pads its arrays, so reading up to three
            // slots past the range is safe), then the hits.
            for (std::size_t k = 0; k < padded; ++k) {
                const Real dx = qx - xs[k], dy = qy - ys[k], dz = qz - zs[k];
                mR2[k] = dx * dx + dy * dy + dz * dz;
            }
            hits = appendHits(mR2, len, radius2, s0, dst, hits);
        }
        return hits;
    }

    /// Slots to particle indices (nothing to do for a grid over a sorted set).
    void toParticleIndices(std::size_t hits)
    {
        if (mIn.targets.identityOrder()) return;
        Index* src = mFound.data();
        for (std::size_t k = 0; k < hits; ++k) src[k] = mIn.targets.particleAt(src[k]);
    }

    /// Write the `hits` (at least one) to `out` from byte `used` on, advancing it: in runs of
    /// consecutive neighbours in one window of 256 indices where that is smaller and the
    /// windows fit 16 bits, else as 32-bit indices. Returns the list's first window, or RAW.
    Index store(std::size_t hits, Chunk& out, std::size_t& used)
    {
        const Index* src = mFound.data();
        Index lo = RAW, hi = 0;
        for (std::size_t k = 0; k < hits; ++k) {
            lo = std::min(lo, src[k]);
            hi = std::max(hi, src[k]);
        }
        const Index window = lo >> 8;
        const std::size_t nRuns = findRuns(hits);
        const std::size_t bytes = List::COUNT + List::HEADER * nRuns + hits;
        if ((hi >> 8) - window <= 0xffff && nRuns <= 0xffff && bytes < sizeof(Index) * hits) {
            out.reserve(used + bytes + List::READ_PAST, used);
            storeRuns(out.bytes.get() + used, hits, nRuns, window);
            used += bytes;
            return window;
        }
        // Windows too far apart for 16 bits, or more runs than entries (targets not sorted).
        out.reserve(used + sizeof(Index) * hits + List::READ_PAST, used);
        std::memcpy(out.bytes.get() + used, src, sizeof(Index) * hits);
        used += sizeof(Index) * hits;
        return RAW;
    }

    /// Where each run of the `hits` starts (where the window changes, branch-free), into
    /// mRunStart; returns the number of runs.
    std::size_t findRuns(std::size_t hits)
    {
        const Index* src = mFound.data();
        std::uint32_t* runStart = mRunStart.data();
#if defined(__x86_64__) && !defined(GHOSTFX_DOUBLE)
        if (mIn.avx2) return findRunsAvx2(src, hits, runStart);
#endif
        std::size_t nRuns = 0;
        Index previous = RAW;
        for (std::size_t k = 0; k < hits; ++k) {
            const Index w = src[k] >> 8;
            runStart[nRuns] = std::uint32_t(k);
            nRuns += std::size_t(w != previous);
            previous = w;
        }
        return nRuns;
    }

    /// Write the hits at `at` as a list in runs: the run count, a header per run (its window
    /// from `window`, its length less one), then a byte per neighbour.
    void storeRuns(std::uint8_t* at, std::size_t hits, std::size_t nRuns, Index window)
    {
        const Index* src = mFound.data();
        std::uint32_t* runStart = mRunStart.data();
        const std::uint16_t runs16 = std::uint16_t(nRuns);
        std::memcpy(at, &runs16, sizeof(runs16));
        std::uint8_t* header = at + List::COUNT;
        runStart[nRuns] = std::uint32_t(hits);
        for (std::size_t r = 0; r < nRuns; ++r, header += List::HEADER) {
            const std::uint32_t k = runStart[r];
            const std::uint16_t w = std::uint16_t((src[k] >> 8) - window);
            std::memcpy(header, &w, sizeof(w));
            header[2] = std::uint8_t(runStart[r + 1] - k - 1); // at most 256 in a window
        }
        std::uint8_t* __restrict entry = header;
        const Index* __restrict from = src;
        for (std::size_t k = 0; k < hits; ++k) entry[k] = std::uint8_t(from[k]);
    }

    /// Keep the chunk's `n` list ends (none when every list is empty) and fit its bytes to the
    /// `used` its lists take: they shrank since an earlier step, or it grew by a sixteenth
    /// while being filled, and capacity is what the process holds. Most chunks are
    /// re-allocated in most steps; that costs less than a step's noise
    /// (bench/history/diary-2026-11.md, "Memory: lists fitted").
    static void finish(Chunk& out, const End* ends, std::size_t n, std::size_t used)
    {
        if (used == 0) {
            out.ends.reset();
            out.bytes.reset();
            out.capacity = 0;
        } else {
            if (!out.ends) out.ends.reset(new End[CHUNK]);
            std::copy(ends, ends + n, out.ends.get());
        }
        if (out.capacity > used + used / 64 + 64 + List::READ_PAST) out.shrink(used);
    }

    const Input& mIn;
    const Real *mX, *mY, *mZ; ///< the targets' sorted coordinates (m)
    Stencil mStencil;         ///< the cells around the last query's cell
    /// The current query's hits as slots, then as particle indices.
    std::vector<Index> mFound = std::vector<Index>(1024);
    std::vector<std::uint32_t> mRunStart = std::vector<std::uint32_t>(1024 + 9); ///< its runs
    alignas(16) Real mR2[BATCH] = {}; ///< squared distances of one batch of candidates
};

void NeighborLists::build(const NeighborGrid& targets, const Vec3* queries, std::size_t count,
                          Real radius, const std::uint8_t* wanted, const Real* supports)
{
    buildSelected(targets, queries, count, radius, wanted, -1, supports);
}

void NeighborLists::buildFor(const NeighborGrid& targets, const Vec3* queries, std::size_t count,
                             Real radius, const std::uint8_t* tags, std::uint8_t tag)
{
    buildSelected(targets, queries, count, radius, tags, int(tag), nullptr);
}

void NeighborLists::buildSelected(const NeighborGrid& targets, const Vec3* queries,
                                  std::size_t count, Real radius, const std::uint8_t* select,
                                  int match, const Real* supports)
{
    if (!(radius > Real(0)) || radius > targets.cellSize()) {
        throw ValueError(msg("neighbour lists: radius ", radius,
                             " m: expected > 0 and at most the "
                             "grid's cell size ",
                             targets.cellSize(), " m"));
    }
    mSize = count;
    if (targets.size() == 0) {
        // Every list is empty: hold nothing per query (a solid block with no particles).
        mChunks = std::vector<Chunk>();
        return;
    }
    const std::size_t chunks = (count + CHUNK - 1) / CHUNK;
    mChunks.resize(chunks); // chunks beyond this build's queries give their memory back
    const ChunkBuilder::Input in{targets, queries, count,       radius,
                                 select,  match,   supports, wideSimd()};
    parallel::forEach(
        0, chunks,
        [&](std::size_t chunk) {
        ChunkBuilder(in).fill(mChunks[chunk], chunk * CHUNK, std::min(count, (chunk + 1) * CHUNK));
        },
        1);
}

void NeighborLists::setWideSimd(bool enabled) { gWideSimd.store(enabled); }

bool NeighborLists::wideSimd()
{
#if defined(__x86_64__) && !defined(GHOSTFX_DOUBLE)
    return haveAvx2() && gWideSimd.load();
#else
    return false;
#endif
}

void NeighborLists::Chunk::shrink(std::size_t used)
{
    const std::size_t fitted = used + List::READ_PAST + 32;
    std::unique_ptr<std::uint8_t[]> smaller(new std::uint8_t[fitted]);
    std::copy(bytes.get(), bytes.get() + used, smaller.get());
    bytes = std::move(smaller);
    capacity = fitted;
}

void NeighborLists::Chunk::reserve(std::size_t size, std::size_t used)
{
    if (size <= capacity) return;
    const std::size_t grown = std::max(size, capacity + capacity / 16 + 512);
    std::unique_ptr<std::uint8_t[]> bigger(new std::uint8_t[grown]);
    if (used > 0) std::copy(bytes.get(), bytes.get() + used, bigger.get());
    bytes = std::move(bigger);
    capacity = grown;
}

std::size_t NeighborLists::pairCount() const
{
    return sumOverLists(*this, [](const List& list) { return list.size(); });
}

std::size_t NeighborLists::rawListCount() const
{
    return sumOverLists(*this, [](const List& list) {
        return std::size_t(list.raw() != nullptr && !list.empty());
    });
}

std::size_t NeighborLists::runCount() const
{
    return sumOverLists(*this, [](const List& list) { return list.runs(); });
}

std::size_t NeighborLists::memoryBytes() const
{
    std::size_t bytes = 0;
    for (const auto& c : mChunks) {
        bytes += c.capacity;
        if (c.ends) bytes += CHUNK * sizeof(End);
    }
    return bytes;
}

} // namespace sph
} // namespace ghostfx
