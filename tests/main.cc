/// @file   main.cc
/// @brief  GoogleTest main shared by the ghostfx test executables: initialises OpenVDB once, and
///         turns the per-user sample cache off (cmd/LiquidScene.h), so that every run a test
///         starts samples its shapes as the test expects and nothing is written outside the
///         tests' folders. Tests of the cache name their own folders.
#include <gtest/gtest.h>
#include <openvdb/openvdb.h>

#include <cstdlib>

int main(int argc, char** argv)
{
    ::setenv("GHOSTFX_SAMPLE_CACHE", "off", 1);
    openvdb::initialize();
    ::testing::InitGoogleTest(&argc, argv);
    return RUN_ALL_TESTS();
}
