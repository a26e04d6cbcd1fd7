/// @file   SampleStore.cc
#include "ghostfx/sph/SampleStore.h"

#include <cstring>
#include <type_traits>

namespace ghostfx {
namespace sph {

namespace {

/// 64-bit FNV-1a.
class Fnv
{
public:
    void bytes(const void* data, std::size_t n)
    {
        const auto* p = static_cast<const unsigned char*>(data);
        for (std::size_t i = 0; i < n; ++i) {
            mHash ^= p[i];
            mHash *= 0x100000001b3ULL;
        }
    }
    template <typename T>
    void value(const T& v)
    {
        static_assert(std::is_arithmetic<T>::value, "arithmetic values only");
        bytes(&v, sizeof(T));
    }
    std::uint64_t hash() const { return mHash; }

private:
    std::uint64_t mHash = 0xcbf29ce484222325ULL;
};

/// What else decides the samples' last bits: the compiler and the instructions it was allowed
/// (fused multiply-adds round once where a multiply and an add round twice). Builds that differ
/// here (an AVX2 build beside a portable one, both using the per-user cache) keep apart files.
constexpr char BUILD[] = "compiler "
#ifdef __VERSION__
    __VERSION__
#endif
#ifdef __FMA__
                         " fma"
#endif
#ifdef __AVX2__
                         " avx2"
#endif
#ifdef __AVX512F__
                         " avx512f"
#endif
#ifdef __FAST_MATH__
                         " fast-math"
#endif
    ;

} // namespace

std::uint64_t sampleKey(const LevelSet& shape, const PoissonSettings& s)
{
    Fnv h;
    h.value(SAMPLER_VERSION);
    h.value(std::uint32_t(sizeof(Real)));
    h.bytes(BUILD, sizeof BUILD);
    h.value(shape.contentHash());
    h.value(s.radius);
    h.value(s.surfaceAttempts);
    h.value(s.surfaceStep);
    h.value(s.volumeAttempts);
    h.value(s.relaxAttempts);
    h.value(s.surfaceRelaxSweeps);
    h.value(s.volumeRelaxSweeps);
    h.value(std::uint8_t(s.volumeRelaxation));
    h.value(s.packingIterations);
    h.value(s.bandDepth);
    h.value(s.seed);
    h.value(std::uint8_t(s.tiledInterior));
    h.value(std::uint64_t(s.maxSamples));
    return h.hash();
}

SampleSet sampleVolumeStored(const PoissonSettings& settings, const LevelSet& shape,
                             SampleStore* store)
{
    if (!store) return PoissonDiskSampler(settings).sampleVolume(shape);
    const std::uint64_t key = sampleKey(shape, settings);
    if (std::optional<SampleSet> kept = store->load(key)) return std::move(*kept);
    SampleSet samples = PoissonDiskSampler(settings).sampleVolume(shape);
    store->store(key, samples);
    return samples;
}

} // namespace sph
} // namespace ghostfx
