/// @file   Expect.h
/// @brief  Test helpers shared by the test files: the message of an expected exception, a
///         substring check, a fresh temporary folder and reading a whole file.
#pragma once

#include <gtest/gtest.h>

#include <exception>
#include <filesystem>
#include <string>

#include <fstream>
#include <iterator>
#include <string>
#include <unistd.h>

namespace ghostfx {
namespace testing {

/// Run `f`, expect it to throw E and return the message ("" and a test failure otherwise).
template <typename E, typename F>
std::string errorOf(F&& f)
{
    try {
        f();
    } catch (const E& e) {
        return e.what();
    } catch (const std::exception& e) {
        ADD_FAILURE() << "unexpected exception type: " << e.what();
        return "";
    }
    ADD_FAILURE() << "no exception thrown";
    return "";
}

/// `settings` with its method set to `method` (any solver's settings).
template <typename Settings, typename Method>
Settings withMethod(Settings settings, Method method)
{
    settings.method = method;
    return settings;
}

inline bool contains(const std::string& text, const std::string& part)
{
    return text.find(part) != std::string::npos;
}

/// An empty folder of the system's temporary directory for one test
/// ("ghostfx_test_<name>_<pid>": test processes that ctest runs side by side never share one).
inline std::filesystem::path freshDir(const std::string& name);

/// freshDir("<prefix>_<name of the running test>"), for a fixture's SetUp.
inline std::filesystem::path freshTestDir(const std::string& prefix)
{
    return freshDir(prefix + "_" + ::testing::UnitTest::GetInstance()->current_test_info()->name());
}

inline std::filesystem::path freshDir(const std::string& name)
{
    const std::filesystem::path dir = std::filesystem::temp_directory_path()
                                      / ("ghostfx_test_" + name + "_" + std::to_string(::getpid()));
    std::filesystem::remove_all(dir);
    std::filesystem::create_directories(dir);
    return dir;
}

/// The whole file as bytes ("" if it cannot be read).
inline std::string slurp(const std::filesystem::path& p)
{
    std::ifstream in(p, std::ios::binary);
    return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

} // namespace testing
} // namespace ghostfx
