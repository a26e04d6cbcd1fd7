/// @file   test_atomic_file.cc
/// @brief  Atomic writes, output folders and frame patterns.
#include <ghostfx/sph/Exceptions.h>
#include <ghostfx/vdbio/AtomicFile.h>

#include "common/Expect.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <stdexcept>

namespace fs = std::filesystem;
using namespace ghostfx;

namespace {

using ghostfx::testing::slurp;

using ghostfx::testing::freshDir;

} // namespace

TEST(AtomicFile, InterruptedWriteLeavesThePreviousFileIntact)
{
    const fs::path dir = freshDir("atomic");
    const std::string path = (dir / "frame.0001.vdb").string();
    vdbio::writeAtomically(path, [](const std::string& tmp) { std::ofstream(tmp) << "frame one"; });
    EXPECT_EQ(slurp(path), "frame one");

    // A writer that dies halfway (here: throws after writing part of the file).
    EXPECT_THROW(vdbio::writeAtomically(
                     path,
                     [](const std::string& tmp) {
        std::ofstream(tmp) << "half of frame tw";
        throw std::runtime_error("killed");
                     }),
                 std::runtime_error);
    EXPECT_EQ(slurp(path), "frame one");
    // No temporary left behind.
    EXPECT_EQ(std::distance(fs::directory_iterator(dir), fs::directory_iterator()), 1);
}

TEST(AtomicFile, FramePatterns)
{
    EXPECT_EQ(vdbio::expandFramePattern("out/liquid.$F4.vdb", 7), "out/liquid.0007.vdb");
    EXPECT_EQ(vdbio::expandFramePattern("a.$F.vdb", 12), "a.12.vdb");
    EXPECT_EQ(vdbio::expandFramePattern("b.$F2.vdb", 123), "b.123.vdb");
    EXPECT_EQ(vdbio::expandFramePattern("static.vdb", 3), "static.vdb");
    EXPECT_TRUE(vdbio::hasFrameToken("x.$F4.vdb"));
    EXPECT_FALSE(vdbio::hasFrameToken("x.vdb"));
    EXPECT_EQ(vdbio::extensionOf("A/B.VDB"), ".vdb");
}

TEST(AtomicFile, UnwritableFolderIsAClearError)
{
    const fs::path dir = freshDir("unwritable");
    const fs::path file = dir / "not_a_folder";
    std::ofstream(file) << "x";
    try {
        vdbio::ensureWritableDirectory(file.string());
        FAIL() << "expected IoError";
    } catch (const IoError& e) {
        EXPECT_NE(std::string(e.what()).find("exists and is not a folder"), std::string::npos)
            << e.what();
    }
    vdbio::ensureWritableDirectory((dir / "a" / "b").string());
    EXPECT_TRUE(fs::is_directory(dir / "a" / "b"));
}
