/// @file   main.cc
/// @brief  GoogleTest main shared by the ghostfx test executables: initialises OpenVDB once.
#include <gtest/gtest.h>
#include <openvdb/openvdb.h>

int main(int argc, char** argv)
{
    openvdb::initialize();
    ::testing::InitGoogleTest(&argc, argv);
    return RUN_ALL_TESTS();
}
