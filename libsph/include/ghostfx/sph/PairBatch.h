/// @file   PairBatch.h
/// @brief  A particle's neighbours taken in batches of arrays, so the kernel arithmetic of an
///         SPH pair sum runs on SIMD lanes.
/// @details A neighbour loop written pair by pair gathers x_j, computes r with a square root and
///          the kernel with a division, one pair at a time, and the three accumulators of a
///          vector sum form dependency chains: about 25 cycles per pair
///          (bench/history/diary-2026-11.md, "Liquid step"). Here the gathers fill small arrays
///          first (xij components, r), the arithmetic then runs over the arrays in loops the
///          compiler vectorises, and sums are taken over `LANES` interleaved partial sums. The
///          order of every addition is fixed by the list, so results are the same at any thread
///          count.
///
///          In a float build with AVX2 the sums run in one register a component, with the
///          neighbours' values gathered into it: GCC vectorised the lane loops with shuffles
///          and spilled the lanes to the stack, and the solve passes spent most of their time
///          there. Each lane adds the same terms in the same order as the scalar loops, so
///          both give the same bits (bench/history/diary-2026-11.md, "Pair sums in AVX2
///          registers").
///
///          Use (forEachBatch walks a list batch by batch):
///          @code
///          PairBatch batch;
///          Real rho = 0;
///          batch.forEachBatch(xi, x, list, [&](PairBatch& b) {
///              for (int k = 0; k < b.n; ++k) b.f[k] = m[b.j[k]];         // gathers
///              for (int k = 0; k < b.n; ++k) b.f[k] *= kernel.W(b.r[k]); // vectorised
///              rho += b.sum(b.f);
///          });
///          @endcode
///          Copy the kernel into a local first: its constants then stay in registers.
#pragma once

#include "ghostfx/sph/Types.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#if defined(__AVX2__)
#include <immintrin.h>
#endif
#include <iterator>
#include <type_traits>
#include <utility>

/// The pair sums in AVX2 registers: float builds for AVX2 processors (see the file comment).
#if defined(__AVX2__) && !defined(GHOSTFX_DOUBLE)
#define GHOSTFX_PAIR_SUMS_AVX2 1
#else
#define GHOSTFX_PAIR_SUMS_AVX2 0
#endif

namespace ghostfx {
namespace sph {

/// Whether List is read run by run (NeighborLists::List::forEachRun).
template <typename List, typename = void>
struct HasRuns : std::false_type
{};
template <typename List>
struct HasRuns<List, std::void_t<decltype(std::declval<const List&>().bytes())>> : std::true_type
{};

struct PairBatch
{
    static constexpr int SIZE = 64; ///< pairs per batch
    static constexpr int LANES = 8; ///< interleaved partial sums
    static_assert(SIZE % LANES == 0, "a batch's arrays hold whole groups of LANES");

    /// Run entries decoded at a time (NeighborLists::List::READ_PAST bytes may be read past a
    /// list).
    static constexpr int BLOCK = 32;
    /// Neighbours of a list decoded at once (longer lists are decoded batch by batch).
    static constexpr int CAPACITY = 1024;

    int n = 0;                         ///< pairs in this batch
    Index j[SIZE + BLOCK];             ///< neighbour indices (room for a block past SIZE)
    Real dx[SIZE], dy[SIZE], dz[SIZE]; ///< x_i - x_j (m)
    Real r[SIZE];                      ///< |x_i - x_j| (m)
    Real f[SIZE];                      ///< scratch for the caller's per-pair factor
    Real g[SIZE];                      ///< second scratch array
    Index decoded[CAPACITY + BLOCK];   ///< a list's indices, decoded (room for a block past)

    /// Load up to SIZE neighbours `idx[0..count)` of the particle at xi; returns how many.
    int load(const Vec3& xi, const Vec3* x, const Index* idx, std::size_t count)
    {
        // Copied into the batch's own array (as every caller's loops were written and
        // measured against), not pointed to: a batch's indices are then known to be apart
        // from f[] and g[], which the callers write while reading j[].
        n = int(std::min<std::size_t>(count, SIZE));
        std::copy(idx, idx + n, j);
        gather(xi, x);
        return n;
    }

