/// @file   SettingReader.h
/// @brief  A settings table (ghostfx/sph/SettingSpec.h) read from a scene object: each row's key
///         read its kind's way and each number checked against its declared range, with the
///         scene's one-line message ("settings.cfl = 50: expected a number in [0.001, 2]").
#pragma once

#include <ghostfx/sph/Exceptions.h>
#include <ghostfx/sph/SettingSpec.h>
#include <ghostfx/vdbio/JsonReader.h>

#include <array>
#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

namespace ghostfx {
namespace cmd {

/// Read a Number or Whole row: absent, the field keeps its value (an automatic row's negative
/// "the solver picks" too); present, a number in the row's range, whole for a Whole row.
template <typename S>
void readNumberSetting(const vdbio::JsonObject& o, const sph::SettingSpec<S>& row, S& s)
{
    if (row.automatic && !o.has(row.key)) return;
    const double v = o.get<double>(row.key, row.numberOf(s));
    const bool whole = row.kind != sph::SettingKind::Whole || v == std::floor(v);
    if (!row.range.contains(v) || !whole) o.failValue(row.key, "expected " + row.expected(false));
    row.setNumber(s, v);
}

/// Read the key of `row` from `o` into `s`; an absent key leaves the field as it is.
template <typename S>
void readSetting(const vdbio::JsonObject& o, const sph::SettingSpec<S>& row, S& s)
{
    using Kind = sph::SettingKind;
    switch (row.kind) {
    case Kind::Number:
    case Kind::Whole:
        readNumberSetting(o, row, s);
        return;
    case Kind::Flag:
        row.setFlag(s, o.get<bool>(row.key, row.flagOf(s)));
        return;
    case Kind::Seed:
        row.setSeed(s, o.get<std::uint64_t>(row.key, row.seedOf(s)));
        return;
    case Kind::Choice:
        row.setChoice(s, o.choice(row.key, row.choiceOf(s), row.choiceNames()));
        return;
    case Kind::Vector: {
        const sph::Vec3& v = row.vectorOf(s);
        const auto a = o.get<std::array<double, 3>>(row.key, {v[0], v[1], v[2]});
        row.setVector(s, sph::Vec3(sph::Real(a[0]), sph::Real(a[1]), sph::Real(a[2])));
        return;
    }
    }
}

/// Read every row of `table` that has a scene key from `o` into `s`.
template <typename S>
void readSettingTable(const vdbio::JsonObject& o, const sph::SettingTable<S>& table, S& s)
{
    for (const sph::SettingSpec<S>& row : table.rows) {
        if (row.key) readSetting(o, row, s);
    }
}

/// `settings.validate()`, its ValueError (a rule between two fields) as a SceneError that names
/// the scene file.
template <typename S>
void validateSceneSettings(const std::string& sceneFile, const S& settings)
{
    try {
        settings.validate();
    } catch (const ValueError& e) {
        throw SceneError(msg("scene '", sceneFile, "': ", e.what()));
    }
}

/// The JSON pointers ("/settings/max_speed") of the keys of `table` in scene object `prefix`
/// ("/settings") that a resumed run may change.
template <typename S>
void addFreeOnResume(const sph::SettingTable<S>& table, const std::string& prefix,
                     std::vector<std::string>& pointers)
{
    for (const sph::SettingSpec<S>& row : table.rows) {
        if (row.key && !row.mustMatch) pointers.push_back(prefix + "/" + row.key);
    }
}

} // namespace cmd
} // namespace ghostfx
