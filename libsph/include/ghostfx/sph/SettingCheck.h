/// @file   SettingCheck.h
/// @brief  The range checks of a settings struct's validate(), with one message form:
///         "liquid setting stiffness = -1: expected > 0 (Pa)".
#pragma once

#include <ghostfx/sph/Exceptions.h>

#include <cmath>

namespace ghostfx {
namespace sph {

class SettingCheck
{
public:
    /// `what` names the settings in messages: "liquid setting", "gas setting", ...
    explicit SettingCheck(const char* what) : mWhat(what) {}

    /// ValueError "<what> <field> = <value>: expected <expected>" unless `ok`.
    void require(bool ok, const char* field, double value, const char* expected) const
    {
        if (!ok) throw ValueError(msg(mWhat, " ", field, " = ", value, ": expected ", expected));
    }

    static bool finite(double v) { return std::isfinite(v); }

private:
    const char* mWhat;
};

} // namespace sph
} // namespace ghostfx
