/// @file   PairBatch.h
/// @brief  A particle's neighbours taken in batches of arrays, so the kernel arithmetic of an
///         SPH pair sum runs on SIMD lanes.
/// @details A neighbour loop written pair by pair gathers x_j, computes r with a square root and
///          the kernel with a division, one pair at a time, and the three accumulators of a
///          vector sum form dependency chains: about 25 cycles per pair (bench/RESULTS.md,
///          "Liquid step"). Here the gathers fill small arrays first (xij components, r), the
///          arithmetic then runs over the arrays in loops the compiler vectorises, and sums
///          are taken over `LANES` interleaved partial sums. The order of every addition is
///          fixed by the list, so results are the same at any thread count.
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
#include <iterator>
#include <type_traits>
#include <utility>

namespace ghostfx {
namespace sph {

/// Whether List may hold 16-bit offsets (NeighborLists::List: narrow(), wide(), base()).
template <typename List, typename = void>
struct HasNarrow : std::false_type
{};
template <typename List>
struct HasNarrow<List, std::void_t<decltype(std::declval<const List&>().narrow())>> : std::true_type
{};

struct PairBatch
{
    static constexpr int SIZE = 64; ///< pairs per batch
    static constexpr int LANES = 8; ///< interleaved partial sums

    int n = 0;                         ///< pairs in this batch
    Index j[SIZE];                     ///< neighbour indices
    Real dx[SIZE], dy[SIZE], dz[SIZE]; ///< x_i - x_j (m)
    Real r[SIZE];                      ///< |x_i - x_j| (m)
    Real f[SIZE];                      ///< scratch for the caller's per-pair factor
    Real g[SIZE];                      ///< second scratch array

    /// Load up to SIZE neighbours `idx[0..count)` of the particle at xi; returns how many.
    int load(const Vec3& xi, const Vec3* x, const Index* idx, std::size_t count)
    {
        return loadEach(xi, x, count, [idx](int k) { return idx[k]; });
    }

    /// Load up to SIZE neighbours `base + offset[0..count)` of the particle at xi (a 16-bit
    /// NeighborLists list); returns how many.
    int load(const Vec3& xi, const Vec3* x, Index base, const std::uint16_t* offset,
             std::size_t count)
    {
        return loadEach(xi, x, count, [base, offset](int k) { return Index(base + offset[k]); });
    }

    /// Call fn(*this) for each batch of SIZE consecutive neighbours of the particle at xi (the
    /// last batch may be shorter). `list` is a NeighborLists::List (16-bit offsets or 32-bit
    /// indices) or a contiguous range of Index (std::data, size()).
    template <typename List, typename Fn>
    void forEachBatch(const Vec3& xi, const Vec3* x, const List& list, Fn&& fn)
    {
        const std::size_t size = list.size();
        const Index* wide = nullptr;
        if constexpr (HasNarrow<List>::value) {
            wide = list.wide();
            if (!wide) {
                const std::uint16_t* offset = list.narrow();
                const Index base = list.base();
                if (list.split()) {
                    forEachTwoBaseBatch(xi, x, list, fn); // rare: out of the hot loop
                    return;
                }
                for (std::size_t k0 = 0; k0 < size; k0 += SIZE) {
                    load(xi, x, base, offset + k0, size - k0);
                    fn(*this);
                }
                return;
            }
        } else {
            wide = std::data(list);
        }
        for (std::size_t k0 = 0; k0 < size; k0 += SIZE) {
            load(xi, x, wide + k0, size - k0);
            fn(*this);
        }
    }

    /// forEachBatch over a two-base list (List::split()): kept apart and not inlined, so the
    /// common 16-bit path stays as tight as it was.
    template <typename List, typename Fn>
    __attribute__((noinline)) void forEachTwoBaseBatch(const Vec3& xi, const Vec3* x,
                                                       const List& list, Fn& fn)
    {
        const std::size_t size = list.size();
        const std::uint16_t* offset = list.narrow();
        const Index base = list.base(), base2 = list.base2();
        constexpr std::uint32_t select = List::SPLIT_BIT, mask = List::SPLIT_BIT - 1u;
        for (std::size_t k0 = 0; k0 < size; k0 += SIZE) {
            const std::uint16_t* at = offset + k0;
            loadEach(xi, x, size - k0, [base, base2, at](int k) {
                const std::uint32_t e = at[k];
                return Index(((e & select) ? base2 : base) + (e & mask));
            });
            fn(*this);
        }
    }

