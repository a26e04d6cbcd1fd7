/// @file   test_parallel.cc
/// @brief  Contracts of the parallel loop helpers: deterministic sums, every index visited once,
///         grain sizes, empty ranges, the serial switch and the thread cap.
/// @details STYLE.md rules 5 and 6: reductions must give bit-identical results at any thread
///          count, so a 1-thread and an N-thread simulation can be compared exactly.
#include <ghostfx/sph/Parallel.h>

#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <mutex>
#include <thread>
#include <utility>
#include <vector>

namespace {

namespace parallel = ghostfx::parallel;

/// Sets the serial switch for one test and restores it afterwards (GHOSTFX_SERIAL may be set in
/// the environment, so tests that need TBB switch it off explicitly).
class SerialGuard
{
public:
    explicit SerialGuard(bool serial) : mPrevious(parallel::isSerial())
    {
        parallel::setSerial(serial);
    }
    ~SerialGuard() { parallel::setSerial(mPrevious); }

private:
    bool mPrevious;
};

std::uint64_t bits(double x)
{
    std::uint64_t b;
    std::memcpy(&b, &x, sizeof b);
    return b;
}

/// Values spanning 16 orders of magnitude with both signs: a sum of them depends on the order
/// of the additions, so equal sums mean an equal order.
std::vector<double> orderSensitiveValues(std::size_t n)
{
    std::vector<double> v(n);
    for (std::size_t i = 0; i < n; ++i) {
        v[i] = std::sin(0.7 * double(i)) * std::pow(10.0, double(int((i * 37) % 17) - 8));
    }
    return v;
}

/// The documented order: blocks of `block` values summed left to right, then the block sums
/// left to right.
double blockedSum(const std::vector<double>& v, std::size_t begin, std::size_t end,
                  std::size_t block)
{
    double total = 0.0;
    for (std::size_t lo = begin; lo < end; lo += block) {
        double s = 0.0;
        for (std::size_t i = lo; i < std::min(lo + block, end); ++i) s += v[i];
        total += s;
    }
    return total;
}

TEST(ParallelSum, IsBitIdenticalForOneThreadAllThreadsAndSerial)
{
    const std::size_t n = 1000003; // not a multiple of the block size
    const std::vector<double> v = orderSensitiveValues(n);
    auto fn = [&v](std::size_t i) { return v[i]; };

    // The data must be order sensitive, or equality below would prove nothing.
    double forward = 0.0, backward = 0.0;
    for (std::size_t i = 0; i < n; ++i) forward += v[i];
    for (std::size_t i = n; i-- > 0;) backward += v[i];
    ASSERT_NE(bits(forward), bits(backward));

    const double expected = blockedSum(v, 0, n, 1024);
    double oneThread, serial;
    {
        SerialGuard guard(false);
        parallel::ThreadLimit limit(1);
        ASSERT_EQ(parallel::maxThreads(), 1);
        oneThread = parallel::sum(0, n, fn);
    }
    {
        SerialGuard guard(true);
        serial = parallel::sum(0, n, fn);
    }
    EXPECT_EQ(bits(oneThread), bits(expected));
    EXPECT_EQ(bits(serial), bits(expected));
    SerialGuard guard(false);
    for (int repeat = 0; repeat < 10; ++repeat) {
        EXPECT_EQ(bits(parallel::sum(0, n, fn)), bits(expected)) << "repeat " << repeat;
    }
    // Other block sizes and a range that does not start at 0 follow the same rule.
    EXPECT_EQ(bits(parallel::sum(17, n, fn, 1000)), bits(blockedSum(v, 17, n, 1000)));
    // Block 1 and a block larger than the range are both the plain left-to-right sum.
    EXPECT_EQ(bits(parallel::sum(0, n, fn, 1)), bits(forward));
    EXPECT_EQ(bits(parallel::sum(0, n, fn, 2 * n)), bits(forward));
}

TEST(ParallelSum, AccumulatesInDouble)
{
    // 1e8f + 1024 x 1.0f: in float every +1 is lost below the 8-unit spacing at 1e8; in double
    // the result is exact (STYLE.md rule 6: reductions in double).
    SerialGuard guard(false);
    const double s = parallel::sum(0, 1025, [](std::size_t i) { return i == 0 ? 1e8f : 1.0f; });
    EXPECT_EQ(s, 1e8 + 1024.0);
}

TEST(ParallelSum, EmptyRangeIsZeroAndCallsNothing)
{
    SerialGuard guard(false);
    int calls = 0;
    auto fn = [&calls](std::size_t) {
        ++calls;
        return 1.0;
    };
    EXPECT_EQ(bits(parallel::sum(5, 5, fn)), bits(0.0));
    EXPECT_EQ(bits(parallel::sum(7, 3, fn)), bits(0.0)); // end < begin: empty, not huge
    EXPECT_EQ(calls, 0);
}

/// Run forEach over [begin, end) with `grain` and check every index there is visited exactly
/// once and nothing outside it is.
void checkVisitsOnce(std::size_t begin, std::size_t end, std::size_t grain)
{
    const std::size_t pad = 3;
    std::vector<std::atomic<int>> visits(end + pad);
    for (auto& c : visits) c.store(0);
    parallel::forEach(
        begin, end, [&](std::size_t i) { visits[i].fetch_add(1); }, grain);
    std::size_t wrong = 0;
    for (std::size_t i = 0; i < visits.size(); ++i) {
        const int expected = (i >= begin && i < end) ? 1 : 0;
        if (visits[i].load() != expected && ++wrong <= 3) {
            ADD_FAILURE() << "index " << i << " visited " << visits[i].load() << " times, expected "
                          << expected << " (range [" << begin << ", " << end << "), grain " << grain
                          << ")";
        }
    }
    EXPECT_EQ(wrong, 0u);
}

TEST(ParallelForEach, VisitsEveryIndexExactlyOnce)
{
    for (bool serial : {false, true}) {
        SerialGuard guard(serial);
        checkVisitsOnce(0, 100003, parallel::DEFAULT_GRAIN);
        checkVisitsOnce(11, 100003, 1);
        checkVisitsOnce(0, 1000, 7);
        checkVisitsOnce(5, 6, 256);   // one index
        checkVisitsOnce(0, 256, 256); // exactly one grain
        checkVisitsOnce(0, 257, 256); // one grain and one index
        checkVisitsOnce(0, 3, 1);
    }
}

TEST(ParallelForEach, EmptyRangesCallNothing)
{
    SerialGuard guard(false);
    std::atomic<int> calls{0};
    parallel::forEach(0, 0, [&](std::size_t) { ++calls; });
    parallel::forEach(
        10, 10, [&](std::size_t) { ++calls; }, 1);
    parallel::forEach(
        10, 2, [&](std::size_t) { ++calls; }, 1); // end < begin
    parallel::forRange(4, 4, [&](std::size_t, std::size_t) { ++calls; });
    EXPECT_EQ(calls.load(), 0);
}

TEST(ParallelForRange, ChunksAreDisjointCoverTheRangeAndRespectTheGrain)
{
    SerialGuard guard(false);
    for (std::size_t grain : {std::size_t(1), std::size_t(10), std::size_t(256)}) {
        const std::size_t begin = 7, end = 10007;
        std::mutex mutex;
        std::vector<std::pair<std::size_t, std::size_t>> chunks;
        parallel::forRange(
            begin, end,
            [&](std::size_t b, std::size_t e) {
            std::lock_guard<std::mutex> lock(mutex);
            chunks.emplace_back(b, e);
            },
            grain);
        std::sort(chunks.begin(), chunks.end());
        ASSERT_FALSE(chunks.empty());
        EXPECT_EQ(chunks.front().first, begin);
        EXPECT_EQ(chunks.back().second, end);
        for (std::size_t c = 0; c < chunks.size(); ++c) {
            EXPECT_LT(chunks[c].first, chunks[c].second) << "empty chunk";
            EXPECT_LE(chunks[c].second - chunks[c].first, grain) << "chunk larger than grain";
            if (c > 0) {
                EXPECT_EQ(chunks[c].first, chunks[c - 1].second) << "gap or overlap";
            }
        }
    }
}

TEST(ParallelForRange, TinyRangeRunsOnceOnTheCallingThread)
{
    // A range no longer than the grain is not worth a task: one call, inline.
    SerialGuard guard(false);
    for (std::size_t size : {std::size_t(1), std::size_t(100), std::size_t(256)}) {
        int calls = 0;
        std::thread::id where;
        parallel::forRange(
            1000, 1000 + size,
            [&](std::size_t b, std::size_t e) {
            ++calls;
            where = std::this_thread::get_id();
            EXPECT_EQ(b, 1000u);
            EXPECT_EQ(e, 1000u + size);
            },
            256);
        EXPECT_EQ(calls, 1) << "size " << size;
        EXPECT_EQ(where, std::this_thread::get_id());
    }
}

TEST(ParallelForRange, ZeroGrainIsTreatedAsOne)
{
    // tbb::blocked_range with grain 0 splits forever; a caller computing grain = n / k for a
    // small n must still get every index once.
    SerialGuard guard(false);
    checkVisitsOnce(0, 1000, 0);
    checkVisitsOnce(0, 1, 0);
    std::vector<double> v = orderSensitiveValues(5000);
    double forward = 0.0;
    for (double x : v) forward += x;
    EXPECT_EQ(bits(parallel::sum(
                  0, v.size(), [&v](std::size_t i) { return v[i]; }, 0)),
              bits(forward)); // block 0 means block 1: the left-to-right sum
}

TEST(ParallelSerial, SwitchRunsEverythingInOrderOnTheCallingThread)
{
    SerialGuard guard(true);
    EXPECT_TRUE(parallel::isSerial());
    EXPECT_EQ(parallel::maxThreads(), 1);
    std::vector<std::size_t> seen; // no lock: serial means one thread
    bool otherThread = false;
    const auto caller = std::this_thread::get_id();
    parallel::forEach(
        0, 50000,
        [&](std::size_t i) {
        seen.push_back(i);
        if (std::this_thread::get_id() != caller) otherThread = true;
        },
        16);
    EXPECT_FALSE(otherThread);
    ASSERT_EQ(seen.size(), 50000u);
    for (std::size_t i = 0; i < seen.size(); ++i) ASSERT_EQ(seen[i], i);
    int calls = 0;
    parallel::forRange(
        0, 50000,
        [&](std::size_t b, std::size_t e) {
        ++calls;
        EXPECT_EQ(b, 0u);
        EXPECT_EQ(e, 50000u);
        },
        16);
    EXPECT_EQ(calls, 1);
    parallel::setSerial(false);
    EXPECT_FALSE(parallel::isSerial());
}

TEST(ParallelThreadLimit, CapsThreadsWhileAliveAndRestoresAfter)
{
    SerialGuard guard(false);
    const int all = parallel::maxThreads();
    EXPECT_GE(all, 1);
    {
        parallel::ThreadLimit limit(1);
        EXPECT_EQ(parallel::maxThreads(), 1);
        // With one thread allowed TBB runs every chunk on the calling thread.
        std::atomic<bool> otherThread{false};
        const auto caller = std::this_thread::get_id();
        parallel::forEach(
            0, 100000,
            [&](std::size_t) {
            if (std::this_thread::get_id() != caller) otherThread = true;
            },
            64);
        EXPECT_FALSE(otherThread.load());
    }
    EXPECT_EQ(parallel::maxThreads(), all);
    {
        parallel::ThreadLimit noCap(0); // 0 means no cap
        EXPECT_EQ(parallel::maxThreads(), all);
    }
}

} // namespace
