/// @file   Parallel.h
/// @brief  The one way ghostfx code runs loops in parallel (TBB), with a serial switch and
///         explicit grain sizes.
/// @details Shapes, best first (STYLE.md rule 5): gather over destinations with `forEach` /
///          `forRange` (each iteration writes only what it owns); deterministic reductions with
///          `sum`, which adds fixed-size blocks in a fixed order so the result is the same at any
///          thread count. `setSerial(true)` (or GHOSTFX_SERIAL=1 in the environment) runs every
///          loop on the calling thread, for debugging. `ThreadLimit` caps the TBB worker count.
#pragma once

#include <tbb/blocked_range.h>
#include <tbb/global_control.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cstddef>
#include <memory>
#include <vector>

namespace ghostfx {
namespace parallel {

/// Iterations per task unless a loop says otherwise: large enough to amortise scheduling of
/// a cheap particle loop body (about 50 ns), small enough to balance 2 to 16 cores.
constexpr std::size_t DEFAULT_GRAIN = 256;

/// Run every loop serially on the calling thread (true) or with TBB (false, the default unless
/// the environment variable GHOSTFX_SERIAL is set to a non-zero value).
void setSerial(bool serial);
bool isSerial();

/// Caps the number of threads TBB may use while the object lives (RAII). 0 means no cap.
class ThreadLimit
{
public:
    explicit ThreadLimit(int maxThreads);
    ~ThreadLimit();
    ThreadLimit(const ThreadLimit&) = delete;
    ThreadLimit& operator=(const ThreadLimit&) = delete;

private:
    std::unique_ptr<tbb::global_control> mControl;
};

/// Number of threads a parallel loop may use right now.
int maxThreads();

/// Call `fn(begin, end)` on disjoint sub-ranges covering [begin, end). A grain of 0 means 1.
template <typename Fn>
void forRange(std::size_t begin, std::size_t end, Fn&& fn, std::size_t grain = DEFAULT_GRAIN)
{
    if (end <= begin) return;
    if (grain == 0) grain = 1; // tbb::blocked_range would split a grain-0 range forever
    if (isSerial() || end - begin <= grain) {
        fn(begin, end);
        return;
    }
    tbb::parallel_for(
        tbb::blocked_range<std::size_t>(begin, end, grain),
        [&fn](const tbb::blocked_range<std::size_t>& r) { fn(r.begin(), r.end()); },
        tbb::simple_partitioner());
}

/// Call `fn(i)` for every i in [begin, end).
template <typename Fn>
void forEach(std::size_t begin, std::size_t end, Fn&& fn, std::size_t grain = DEFAULT_GRAIN)
{
    forRange(
        begin, end,
        [&fn](std::size_t b, std::size_t e) {
        for (std::size_t i = b; i < e; ++i) fn(i);
        },
        grain);
}

/// Deterministic sum of `fn(i)` (converted to double) over [begin, end): blocks of `block`
/// iterations are summed in parallel, then the block sums are added in index order, so the
/// result does not depend on the thread count or the scheduling. A block of 0 means 1.
template <typename Fn>
double sum(std::size_t begin, std::size_t end, Fn&& fn, std::size_t block = 1024)
{
    if (end <= begin) return 0.0;
    if (block == 0) block = 1;
    const std::size_t nBlocks = (end - begin + block - 1) / block;
    std::vector<double> partial(nBlocks, 0.0);
    forEach(
        0, nBlocks,
        [&](std::size_t b) {
        const std::size_t lo = begin + b * block;
        const std::size_t hi = lo + block < end ? lo + block : end;
        double s = 0.0;
        for (std::size_t i = lo; i < hi; ++i) s += double(fn(i));
        partial[b] = s;
        },
        1);
    double total = 0.0;
    for (double s : partial) total += s;
    return total;
}

/// Deterministic reduction into a value of type T: each block of `block` iterations starts
/// from a copy of `zero` and fn(i, acc) adds iteration i's share to it; the blocks' values are
/// then combined by add(total, blockValue) in index order, so the result does not depend on
/// the thread count or the scheduling (as sum()). A block of 0 means 1.
template <typename T, typename Fn, typename Add>
T reduceInOrder(std::size_t begin, std::size_t end, const T& zero, Fn&& fn, Add&& add,
                std::size_t block = 1024)
{
    T total = zero;
    if (end <= begin) return total;
    if (block == 0) block = 1;
    const std::size_t nBlocks = (end - begin + block - 1) / block;
    std::vector<T> partial(nBlocks, zero);
    forEach(
        0, nBlocks,
        [&](std::size_t b) {
        const std::size_t lo = begin + b * block;
        const std::size_t hi = lo + block < end ? lo + block : end;
        for (std::size_t i = lo; i < hi; ++i) fn(i, partial[b]);
        },
        1);
    for (const T& value : partial) add(total, value);
    return total;
}

/// Largest `fn(i)` (as double) over [begin, end), or `lowest` when the range is empty; a maximum
/// does not depend on the order, so neither on the thread count.
template <typename Fn>
double maximum(std::size_t begin, std::size_t end, Fn&& fn, double lowest = 0.0,
               std::size_t block = 1024)
{
    if (end <= begin) return lowest;
    if (block == 0) block = 1;
    const std::size_t nBlocks = (end - begin + block - 1) / block;
    std::vector<double> partial(nBlocks, lowest);
    forEach(
        0, nBlocks,
        [&](std::size_t b) {
        const std::size_t lo = begin + b * block;
        const std::size_t hi = lo + block < end ? lo + block : end;
        double m = lowest;
        for (std::size_t i = lo; i < hi; ++i) m = std::max(m, double(fn(i)));
        partial[b] = m;
        },
        1);
    double result = lowest;
    for (double m : partial) result = std::max(result, m);
    return result;
}

} // namespace parallel
} // namespace ghostfx
