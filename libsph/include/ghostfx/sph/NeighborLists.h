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
///          The storage keeps its capacity from step to step.
#pragma once

#include "ghostfx/sph/NeighborGrid.h"
#include "ghostfx/sph/Types.h"

#include <cstdint>
#include <memory>
#include <vector>

namespace ghostfx {
namespace sph {

class NeighborLists
{
public:
    /// Queries per chunk (a chunk is filled by one task).
    static constexpr std::size_t CHUNK = 256;

    /// A list: contiguous target indices.
    struct List
    {
        const Index* first = nullptr;
        const Index* last = nullptr;
        const Index* begin() const { return first; }
        const Index* end() const { return last; }
        std::size_t size() const { return std::size_t(last - first); }
        bool empty() const { return first == last; }
    };

    /// Build the lists of the particles of `targets` closer than `radius` (m, at most the
    /// grid's cell size) to each of `count` query points. Queries with `wanted[q] == 0` get an
    /// empty list (`wanted` may be null: every query is wanted). Sorted queries run fastest.
    /// `queryRadius` (optional, m): a smaller radius per query (capped at `radius`), for
    /// particles with their own support radius.
    void build(const NeighborGrid& targets, const Vec3* queries, std::size_t count, Real radius,
               const std::uint8_t* wanted = nullptr, const Real* queryRadius = nullptr);

    /// Number of query points of the last build.
    std::size_t size() const { return mEnd.size(); }
    /// The neighbours of query q.
    List operator[](std::size_t q) const
    {
        const Index* base = mChunks[q / CHUNK].data.get();
        const std::uint32_t first = q % CHUNK == 0 ? 0 : mEnd[q - 1];
        return {base + first, base + mEnd[q]};
    }
    /// Use the AVX2 search where the processor has it (default), or always the portable one.
    /// Both give the same lists; this switch lets a test compare them.
    static void setWideSimd(bool enabled);
    static bool wideSimd();

    /// Total number of (query, neighbour) pairs.
    std::size_t pairCount() const;
    /// Bytes held (capacity).
    std::size_t memoryBytes() const;

private:
    /// A chunk's lists, back to back; grows geometrically and keeps its capacity.
    struct Chunk
    {
        std::unique_ptr<Index[]> data;
        std::size_t capacity = 0;
        /// Make room for `size` entries, keeping the first `used`.
        void reserve(std::size_t size, std::size_t used);
        /// Give back room beyond `used` entries (and a little slack).
        void shrink(std::size_t used);
    };

    std::vector<std::uint32_t> mEnd; ///< per query: end of its list within its chunk
    std::vector<Chunk> mChunks;
};

} // namespace sph
} // namespace ghostfx
