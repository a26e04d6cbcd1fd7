/// @file   NeighborLists.h
/// @brief  Compact neighbour lists: one search per step, reused by every pass of the step.
/// @details A solver step sums over the same neighbourhoods several times ([SB12] Algorithm 3:
///          density, pressure force, XSPH). Searching the grid in each pass tests six to eight
///          candidates per neighbour every time; here the search runs once and every later pass
///          streams through a list of indices.
///
///          The search visits the query points in order and caches the slot ranges of the 27
///          cells around the current cell, so sorted queries (particles sorted by the same grid)
///          look cells up once per cell, not once per particle. Per query it skips the cells
///          that the query's support ball cannot reach (about a quarter of the 27) and filters
///          each remaining range with a branch-free distance test over the grid's coordinate
///          arrays.
///
///          Lists live in fixed chunks of queries, each filled by one task, so building needs no
///          second counting pass and no copy, and the result does not depend on the thread
///          count: list q holds the target indices in a fixed order (cells in stencil order,
///          slots ascending). A query is its own neighbour when it is in the target grid.
///          A task gathers each query's hits as 32-bit entries in a buffer of its own and writes
///          the list in its final form to its chunk, which is fitted to what it holds at the end
///          of the build (within 1/64 plus 96 bytes, 32 of them readable past the last list):
///          the lists are memory a step holds for every particle, so they carry no room for a
///          search's candidates and no growth left from an earlier, busier step.
///
///          Storage: a query's neighbours, in list order, fall into runs that lie in one window
///          of 256 target indices (the window k holds indices 256 k to 256 k + 255). A list
///          holds its run count (16 bits), a header per run (the window, 16 bits from the list's
///          first window, and the run's length less one) and then one byte per neighbour, its
///          index within its window. For particles sorted by the grid a query's neighbours lie
///          in a few windows: about 1.3 bytes per neighbour, where 16-bit offsets took 2 and
///          32-bit indices 4. A list whose windows span more than 65,536, or that runs would
///          make larger (unsorted targets), is kept as 32-bit indices (raw()). The entries are
///          written and read by loops the compiler vectorises; bench/history/diary-2026-11.md
///          ("Neighbour lists in windows of 256") has the memory and the cost.
#pragma once

#include "ghostfx/sph/NeighborGrid.h"
#include "ghostfx/sph/Types.h"

#include <cstdint>
#include <cstring>
#include <memory>
#include <vector>

namespace ghostfx {
namespace sph {

class NeighborLists
{
public:
    /// Queries per chunk (a chunk is filled by one task).
    static constexpr std::size_t CHUNK = 256;

    /// A list: the neighbours of one query. Read it with forEach, PairBatch::forEachBatch, or
    /// begin()/end(); every reader gives the neighbours in the same order.
    class List
    {
    public:
        /// Bytes that may be read past a list's end (NeighborLists keeps them readable), so a
        /// run's entries can be read in blocks of this many.
        static constexpr std::size_t READ_PAST = 32;

        /// A forward iterator over the neighbour indices.
        class Iterator
        {
        public:
            using iterator_category = std::forward_iterator_tag;
            using value_type = Index;
            using difference_type = std::ptrdiff_t;
            using pointer = const Index*;
            using reference = Index;

            Index operator*() const { return mRaw ? load32(mAt) : Index(mStart | *mAt); }
            Iterator& operator++()
            {
                if (mRaw) {
                    mAt += sizeof(Index);
                } else if (++mAt != mEnd && --mLeft == 0) {
                    enterRun();
                }
                return *this;
            }
            Iterator operator++(int)
            {
                Iterator before = *this;
                ++*this;
                return before;
            }
            bool operator==(const Iterator& o) const { return mAt == o.mAt; }
            bool operator!=(const Iterator& o) const { return mAt != o.mAt; }

