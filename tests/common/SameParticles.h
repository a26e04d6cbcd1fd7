/// @file   SameParticles.h
/// @brief  Test helper: expect two particle sets to be the same bit for bit, as the thread-count
///         and step-by-step determinism tests compare them.
#pragma once

#include <ghostfx/sph/ParticleSet.h>

#include <gtest/gtest.h>

namespace ghostfx {
namespace testing {

/// Which channels expectSameParticles compares beyond ids, positions and velocities.
enum class AlsoCompare { Nothing, Pressures };

/// Expect `a` and `b` to hold the same particles: the same count (asserted; nothing else is
/// compared when it differs), then equal ids, positions, velocities and, if asked, pressures.
inline void expectSameParticles(const sph::ParticleSet& a, const sph::ParticleSet& b,
                                AlsoCompare also)
{
    ASSERT_EQ(a.size(), b.size());
    EXPECT_TRUE(a.ids() == b.ids());
    EXPECT_TRUE(a.positions() == b.positions());
    EXPECT_TRUE(a.velocities() == b.velocities());
    if (also == AlsoCompare::Pressures) {
        EXPECT_TRUE(a.pressures() == b.pressures());
    }
}

} // namespace testing
} // namespace ghostfx