    /// Call fn(*this) for each batch of SIZE consecutive neighbours of the particle at xi (the
    /// last batch may be shorter). `list` is a NeighborLists::List or a contiguous range of
    /// Index (std::data, size()).
    template <typename List, typename Fn>
    void forEachBatch(const Vec3& xi, const Vec3* x, const List& list, Fn&& fn)
    {
        if constexpr (HasRuns<List>::value) {
            const std::size_t size = list.size();
            if (list.raw() || size > std::size_t(CAPACITY)) {
                forEachRareBatch(xi, x, list, fn);
                return;
            }
            // The whole list at once, then the batches over it. The batches hold SIZE
            // neighbours whatever the runs, so sums do not depend on how the list is stored.
            // The rare kinds and the decoding stay out of line: this loop is inlined into
            // every pass, and a larger one kept the passes' bodies from being inlined into
            // their tasks (DFSPH's solves lost their vectorised kernel loops and took 50 %
            // longer).
            decodeRuns(list);
            for (std::size_t k0 = 0; k0 < size; k0 += SIZE) {
                load(xi, x, decoded + k0, size - k0);
                fn(*this);
            }
        } else {
            const Index* idx = std::data(list);
            const std::size_t size = std::size(list);
            for (std::size_t k0 = 0; k0 < size; k0 += SIZE) {
                load(xi, x, idx + k0, size - k0);
                fn(*this);
            }
        }
    }

    /// Call fn(*this, first) for each batch of SIZE consecutive neighbours of a list, with
    /// j[0, n) the list's entries first .. first + n and nothing gathered (dx, dy, dz and r
    /// are not set): for passes that read per-pair values stored in the list's order.
    template <typename List, typename Fn>
    void forEachIndexBatch(const List& list, Fn&& fn)
    {
        const std::size_t size = std::size(list);
        if constexpr (HasRuns<List>::value) {
            if (list.raw() || size > std::size_t(CAPACITY)) {
                forEachRareBatch(Vec3(0), nullptr, list, fn);
                return;
            }
            decodeRuns(list);
            for (std::size_t k0 = 0; k0 < size; k0 += SIZE) {
                n = int(std::min<std::size_t>(size - k0, SIZE));
                std::copy(decoded + k0, decoded + k0 + n, j);
                fn(*this, k0);
            }
        } else {
            const Index* idx = std::data(list);
            for (std::size_t k0 = 0; k0 < size; k0 += SIZE) {
                n = int(std::min<std::size_t>(size - k0, SIZE));
                std::copy(idx + k0, idx + k0 + n, j);
                fn(*this, k0);
            }
        }
    }

    /// decoded[0, list.size()) = the neighbours of a list kept in runs (at most CAPACITY).
    template <typename List>
    __attribute__((noinline)) void decodeRuns(const List& list)
    {
        Index* to = decoded;
        list.forEachRun([&](Index start, const std::uint8_t* offset, std::size_t count) {
            for (std::size_t k = 0; k < count; k += BLOCK) decode(start, offset + k, to + k);
            to += count;
        });
    }

    /// forEachBatch over a list of 32-bit indices, or one longer than CAPACITY (decoded batch
    /// by batch); for forEachIndexBatch's fn(*this, first), the same without the gather.
    template <typename List, typename Fn>
    __attribute__((noinline)) void forEachRareBatch(const Vec3& xi, const Vec3* x, const List& list,
                                                    Fn& fn)
    {
        std::size_t first = 0;
        auto call = [&] {
            if constexpr (std::is_invocable_v<Fn&, PairBatch&>) {
                gather(xi, x);
                fn(*this);
            } else {
                fn(*this, first);
            }
            first += std::size_t(n);
        };
        if (const std::uint8_t* raw = list.raw()) {
            const std::size_t size = list.size();
            for (std::size_t k0 = 0; k0 < size; k0 += SIZE) {
                n = int(std::min<std::size_t>(size - k0, SIZE));
                std::memcpy(j, raw + k0 * sizeof(Index), std::size_t(n) * sizeof(Index));
                call();
            }
            return;
        }
        n = 0;
        list.forEachRun([&](Index start, const std::uint8_t* offset, std::size_t count) {
            for (;;) {
                const int take = int(std::min<std::size_t>(count, std::size_t(SIZE - n)));
                for (int k0 = 0; k0 < take; k0 += BLOCK) decode(start, offset + k0, j + n + k0);
                n += take;
                if (n < SIZE) return;
                call();
                n = 0;
                count -= std::size_t(take);
                if (count == 0) return;
                offset += take;
            }
        });
        if (n > 0) call();
    }

