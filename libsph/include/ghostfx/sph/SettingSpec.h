/// @file   SettingSpec.h
/// @brief  Each setting declared once: a table row per field of a settings struct, with its scene
///         key, kind, range, unit, one-line meaning and whether a checkpoint must match it.
/// @details A solver's settings table feeds its `validate()` (validateTable below), the scene
///          reader of cmd (cmd/SettingReader.h), the fields a resumed run may change and the
///          settings tables of docs/scene-format.md (tests/cli/test_setting_tables.cc compares
///          them). The default of a row is the default-constructed struct's field, so it is
///          written once too. A row reaches its field through a member pointer:
///
///              Row::number("kernel_support", "supportFactor", &GhostSettings::supportFactor,
///                          sph::between(1.5, 5), "h", "kernel support radius / spacing h")
///
///          Rules that tie two fields together (max_dt >= min_dt) stay explicit in validate().
#pragma once

#include <ghostfx/sph/EnumNames.h>
#include <ghostfx/sph/SettingCheck.h>
#include <ghostfx/sph/Types.h>

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <limits>
#include <string>
#include <type_traits>
#include <variant>
#include <vector>

namespace ghostfx {
namespace sph {

/// The numbers a setting accepts: from lo to hi, either end open; infinite ends are no bound.
/// Every accepted number is finite.
struct SettingRange
{
    double lo = -std::numeric_limits<double>::infinity();
    double hi = std::numeric_limits<double>::infinity();
    bool loOpen = false;
    bool hiOpen = false;

    bool contains(double v) const
    {
        return std::isfinite(v) && (loOpen ? v > lo : v >= lo) && (hiOpen ? v < hi : v <= hi);
    }
    /// "> 0", ">= 0", "[1.5, 5]", "(0, 1]" or "finite": how docs and messages write it.
    std::string text() const;
};

/// Any finite number.
inline SettingRange anyFinite() { return SettingRange(); }
/// > 0.
inline SettingRange positive() { return SettingRange{0, SettingRange().hi, true, false}; }
/// >= 0.
inline SettingRange nonNegative() { return SettingRange{0, SettingRange().hi, false, false}; }
/// [lo, hi].
inline SettingRange between(double lo, double hi) { return SettingRange{lo, hi, false, false}; }
/// (lo, hi].
inline SettingRange above(double lo, double hi) { return SettingRange{lo, hi, true, false}; }

/// A number as the tables write it: "0.05", "1e-5", "2000", "1e6".
std::string settingNumberText(double v);

inline std::string SettingRange::text() const
{
    const bool noLo = std::isinf(lo), noHi = std::isinf(hi);
    if (noLo && noHi) return "finite";
    if (noHi) return (loOpen ? "> " : ">= ") + settingNumberText(lo);
    if (noLo) return (hiOpen ? "< " : "<= ") + settingNumberText(hi);
    return (loOpen ? "(" : "[") + settingNumberText(lo) + ", " + settingNumberText(hi)
           + (hiOpen ? ")" : "]");
}

inline std::string settingNumberText(double v)
{
    char text[32];
    std::snprintf(text, sizeof text, "%g", v);
    std::string s(text);
    // %g writes "1e-05" and "1e+06": the tables write "1e-5" and "1e6".
    const std::size_t e = s.find('e');
    if (e == std::string::npos) return s;
    std::size_t digits = e + 1;
    if (digits < s.size() && s[digits] == '+') s.erase(digits, 1);
    if (digits < s.size() && s[digits] == '-') ++digits;
    while (digits + 1 < s.size() && s[digits] == '0') s.erase(digits, 1);
    return s;
}

/// What a setting holds: a real number, a whole number, true/false, one name of a list, three
/// real numbers, or a 64-bit random seed.
enum class SettingKind : std::uint8_t { Number, Whole, Flag, Choice, Vector, Seed };

/// One name of a Choice setting and the enum value (as int) it stands for.
struct SettingChoice
{
    const char* name;
    int value;
};

/// The choices of an enum named by `table` (EnumNames.h), in the table's order.
template <typename Enum, std::size_t N>
std::vector<SettingChoice> choicesOf(const EnumName<Enum> (&table)[N])
{
    std::vector<SettingChoice> choices;
    for (const EnumName<Enum>& e : table) choices.push_back({e.name, int(e.value)});
    return choices;
}

/// One setting of the settings struct S.
template <typename S>
struct SettingSpec
{
    /// Reads and writes an enum field as int.
    struct EnumAccess
    {
        int (*get)(const S&);
        void (*set)(S&, int);
    };
    using Field = std::variant<float S::*, double S::*, int S::*, bool S::*, std::uint64_t S::*,
                               Vec3 S::*, EnumAccess>;