    /// Load neighbours indexOf(0..min(count, SIZE)) of the particle at xi.
    template <typename IndexOf>
    int loadEach(const Vec3& xi, const Vec3* x, std::size_t count, IndexOf indexOf)
    {
        n = int(std::min<std::size_t>(count, SIZE));
        for (int k = 0; k < n; ++k) {
            const Index q = indexOf(k);
            j[k] = q;
            dx[k] = xi[0] - x[q][0];
            dy[k] = xi[1] - x[q][1];
            dz[k] = xi[2] - x[q][2];
        }
        for (int k = 0; k < n; ++k) r[k] = std::sqrt(dx[k] * dx[k] + dy[k] * dy[k] + dz[k] * dz[k]);
        return n;
    }

    /// sum_k a[k] over the batch, in LANES interleaved partial sums (fixed order).
    Real sum(const Real* a) const
    {
        Real lane[LANES] = {};
        int k = 0;
        for (; k + LANES <= n; k += LANES) {
            for (int l = 0; l < LANES; ++l) lane[l] += a[k + l];
        }
        for (int l = 0; k < n; ++k, ++l) lane[l] += a[k];
        Real total = 0;
        for (int l = 0; l < LANES; ++l) total += lane[l];
        return total;
    }

    /// sum_k a[k] (values[j[k]] - vi) over the batch, each component as in sum().
    Vec3 sumScaledDifferences(const Real* a, const Vec3* values, const Vec3& vi) const
    {
        Real lx[LANES] = {}, ly[LANES] = {}, lz[LANES] = {};
        int k = 0;
        for (; k + LANES <= n; k += LANES) {
            for (int l = 0; l < LANES; ++l) {
                const Vec3& v = values[j[k + l]];
                lx[l] += a[k + l] * (v[0] - vi[0]);
                ly[l] += a[k + l] * (v[1] - vi[1]);
                lz[l] += a[k + l] * (v[2] - vi[2]);
            }
        }
        for (int l = 0; k < n; ++k, ++l) {
            const Vec3& v = values[j[k]];
            lx[l] += a[k] * (v[0] - vi[0]);
            ly[l] += a[k] * (v[1] - vi[1]);
            lz[l] += a[k] * (v[2] - vi[2]);
        }
        Vec3 total(0);
        for (int l = 0; l < LANES; ++l) total += Vec3(lx[l], ly[l], lz[l]);
        return total;
    }

    /// sum_k a[k] (vi - values[j[k]]) . (x_i - x_j) over the batch, as in sum(): with a[k] =
    /// m_j gradFactor(r), the rate of density change sum_j m_j (v_i - v_j) . grad W_ij.
    Real sumScaledApproach(const Real* a, const Vec3* values, const Vec3& vi) const
    {
        Real lane[LANES] = {};
        int k = 0;
        for (; k + LANES <= n; k += LANES) {
            for (int l = 0; l < LANES; ++l) {
                const Vec3& v = values[j[k + l]];
                lane[l] += a[k + l]
                           * ((vi[0] - v[0]) * dx[k + l] + (vi[1] - v[1]) * dy[k + l]
                              + (vi[2] - v[2]) * dz[k + l]);
            }
        }
        for (int l = 0; k < n; ++k, ++l) {
            const Vec3& v = values[j[k]];
            lane[l] +=
                a[k] * ((vi[0] - v[0]) * dx[k] + (vi[1] - v[1]) * dy[k] + (vi[2] - v[2]) * dz[k]);
        }
        Real total = 0;
        for (int l = 0; l < LANES; ++l) total += lane[l];
        return total;
    }

    /// sum_k a[k] (x_i - x_j) over the batch, each component as in sum().
    Vec3 sumScaledOffsets(const Real* a) const
    {
        Real lx[LANES] = {}, ly[LANES] = {}, lz[LANES] = {};
        int k = 0;
        for (; k + LANES <= n; k += LANES) {
            for (int l = 0; l < LANES; ++l) {
                lx[l] += a[k + l] * dx[k + l];
                ly[l] += a[k + l] * dy[k + l];
                lz[l] += a[k + l] * dz[k + l];
            }
        }
        for (int l = 0; k < n; ++k, ++l) {
            lx[l] += a[k] * dx[k];
            ly[l] += a[k] * dy[k];
            lz[l] += a[k] * dz[k];
        }
        Vec3 total(0);
        for (int l = 0; l < LANES; ++l) total += Vec3(lx[l], ly[l], lz[l]);
        return total;
    }
};

} // namespace sph
} // namespace ghostfx
