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
///          of the build (within 1/64 plus 64 units): the lists are memory a step holds for
///          every particle, so they carry no room for a search's candidates and no growth left
///          from an earlier, busier step.
///
///          Storage: a list whose indices all lie within 65,536 of its smallest is kept as
///          16-bit offsets from that smallest index (the usual case for particles sorted by the
///          grid: neighbours are nearby in the sort order). A list that straddles a large step of
///          the sort order (its neighbours in two places of it, 32,768 indices wide each) is
///          kept as 15-bit offsets from one of two bases, the top bit choosing which; any other
///          as 32-bit indices. Reading a short list adds the offset to its base as it loads;
///          bench/RESULTS.md ("Neighbour lists in 16 bits", "two bases") has the memory and the
///          cost.
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

    /// A list: the neighbours of one query, either 16-bit offsets from a base index or
    /// 32-bit indices. Read it with forEach, PairBatch::forEachBatch, or begin()/end().
    class List
    {
    public:
        /// A forward iterator over the neighbour indices. Branch-free for both kinds of list:
        /// it reads 4 bytes at each entry and keeps the low 16 bits (adding the base) or all
        /// 32 (the storage keeps 2 readable bytes past every list).
        class Iterator
        {
        public:
            using iterator_category = std::forward_iterator_tag;
            using value_type = Index;
            using difference_type = std::ptrdiff_t;
            using pointer = const Index*;
            using reference = Index;

            Index operator*() const
            {
                std::uint32_t bits;
                std::memcpy(&bits, mAt, sizeof(bits));
                return ((bits & mSelect) ? mBase2 : mBase) + (bits & mMask);
            }
            Iterator& operator++()
            {
                mAt += mStride;
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
            const unsigned char* mAt = nullptr;
            std::size_t mStride = 0;
            std::uint32_t mMask = 0;
            std::uint32_t mSelect = 0; ///< the bit that chooses mBase2 (two-base lists)
            Index mBase = 0, mBase2 = 0;
        };

        Iterator begin() const { return at(0); }
        Iterator end() const { return at(mSize); }
        std::size_t size() const { return mSize; }
        bool empty() const { return mSize == 0; }

        /// 32-bit indices (null for a 16-bit list).
        const Index* wide() const { return mWide; }
        /// 16-bit offsets from base() (null for a 32-bit list); in a two-base list (split()),
        /// 15-bit offsets from base(), or from base2() where the top bit is set.
        const std::uint16_t* narrow() const { return mNarrow; }
        /// The index that narrow() offsets are added to.
        Index base() const { return mBase; }
        /// Whether the list has two bases (SPLIT_BIT of an offset: base2()).
        bool split() const { return mSplit; }
        Index base2() const { return mBase2; }
        /// The offset bit of a two-base list that chooses base2().
        static constexpr std::uint16_t SPLIT_BIT = 0x8000;

        /// Call fn(j) for each neighbour j in order (one loop per kind of list: faster than the
        /// iterator in hot loops).
        template <typename Fn>
        void forEach(Fn&& fn) const
        {
            if (mWide) {
                for (std::size_t k = 0; k < mSize; ++k) fn(mWide[k]);
            } else if (mSplit) {
                for (std::size_t k = 0; k < mSize; ++k) {
                    const std::uint32_t e = mNarrow[k];
                    fn(Index(((e & SPLIT_BIT) ? mBase2 : mBase) + (e & (SPLIT_BIT - 1u))));
                }
            } else {
                for (std::size_t k = 0; k < mSize; ++k) fn(Index(mBase + mNarrow[k]));
            }
        }

    private:
        friend class NeighborLists;
        Iterator at(std::size_t k) const
        {
            Iterator it;
            if (mWide) {
                it.mAt = reinterpret_cast<const unsigned char*>(mWide + k);
                it.mStride = sizeof(Index);
                it.mMask = ~std::uint32_t(0);
            } else {
                it.mAt = reinterpret_cast<const unsigned char*>(mNarrow + k);
                it.mStride = sizeof(std::uint16_t);
                it.mMask = mSplit ? SPLIT_BIT - 1u : 0xffffu;
                it.mSelect = mSplit ? SPLIT_BIT : 0u;
                it.mBase = mBase;
                it.mBase2 = mBase2;
            }
            return it;
        }

        const std::uint16_t* mNarrow = nullptr;
        const Index* mWide = nullptr;
        Index mBase = 0, mBase2 = 0;
        bool mSplit = false;
        std::size_t mSize = 0;
    };

    /// Build the lists of the particles of `targets` closer than `radius` (m, at most the
    /// grid's cell size) to each of `count` query points. Queries with `wanted[q] == 0` get an
    /// empty list (`wanted` may be null: every query is wanted). Sorted queries run fastest.
    /// `queryRadius` (optional, m): a smaller radius per query (capped at `radius`), for
    /// particles with their own support radius.
    void build(const NeighborGrid& targets, const Vec3* queries, std::size_t count, Real radius,
               const std::uint8_t* wanted = nullptr, const Real* queryRadius = nullptr);
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
        const std::uint16_t* units = chunk.units.get();
        const std::size_t k = q % CHUNK;
        // Every list starts at an even unit (4-byte aligned for 32-bit indices).
        const std::uint32_t from = k == 0 ? 0 : (chunk.ends[k - 1].end + 1) & ~1u;
        const End& e = chunk.ends[k];
        List list;
        if (e.base == WIDE) {
            list.mWide = reinterpret_cast<const Index*>(units + from);
            list.mSize = (e.end - from) / 2;
        } else if (e.base & SPLIT) {
            // The second base (two units), then the offsets.
            std::memcpy(&list.mBase2, units + from, sizeof(Index));
            list.mNarrow = units + from + 2;
            list.mBase = e.base & ~SPLIT;
            list.mSplit = true;
            list.mSize = e.end - from - 2;
        } else {
            list.mNarrow = units + from;
            list.mBase = e.base;
            list.mSize = e.end - from;
        }
        return list;
    }
    /// Use the AVX2 search where the processor has it (default), or always the portable one.
    /// Both give the same lists; this switch lets a test compare them.
    static void setWideSimd(bool enabled);
    static bool wideSimd();

    /// Total number of (query, neighbour) pairs.
    std::size_t pairCount() const;
    /// Number of lists kept as 32-bit indices (the others are 16-bit offsets).
    std::size_t wideListCount() const;
    /// Number of lists kept as 15-bit offsets from two bases.
    std::size_t splitListCount() const;
    /// Bytes held (capacity).
    std::size_t memoryBytes() const;