    /// to[k] = start | offset[k] for k < BLOCK.
    static void decode(Index start, const std::uint8_t* offset, Index* to)
    {
#if defined(__AVX2__)
        const __m256i s = _mm256_set1_epi32(std::int32_t(start));
        for (int k = 0; k < BLOCK; k += 8) {
            const __m128i bytes = _mm_loadl_epi64(reinterpret_cast<const __m128i*>(offset + k));
            const __m256i wide = _mm256_or_si256(_mm256_cvtepu8_epi32(bytes), s);
            _mm256_storeu_si256(reinterpret_cast<__m256i*>(to + k), wide);
        }
#else
        for (int k = 0; k < BLOCK; ++k) to[k] = start | offset[k];
#endif
    }

#if GHOSTFX_PAIR_SUMS_AVX2
    /// Lanes [0, count) set, for the masked loads of a batch's last count < LANES terms.
    static __m256i tailMask(int count)
    {
        return _mm256_cmpgt_epi32(_mm256_set1_epi32(count),
                                  _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7));
    }

    /// The components of a vector, each in every lane.
    struct Lanes3
    {
        __m256 x, y, z;
    };
    static Lanes3 broadcast(const Vec3& v)
    {
        return {_mm256_set1_ps(v[0]), _mm256_set1_ps(v[1]), _mm256_set1_ps(v[2])};
    }

    /// fn(load, vx, vy, vz) for each group of LANES neighbours, with values[j[k + l]] gathered
    /// into the lanes and load(a) giving a[k + l] (the group's first neighbour k). In a last,
    /// partial group the lanes past the batch hold 0 in both, so the terms fn adds from them
    /// must be 0.
    template <typename Fn>
    void forEachLaneGroup(const Vec3* values, Fn&& fn) const
    {
        __m256 vx, vy, vz;
        int k = 0;
        for (; k + LANES <= n; k += LANES) {
            loadLanes(values, j + k, LANES, vx, vy, vz);
            fn([k](const float* a) { return _mm256_loadu_ps(a + k); }, vx, vy, vz);
        }
        if (k < n) {
            const __m256i m = tailMask(n - k);
            loadLanes(values, j + k, n - k, vx, vy, vz);
            fn([k, m](const float* a) { return _mm256_maskload_ps(a + k, m); }, vx, vy, vz);
        }
    }

    /// The components of values[idx[l]], l < count (<= LANES), in three registers (0 in the
    /// lanes from count on): each Vec3 read with an 8-byte and a 4-byte load, then the eight
    /// transposed. Measured cheaper than three vgatherdps a group on this project's machine
    /// (bench/history/diary-2026-11.md, "Pair sums in AVX2 registers").
    static void loadLanes(const Vec3* values, const Index* idx, int count, __m256& vx, __m256& vy,
                          __m256& vz)
    {
        auto one = [&](int l) {
            if (l >= count) return _mm_setzero_ps();
            const float* p = values[idx[l]].asPointer();
            const __m128 xy = _mm_castpd_ps(_mm_load_sd(reinterpret_cast<const double*>(p)));
            return _mm_insert_ps(xy, _mm_load_ss(p + 2), 0x20);
        };
        auto pair = [&](int l) {
            return _mm256_insertf128_ps(_mm256_castps128_ps256(one(l)), one(l + 4), 1);
        };
        const __m256 r0 = pair(0), r1 = pair(1), r2 = pair(2), r3 = pair(3);
        const __m256 t0 = _mm256_unpacklo_ps(r0, r1); // x0 x1 y0 y1 | x4 x5 y4 y5
        const __m256 t1 = _mm256_unpacklo_ps(r2, r3); // x2 x3 y2 y3 | x6 x7 y6 y7
        const __m256 t2 = _mm256_unpackhi_ps(r0, r1); // z0 z1 0 0 | z4 z5 0 0
        const __m256 t3 = _mm256_unpackhi_ps(r2, r3); // z2 z3 0 0 | z6 z7 0 0
        vx = _mm256_shuffle_ps(t0, t1, _MM_SHUFFLE(1, 0, 1, 0));
        vy = _mm256_shuffle_ps(t0, t1, _MM_SHUFFLE(3, 2, 3, 2));
        vz = _mm256_shuffle_ps(t2, t3, _MM_SHUFFLE(1, 0, 1, 0));
    }

    /// (vi - v) . p lane by lane, in the scalar loops' order ((dx px + dy py) + dz pz).
    static __m256 approach(const Lanes3& vi, __m256 vx, __m256 vy, __m256 vz, __m256 px, __m256 py,
                           __m256 pz)
    {
        return _mm256_add_ps(_mm256_add_ps(_mm256_mul_ps(_mm256_sub_ps(vi.x, vx), px),
                                           _mm256_mul_ps(_mm256_sub_ps(vi.y, vy), py)),
                             _mm256_mul_ps(_mm256_sub_ps(vi.z, vz), pz));
    }