    /// The key in its scene object ("kernel_support"); nullptr: not a key of that object (the
    /// scene's shared keys give it, or only a library user sets it), validated only.
    const char* key = nullptr;
    /// The field as validate()'s messages name it ("supportFactor", "dfsph.maxTimeStep").
    const char* field = nullptr;
    SettingKind kind = SettingKind::Number;
    Field member;
    SettingRange range;                 ///< Number and Whole, in scene units
    const char* unit = "";              ///< of the scene value: "m", "Pa", "h" (spacings); "" none
    const char* meaning = "";           ///< one line
    std::vector<SettingChoice> choices; ///< Choice: the names, the scene's spelling
    /// A checkpoint resumes only in a scene that gives this setting the same value.
    bool mustMatch = true;
    /// Number and Whole: a negative field value means "the solver picks" (GhostSettings::
    /// shifting()); a scene that gives the key gives a value in `range`.
    bool automatic = false;
    /// The field holds scale x the scene value (bytes for GiB).
    double scale = 1;
    /// The default as docs write it, where it is not the struct's (it depends on the scene).
    const char* defaultText = nullptr;

    SettingSpec() = default;
    /// A row without range, choices or flags; the factories below add those of their kind.
    SettingSpec(const char* sceneKey, const char* fieldName, SettingKind k, Field m,
                const char* unitName, const char* oneLine)
        : key(sceneKey)
        , field(fieldName)
        , kind(k)
        , member(m)
        , unit(unitName)
        , meaning(oneLine)
    {}
    /// A real (float or double field) or whole (int field) number within `range`.
    template <typename T>
    static SettingSpec number(const char* key, const char* field, T S::*m, SettingRange range,
                              const char* unit, const char* meaning)
    {
        static_assert(std::is_floating_point<T>::value || std::is_same<T, int>::value);
        const bool whole = std::is_same<T, int>::value;
        SettingSpec r(key, field, whole ? SettingKind::Whole : SettingKind::Number, Field(m), unit,
                      meaning);
        r.range = range;
        return r;
    }
    /// True or false.
    static SettingSpec flag(const char* key, const char* field, bool S::*m, const char* meaning)
    {
        return SettingSpec(key, field, SettingKind::Flag, Field(m), "", meaning);
    }
    /// Three finite numbers.
    static SettingSpec vector(const char* key, const char* field, Vec3 S::*m, const char* unit,
                              const char* meaning)
    {
        return SettingSpec(key, field, SettingKind::Vector, Field(m), unit, meaning);
    }
    /// A 64-bit random seed.
    static SettingSpec seed(const char* key, const char* field, std::uint64_t S::*m,
                            const char* meaning)
    {
        return SettingSpec(key, field, SettingKind::Seed, Field(m), "", meaning);
    }
    /// An enum field `Member` whose values are named by `choices`.
    template <auto Member>
    static SettingSpec choice(const char* key, const char* field,
                              std::vector<SettingChoice> choices, const char* meaning)
    {
        using Enum = std::decay_t<decltype(std::declval<S&>().*Member)>;
        const EnumAccess access{[](const S& s) { return int(s.*Member); },
                                [](S& s, int v) { s.*Member = Enum(v); }};
        SettingSpec r(key, field, SettingKind::Choice, Field(access), "", meaning);
        r.choices = std::move(choices);
        return r;
    }

