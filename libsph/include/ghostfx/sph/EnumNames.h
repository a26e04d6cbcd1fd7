/// @file   EnumNames.h
/// @brief  The names of an enum's values (in scenes, files and messages) kept in one table, with
///         the lookups both ways: `nameOf(METHOD_NAMES, m)` and `valueOf(METHOD_NAMES, "ghost",
///         "liquid method")`, whose error lists every name.
#pragma once

#include <ghostfx/sph/Exceptions.h>

#include <cstddef>
#include <string>

namespace ghostfx {
namespace sph {

template <typename Enum>
struct EnumName
{
    Enum value;
    const char* name;
};

/// The name of `value` in `table`, or "unknown" for a value the table does not hold.
template <typename Enum, std::size_t N>
const char* nameOf(const EnumName<Enum> (&table)[N], Enum value)
{
    for (const EnumName<Enum>& e : table) {
        if (e.value == value) return e.name;
    }
    return "unknown";
}

/// "'a', 'b' or 'c'": the names of `table` for messages.
template <typename Enum, std::size_t N>
std::string quotedNames(const EnumName<Enum> (&table)[N])
{
    std::string list;
    for (std::size_t i = 0; i < N; ++i) {
        if (i > 0) list += i + 1 == N ? " or " : ", ";
        list += std::string("'") + table[i].name + "'";
    }
    return list;
}

/// The value named `name` in `table`; throws ValueError "<what> '<name>': expected 'a' or 'b'".
template <typename Enum, std::size_t N>
Enum valueOf(const EnumName<Enum> (&table)[N], const std::string& name, const char* what)
{
    for (const EnumName<Enum>& e : table) {
        if (name == e.name) return e.value;
    }
    throw ValueError(msg(what, " '", name, "': expected ", quotedNames(table)));
}

} // namespace sph
} // namespace ghostfx
