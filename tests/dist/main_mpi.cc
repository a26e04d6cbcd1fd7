/// @file   main_mpi.cc
/// @brief  GoogleTest main of the MPI tests: every rank runs every test (they are collective),
///         only rank 0 prints, and a failure on any rank fails the whole run (mpirun returns
///         the first non-zero exit code).
#include <ghostfx/dist/MpiExchange.h>

#include <gtest/gtest.h>
#include <openvdb/openvdb.h>

#include <cstdlib>

int main(int argc, char** argv)
{
    ::setenv("GHOSTFX_SAMPLE_CACHE", "off", 1); // as tests/main.cc: no per-user cache in tests
    ghostfx::dist::MpiSession mpi(&argc, &argv);
    openvdb::initialize();
    ::testing::InitGoogleTest(&argc, argv);
    if (mpi.rank() != 0) {
        auto& listeners = ::testing::UnitTest::GetInstance()->listeners();
        delete listeners.Release(listeners.default_result_printer());
    }
    const int failed = RUN_ALL_TESTS();
    // Every rank learns whether any failed, so all exit alike.
    int any = failed;
    MPI_Allreduce(&failed, &any, 1, MPI_INT, MPI_MAX, MPI_COMM_WORLD);
    return any;
}