    /// This row with a negative field meaning automatic, free on resume, scaled, or with its
    /// default shown as `text`.
    SettingSpec automaticWhenNegative() const { return with(&SettingSpec::automatic, true); }
    SettingSpec freeOnResume() const { return with(&SettingSpec::mustMatch, false); }
    SettingSpec scaled(double s) const { return with(&SettingSpec::scale, s); }
    SettingSpec shownDefault(const char* text) const
    {
        return with(&SettingSpec::defaultText, text);
    }

    /// Number and Whole: the field in scene units (field / scale).
    double numberOf(const S& s) const
    {
        if (auto m = std::get_if<float S::*>(&member)) return double(s.**m) / scale;
        if (auto m = std::get_if<double S::*>(&member)) return s.**m / scale;
        return double(s.*std::get<int S::*>(member));
    }
    /// Number and Whole: set the field from the scene value v (scale x v).
    void setNumber(S& s, double v) const
    {
        if (auto m = std::get_if<float S::*>(&member)) s.** m = float(scale * v);
        else if (auto m = std::get_if<double S::*>(&member)) s.** m = scale * v;
        else s.*std::get<int S::*>(member) = int(v);
    }
    bool flagOf(const S& s) const { return s.*std::get<bool S::*>(member); }
    void setFlag(S& s, bool v) const { s.*std::get<bool S::*>(member) = v; }
    std::uint64_t seedOf(const S& s) const { return s.*std::get<std::uint64_t S::*>(member); }
    void setSeed(S& s, std::uint64_t v) const { s.*std::get<std::uint64_t S::*>(member) = v; }
    const Vec3& vectorOf(const S& s) const { return s.*std::get<Vec3 S::*>(member); }
    void setVector(S& s, const Vec3& v) const { s.*std::get<Vec3 S::*>(member) = v; }
    /// Choice: the name of the field's value ("" for a value without a name here).
    const char* choiceOf(const S& s) const
    {
        const int v = std::get<EnumAccess>(member).get(s);
        for (const SettingChoice& c : choices)
            if (c.value == v) return c.name;
        return "";
    }
    /// Choice: set the field to the value named `name` (one of `choices`).
    void setChoice(S& s, const std::string& name) const
    {
        for (const SettingChoice& c : choices)
            if (name == c.name) std::get<EnumAccess>(member).set(s, c.value);
    }
    std::vector<std::string> choiceNames() const
    {
        std::vector<std::string> names;
        for (const SettingChoice& c : choices) names.push_back(c.name);
        return names;
    }

    /// What validate() and the reader expect of a Number or Whole: "a number in [1.5, 5] (h)",
    /// "a whole number >= 1"; `field` adds ", or negative (automatic)" for an automatic one
    /// (a field may hold that, a scene key gives a value in the range or nothing).
    std::string expected(bool field = true) const
    {
        std::string text = kind == SettingKind::Whole ? "a whole number " : "a number ";
        const std::string r = range.text();
        text += r == "finite" ? "(finite)" : (r[0] == '[' || r[0] == '(' ? "in " + r : r);
        if (*unit) text += std::string(" (") + unit + ")";
        if (automatic && field) text += ", or negative (automatic)";
        return text;
    }