    /// The lanes' partial sums added in lane order from zero, as the scalar loops add theirs.
    static float reduceLanes(__m256 lanes)
    {
        alignas(32) float lane[LANES];
        _mm256_store_ps(lane, lanes);
        float total = 0;
        for (int l = 0; l < LANES; ++l) total += lane[l];
        return total;
    }
#endif

    /// sum_k term(k) over the batch in LANES interleaved partial sums, then the lanes added in
    /// order from zero: the order of every scalar sum here.
    template <typename Term>
    Real laneSum(Term&& term) const
    {
        Real lane[LANES] = {};
        int k = 0;
        for (; k + LANES <= n; k += LANES) {
            for (int l = 0; l < LANES; ++l) lane[l] += term(k + l);
        }
        // Fewer than LANES terms are left; `l < LANES` says so to the compiler, which otherwise
        // warns that lane[] could be overrun where it cannot bound n.
        for (int l = 0; l < LANES && k < n; ++k, ++l) lane[l] += term(k);
        Real total = 0;
        for (int l = 0; l < LANES; ++l) total += lane[l];
        return total;
    }

    /// laneSum of a vector term, each component in partial sums of its own.
    template <typename Term>
    Vec3 laneSum3(Term&& term) const
    {
        Real lx[LANES] = {}, ly[LANES] = {}, lz[LANES] = {};
        auto add = [&](int l, const Vec3& t) {
            lx[l] += t[0];
            ly[l] += t[1];
            lz[l] += t[2];
        };
        int k = 0;
        for (; k + LANES <= n; k += LANES) {
            for (int l = 0; l < LANES; ++l) add(l, term(k + l));
        }
        for (int l = 0; l < LANES && k < n; ++k, ++l) add(l, term(k));
        Vec3 total(0);
        for (int l = 0; l < LANES; ++l) total += Vec3(lx[l], ly[l], lz[l]);
        return total;
    }

    /// x_i - x_j and r for the n indices in j[].
    void gather(const Vec3& xi, const Vec3* x)
    {
#if GHOSTFX_PAIR_SUMS_AVX2
        // Eight neighbours at a time (the arrays hold SIZE, a multiple of LANES, so the last
        // group's stores stay inside them; entries past n are not read).
        const Lanes3 i = broadcast(xi);
        for (int k = 0; k < n; k += LANES) {
            __m256 vx, vy, vz;
            loadLanes(x, j + k, std::min(LANES, n - k), vx, vy, vz);
            const __m256 ox = _mm256_sub_ps(i.x, vx), oy = _mm256_sub_ps(i.y, vy),
                         oz = _mm256_sub_ps(i.z, vz);
            _mm256_storeu_ps(dx + k, ox);
            _mm256_storeu_ps(dy + k, oy);
            _mm256_storeu_ps(dz + k, oz);
            _mm256_storeu_ps(r + k, _mm256_sqrt_ps(_mm256_add_ps(
                                        _mm256_add_ps(_mm256_mul_ps(ox, ox), _mm256_mul_ps(oy, oy)),
                                        _mm256_mul_ps(oz, oz))));
        }
#else
        for (int k = 0; k < n; ++k) {
            const Index q = j[k];
            dx[k] = xi[0] - x[q][0];
            dy[k] = xi[1] - x[q][1];
            dz[k] = xi[2] - x[q][2];
        }
        for (int k = 0; k < n; ++k) r[k] = std::sqrt(dx[k] * dx[k] + dy[k] * dy[k] + dz[k] * dz[k]);
#endif
    }

    /// sum_k a[k] over the batch, in LANES interleaved partial sums (fixed order).
    Real sum(const Real* a) const
    {
#if GHOSTFX_PAIR_SUMS_AVX2
        __m256 acc = _mm256_setzero_ps();
        int k = 0;
        for (; k + LANES <= n; k += LANES) acc = _mm256_add_ps(acc, _mm256_loadu_ps(a + k));
        if (k < n) acc = _mm256_add_ps(acc, _mm256_maskload_ps(a + k, tailMask(n - k)));
        return reduceLanes(acc);
#else
        return laneSum([a](int k) { return a[k]; });
#endif
    }