private:
    /// build() and buildFor(): a query is wanted when `select` is null, or when select[q] is
    /// non-zero (`match` < 0) or equals `match`.
    void buildSelected(const NeighborGrid& targets, const Vec3* queries, std::size_t count,
                       Real radius, const std::uint8_t* select, int match,
                       const Real* queryRadius);
    /// `End::base` of a list of 32-bit indices.
    static constexpr Index WIDE = ~Index(0);
    /// Set in `End::base` (with its first base below) for a two-base list. Lists into more
    /// than 2^31 targets never have two bases.
    static constexpr Index SPLIT = Index(1) << 31;

    /// Per query: the end of its list within its chunk (units), and the base its 16-bit offsets
    /// are added to (WIDE: 32-bit indices).
    struct End
    {
        std::uint32_t end;
        Index base;
    };
    /// A chunk's lists, back to back in 16-bit units (grown by a sixteenth while it is filled
    /// and fitted to its lists at the end of the build), and the ends of its queries' lists.
    /// A chunk whose lists are all empty holds no ends: lists into a solid are empty for most
    /// liquid particles, and one vector of ends for every query (doubled by its growth) held
    /// 11.6 of the paper-size double dam break's 296 MB (bench/RESULTS.md, "Memory: the lists'
    /// ends").
    struct Chunk
    {
        std::unique_ptr<std::uint16_t[]> units;
        std::size_t capacity = 0;   ///< in units
        std::unique_ptr<End[]> ends; ///< CHUNK entries, or null: every list is empty
        /// Make room for `size` units, keeping the first `used`.
        void reserve(std::size_t size, std::size_t used);
        /// Give back room beyond `used` units (and a little slack).
        void shrink(std::size_t used);
    };

    std::size_t mSize = 0;      ///< queries of the last build
    std::vector<Chunk> mChunks; ///< empty when the last build had no targets
};

} // namespace sph
} // namespace ghostfx