        private:
            friend class List;
            void enterRun()
            {
                mStart = windowStart(mHeader, mWindow);
                mLeft = runLength(mHeader);
                mHeader += HEADER;
            }
            const std::uint8_t* mAt = nullptr;     ///< the current entry
            const std::uint8_t* mEnd = nullptr;    ///< past the last entry
            const std::uint8_t* mHeader = nullptr; ///< the next run's header
            Index mWindow = 0, mStart = 0;
            std::size_t mLeft = 0; ///< entries left in the current run
            bool mRaw = false;
        };

        Iterator begin() const
        {
            Iterator it = end();
            if (mRaw) {
                it.mAt = mAt;
            } else if (mAt != mEnd) {
                it.mHeader = mAt + COUNT;
                it.mAt = entries();
                it.enterRun();
            }
            return it;
        }
        Iterator end() const
        {
            Iterator it;
            it.mAt = it.mEnd = mEnd;
            it.mWindow = mWindow;
            it.mRaw = mRaw;
            return it;
        }
        /// Number of neighbours.
        std::size_t size() const
        {
            if (mRaw) return std::size_t(mEnd - mAt) / sizeof(Index);
            return mAt == mEnd ? 0 : std::size_t(mEnd - entries());
        }
        bool empty() const { return mAt == mEnd; }
        /// The list's 32-bit indices (possibly unaligned: read with memcpy), or null for a
        /// list kept in runs.
        const std::uint8_t* raw() const { return mRaw ? mAt : nullptr; }
        /// Bytes the list takes.
        std::size_t bytes() const { return std::size_t(mEnd - mAt); }
        /// Number of runs (0 for a raw list).
        std::size_t runs() const { return mRaw || mAt == mEnd ? 0 : runCount(); }

        /// Call fn(start, offsets, count) for each run of a list kept in runs, in order: its
        /// neighbours are start + offsets[k] for k < count (1 to 256); offsets may be read up
        /// to READ_PAST bytes past count.
        template <typename Fn>
        void forEachRun(Fn&& fn) const
        {
            if (mAt == mEnd) return;
            const std::uint8_t* header = mAt + COUNT;
            const std::uint8_t* entry = entries();
            for (const std::uint8_t* last = entry; header != last; header += HEADER) {
                const std::size_t count = runLength(header);
                fn(windowStart(header, mWindow), entry, count);
                entry += count;
            }
        }
        /// Call fn(j) for each neighbour j in order.
        template <typename Fn>
        void forEach(Fn&& fn) const
        {
            if (mRaw) {
                for (const std::uint8_t* at = mAt; at != mEnd; at += sizeof(Index)) fn(load32(at));
                return;
            }
            forEachRun([&fn](Index start, const std::uint8_t* offset, std::size_t count) {
                for (std::size_t k = 0; k < count; ++k) fn(Index(start | offset[k]));
            });
        }

    private:
        friend class NeighborLists;
        static constexpr std::size_t COUNT = 2;  ///< bytes of the run count
        static constexpr std::size_t HEADER = 3; ///< bytes of a run header
        static Index load32(const std::uint8_t* at)
        {
            Index v;
            std::memcpy(&v, at, sizeof(v));
            return v;
        }
        static Index windowStart(const std::uint8_t* header, Index firstWindow)
        {
            std::uint16_t w;
            std::memcpy(&w, header, sizeof(w));
            return (firstWindow + w) << 8;
        }
        static std::size_t runLength(const std::uint8_t* header)
        {
            return std::size_t(header[2]) + 1;
        }
        std::size_t runCount() const
        {
            std::uint16_t n;
            std::memcpy(&n, mAt, sizeof(n));
            return n;
        }
        const std::uint8_t* entries() const { return mAt + COUNT + HEADER * runCount(); }

        const std::uint8_t* mAt = nullptr;  ///< the list's first byte
        const std::uint8_t* mEnd = nullptr; ///< past its last
        Index mWindow = 0;                  ///< the first window (runs)
        bool mRaw = false;
    };