    /// sum_k a[k] (values[j[k]] - vi) over the batch, each component as in sum().
    Vec3 sumScaledDifferences(const Real* a, const Vec3* values, const Vec3& vi) const
    {
#if GHOSTFX_PAIR_SUMS_AVX2
        const Lanes3 i = broadcast(vi);
        __m256 lx = _mm256_setzero_ps(), ly = lx, lz = lx;
        forEachLaneGroup(values, [&](auto load, __m256 vx, __m256 vy, __m256 vz) {
            const __m256 w = load(a);
            lx = _mm256_add_ps(lx, _mm256_mul_ps(w, _mm256_sub_ps(vx, i.x)));
            ly = _mm256_add_ps(ly, _mm256_mul_ps(w, _mm256_sub_ps(vy, i.y)));
            lz = _mm256_add_ps(lz, _mm256_mul_ps(w, _mm256_sub_ps(vz, i.z)));
        });
        return Vec3(reduceLanes(lx), reduceLanes(ly), reduceLanes(lz));
#else
        return laneSum3([&](int k) {
            const Vec3& v = values[j[k]];
            return Vec3(a[k] * (v[0] - vi[0]), a[k] * (v[1] - vi[1]), a[k] * (v[2] - vi[2]));
        });
#endif
    }

    /// sum_k a[k] (vi - values[j[k]]) . (x_i - x_j) over the batch, as in sum(): with a[k] =
    /// m_j gradFactor(r), the rate of density change sum_j m_j (v_i - v_j) . grad W_ij.
    Real sumScaledApproach(const Real* a, const Vec3* values, const Vec3& vi) const
    {
#if GHOSTFX_PAIR_SUMS_AVX2
        const Lanes3 i = broadcast(vi);
        __m256 acc = _mm256_setzero_ps();
        forEachLaneGroup(values, [&](auto load, __m256 vx, __m256 vy, __m256 vz) {
            const __m256 t = approach(i, vx, vy, vz, load(dx), load(dy), load(dz));
            acc = _mm256_add_ps(acc, _mm256_mul_ps(load(a), t));
        });
        return reduceLanes(acc);
#else
        return laneSum([&](int k) {
            const Vec3& v = values[j[k]];
            return a[k]
                   * ((vi[0] - v[0]) * dx[k] + (vi[1] - v[1]) * dy[k] + (vi[2] - v[2]) * dz[k]);
        });
#endif
    }

    /// sum_k a[k] (x_i - x_j) over the batch, each component as in sum().
    Vec3 sumScaledOffsets(const Real* a) const { return sumScaled(a, dx, dy, dz); }

    /// sum_k a[k] (x[k], y[k], z[k]) over the batch, each component as in sum().
    Vec3 sumScaled(const Real* a, const Real* x, const Real* y, const Real* z) const
    {
#if GHOSTFX_PAIR_SUMS_AVX2
        __m256 lx = _mm256_setzero_ps(), ly = lx, lz = lx;
        auto add = [&](__m256 w, __m256 vx, __m256 vy, __m256 vz) {
            lx = _mm256_add_ps(lx, _mm256_mul_ps(w, vx));
            ly = _mm256_add_ps(ly, _mm256_mul_ps(w, vy));
            lz = _mm256_add_ps(lz, _mm256_mul_ps(w, vz));
        };
        int k = 0;
        for (; k + LANES <= n; k += LANES) {
            add(_mm256_loadu_ps(a + k), _mm256_loadu_ps(x + k), _mm256_loadu_ps(y + k),
                _mm256_loadu_ps(z + k));
        }
        if (k < n) {
            const __m256i m = tailMask(n - k);
            add(_mm256_maskload_ps(a + k, m), _mm256_maskload_ps(x + k, m),
                _mm256_maskload_ps(y + k, m), _mm256_maskload_ps(z + k, m));
        }
        return Vec3(reduceLanes(lx), reduceLanes(ly), reduceLanes(lz));
#else
        return laneSum3([&](int k) { return Vec3(a[k] * x[k], a[k] * y[k], a[k] * z[k]); });
#endif
    }

    /// sum_k (vi - values[j[k]]) . (x[k], y[k], z[k]) over the batch, as in sum(): with the
    /// pair vectors m_j grad W_ij, the rate of density change sum_j m_j (v_i - v_j) . grad W_ij.
    Real sumApproach(const Vec3* values, const Vec3& vi, const Real* x, const Real* y,
                     const Real* z) const
    {
#if GHOSTFX_PAIR_SUMS_AVX2
        const Lanes3 i = broadcast(vi);
        __m256 acc = _mm256_setzero_ps();
        forEachLaneGroup(values, [&](auto load, __m256 vx, __m256 vy, __m256 vz) {
            acc = _mm256_add_ps(acc, approach(i, vx, vy, vz, load(x), load(y), load(z)));
        });
        return reduceLanes(acc);
#else
        return laneSum([&](int k) {
            const Vec3& v = values[j[k]];
            return (vi[0] - v[0]) * x[k] + (vi[1] - v[1]) * y[k] + (vi[2] - v[2]) * z[k];
        });
#endif
    }
};

} // namespace sph
} // namespace ghostfx