    /// The default as docs write it, from `defaults` (a default-constructed S): "0.05",
    /// "automatic", "true", "\"tait\"", "[0, -9.81, 0]", or defaultText.
    std::string defaultShown(const S& defaults) const
    {
        if (defaultText) return defaultText;
        switch (kind) {
        case SettingKind::Number:
        case SettingKind::Whole:
            if (automatic && numberOf(defaults) < 0) return "automatic";
            return settingNumberText(numberOf(defaults));
        case SettingKind::Flag:
            return flagOf(defaults) ? "true" : "false";
        case SettingKind::Seed:
            return std::to_string(seedOf(defaults));
        case SettingKind::Choice:
            return std::string("\"") + choiceOf(defaults) + "\"";
        case SettingKind::Vector:
            break;
        }
        const Vec3& v = vectorOf(defaults);
        return "[" + settingNumberText(v[0]) + ", " + settingNumberText(v[1]) + ", "
               + settingNumberText(v[2]) + "]";
    }
    /// The values accepted as docs write them: "[1.5, 5]", "> 0", "tait, dfsph", "true, false",
    /// "finite" (a vector's components), "" (a seed: any).
    std::string rangeShown() const
    {
        switch (kind) {
        case SettingKind::Number:
        case SettingKind::Whole:
            return range.text();
        case SettingKind::Flag:
            return "true, false";
        case SettingKind::Seed:
            return "";
        case SettingKind::Vector:
            return "finite";
        case SettingKind::Choice:
            break;
        }
        std::string names;
        for (const SettingChoice& c : choices)
            names += (names.empty() ? "" : ", ") + std::string(c.name);
        return names;
    }

private:
    template <typename T, typename V>
    SettingSpec with(T SettingSpec::*m, V v) const
    {
        SettingSpec r = *this;
        r.*m = v;
        return r;
    }
};

/// The settings table of a struct S: its rows in the order scenes and docs list them.
template <typename S>
struct SettingTable
{
    const char* what; ///< names the settings in validate()'s messages: "liquid setting"
    std::vector<SettingSpec<S>> rows;
};

/// The rows of the step-control fields every solver's settings have (substeps, cflNumber,
/// maxSpeed, seed), read from the same keys.
template <typename S>
std::vector<SettingSpec<S>> stepSettingRows()
{
    using Row = SettingSpec<S>;
    return {
        Row::number("substeps", "substeps", &S::substeps, between(0, 100000), "",
                    "fixed steps per frame; 0 = CFL-adaptive steps"),
        Row::number("cfl", "cflNumber", &S::cflNumber, between(1e-3, 2), "",
                    "CFL number of adaptive steps"),
        Row::number("max_speed", "maxSpeed", &S::maxSpeed, nonNegative(), "m/s",
                    "blow-up bound: a faster particle stops the run; 0 = automatic")
            .freeOnResume(),
        Row::seed("seed", "seed", &S::seed, "random seed of all sampling"),
    };
}

/// The table of `rows` followed by the step-control rows (stepSettingRows()).
template <typename S>
SettingTable<S> withStepRows(const char* what, std::vector<SettingSpec<S>> rows)
{
    const std::vector<SettingSpec<S>> steps = stepSettingRows<S>();
    rows.insert(rows.end(), steps.begin(), steps.end());
    return SettingTable<S>{what, std::move(rows)};
}

/// Throw ValueError "<what> <field> = <value>: expected <range>" for the first Number or Whole
/// row of `table` whose field `s` holds out of range (an automatic one may be negative), or
/// for the first Vector with a component that is not finite.
template <typename S>
void validateTable(const SettingTable<S>& table, const S& s)
{
    const SettingCheck check(table.what);
    for (const SettingSpec<S>& row : table.rows) {
        if (row.kind == SettingKind::Vector) {
            check.require(isFinite(row.vectorOf(s)), row.field, row.vectorOf(s).length(),
                          "finite components");
        }
        if (row.kind != SettingKind::Number && row.kind != SettingKind::Whole) continue;
        const double v = row.numberOf(s);
        if (row.automatic && v < 0) continue;
        check.require(row.range.contains(v), row.field, v, row.expected().c_str());
    }
}

} // namespace sph
} // namespace ghostfx
