/// @file   Exceptions.h
/// @brief  Typed exceptions thrown by the ghostfx libraries.
/// @details Libraries throw, only `main` exits (STYLE.md rule 7). Every message names what was
///          wrong, where (setting, grid, file, key) and what was expected, in one line, so the
///          command line can print `what()` as it is.
#pragma once

#include <sstream>
#include <stdexcept>
#include <string>

namespace ghostfx {

/// Base of every ghostfx error.
class Error : public std::runtime_error
{
public:
    explicit Error(const std::string& msg) : std::runtime_error(msg) {}
};

/// A setting or argument is out of range or inconsistent ("settings.stiffness = -1: expected > 0").
class ValueError : public Error
{
    using Error::Error;
};

/// A grid cannot be used as asked: wrong class or type, non-uniform voxels, empty, NaN values.
class GridError : public Error
{
    using Error::Error;
};

/// Sampling could not produce what was asked (shape without a surface, too many samples...).
class SamplingError : public Error
{
    using Error::Error;
};

/// A simulation left the range where its numbers mean anything (NaN, speed beyond a bound).
class NumericalError : public Error
{
    using Error::Error;
};

/// A file could not be read or written (thrown by vdbio only: solvers never touch files).
class IoError : public Error
{
    using Error::Error;
};

/// A scene file is malformed: unknown key, wrong type, missing value.
class SceneError : public Error
{
    using Error::Error;
};

/// Build a message from stream-able parts: `throw ValueError(msg("spacing = ", h, ": expected > 0"))`.
template <typename... Args>
std::string msg(const Args&... args)
{
    std::ostringstream os;
    (os << ... << args);
    return os.str();
}

} // namespace ghostfx