    /// Build the lists of the particles of `targets` closer than `radius` (m, at most the
    /// grid's cell size) to each of `count` query points. Queries with `wanted[q] == 0` get an
    /// empty list (`wanted` may be null: every query is wanted). Sorted queries run fastest.
    /// `supports` (optional, m): for particles with their own support radius h, where the
    /// queries are the targets' own particles (query q is particle q of the set the grid was
    /// built over): query q lists target t only when it lies within their pair support
    /// (h_q + h_t) / 2 (with `radius` at least every h), give or take 1e-4 of it, so a pass
    /// that tests the pair support itself sees every pair it would have seen in a list of the
    /// whole radius, in the same order.
    void build(const NeighborGrid& targets, const Vec3* queries, std::size_t count, Real radius,
               const std::uint8_t* wanted = nullptr, const Real* supports = nullptr);
    /// The same for the queries whose byte `tags[q]` equals `tag`, e.g. the liquid particles of
    /// a set that holds liquid and air, chosen by its kind channel with no mask of their own.
    void buildFor(const NeighborGrid& targets, const Vec3* queries, std::size_t count,
                  Real radius, const std::uint8_t* tags, std::uint8_t tag);

    /// Number of query points of the last build.
    std::size_t size() const { return mSize; }
    /// The neighbours of query q.
    List operator[](std::size_t q) const
    {
        if (mChunks.empty()) return List(); // no targets: every list is empty
        const Chunk& chunk = mChunks[q / CHUNK];
        if (!chunk.ends) return List(); // every list of the chunk is empty
        const std::size_t k = q % CHUNK;
        const std::uint8_t* bytes = chunk.bytes.get();
        const End& e = chunk.ends[k];
        List list;
        list.mAt = bytes + (k == 0 ? 0 : chunk.ends[k - 1].end);
        list.mEnd = bytes + e.end;
        list.mRaw = e.window == RAW;
        list.mWindow = list.mRaw ? 0 : e.window;
        return list;
    }
    /// Use the AVX2 search where the processor has it (default), or always the portable one.
    /// Both give the same lists; this switch lets a test compare them.
    static void setWideSimd(bool enabled);
    static bool wideSimd();

    /// Total number of (query, neighbour) pairs.
    std::size_t pairCount() const;
    /// Number of lists kept as 32-bit indices (List::raw()).
    std::size_t rawListCount() const;
    /// Number of runs (windows) over all lists.
    std::size_t runCount() const;
    /// Bytes held (capacity).
    std::size_t memoryBytes() const;

private:
    /// build() and buildFor(): a query is wanted when `select` is null, or when select[q] is
    /// non-zero (`match` < 0) or equals `match`.
    void buildSelected(const NeighborGrid& targets, const Vec3* queries, std::size_t count,
                       Real radius, const std::uint8_t* select, int match,
                       const Real* supports);
    /// `End::window` of a list kept as 32-bit indices.
    static constexpr Index RAW = ~Index(0);
    /// Searches the queries of one chunk and writes their lists (NeighborLists.cc).
    class ChunkBuilder;

    /// Per query: the end of its list within its chunk (bytes), and the window its runs'
    /// windows count from (RAW: 32-bit indices).
    struct End
    {
        std::uint32_t end;
        Index window;
    };
    /// A chunk's lists, back to back (grown by a sixteenth while it is filled and fitted to
    /// its lists at the end of the build), and the ends of its queries' lists. A chunk whose
    /// lists are all empty holds no ends: lists into a solid are empty for most liquid
    /// particles, and one vector of ends for every query (doubled by its growth) held 11.6 of
    /// the paper-size double dam break's 296 MB (bench/history/diary-2026-11.md, "Memory: the
    /// lists' ends").
    struct Chunk
    {
        std::unique_ptr<std::uint8_t[]> bytes;
        std::size_t capacity = 0;    ///< in bytes
        std::unique_ptr<End[]> ends; ///< CHUNK entries, or null: every list is empty
        /// Make room for `size` bytes, keeping the first `used`.
        void reserve(std::size_t size, std::size_t used);
        /// Give back room beyond `used` bytes (and a little slack).
        void shrink(std::size_t used);
    };

    std::size_t mSize = 0;      ///< queries of the last build
    std::vector<Chunk> mChunks; ///< empty when the last build had no targets
};

} // namespace sph
} // namespace ghostfx
