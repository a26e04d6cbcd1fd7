/// @file   JsonReader.h
/// @brief  Strict reading of JSON scene files: every key is read or the run stops.
/// @details A JsonObject wraps one JSON object of a document. Each key a reader asks for (found
///          or not) becomes a known key; finish() then reports any key in the object that was
///          never asked for, with its path and the closest known key:
///
///              scene 'dam.json': settings.stifness: unknown key (did you mean 'stiffness'?)
///
///          Paths use the same dotted form as `-D` overrides (`solids[0].velocity`), so a message
///          can be pasted back on the command line. Type and range errors name the path, the bad
///          value and what was expected.
#pragma once

#include <nlohmann/json.hpp>

#include <array>
#include <memory>
#include <optional>
#include <set>
#include <string>
#include <vector>

namespace ghostfx {
namespace vdbio {

using Json = nlohmann::json;

class JsonObject
{
public:
    /// An empty object (nothing to read).
    JsonObject();
    /// @param document  keeps the whole document alive; `value` points into it
    /// @param source    the file name used in messages
    /// @param kind      what the document is, for messages: "scene" (default) or "study"
    JsonObject(std::shared_ptr<const Json> document, const Json* value, std::string path,
               std::string source, std::string kind = "scene");

    /// Path of this object ("settings", "solids[1]"; "" for the root).
    const std::string& path() const { return mPath; }
    /// Path of a key of this object.
    std::string pathOf(const std::string& key) const;
    const std::string& source() const { return mSource; }

    /// True if the key is present (and not null). Makes the key known.
    bool has(const std::string& key) const;
    /// The raw value, or nullptr. Makes the key known.
    const Json* raw(const std::string& key) const;

    /// Read a value of type T (double, int, std::int64_t, std::uint64_t, bool, std::string,
    /// std::array<double, 3>, std::vector<double>, std::vector<std::string>), or `fallback` if absent.
    template <typename T>
    T get(const std::string& key, const T& fallback) const;
    /// Read a value that must be present.
    template <typename T>
    T require(const std::string& key) const;

    /// Numbers with a range check: "settings.stiffness = -1: expected > 0".
    double positive(const std::string& key, double fallback) const;
    double nonNegative(const std::string& key, double fallback) const;
    double inRange(const std::string& key, double fallback, double lo, double hi) const;
    /// A string that must be one of `choices`.
    std::string choice(const std::string& key, const std::string& fallback,
                       const std::vector<std::string>& choices) const;

    /// A nested object (required / optional).
    JsonObject object(const std::string& key) const;
    std::optional<JsonObject> optionalObject(const std::string& key) const;
    /// An array of objects; absent means empty.
    std::vector<JsonObject> objects(const std::string& key) const;

    /// Throw SceneError for the first key that was never asked for.
    void finish() const;

    /// SceneError "<kind> '<source>': <path of key>: <what>" (kind "scene" or "study").
    [[noreturn]] void fail(const std::string& key, const std::string& what) const;
    /// SceneError "<kind> '<source>': <path of key> = <value>: <what>".
    [[noreturn]] void failValue(const std::string& key, const std::string& what) const;

private:
    std::shared_ptr<const Json> mDocument;
    const Json* mValue;
    std::string mPath;
    std::string mSource;
    std::string mKind = "scene";
    mutable std::set<std::string> mKnown;
};

/// Read the JSON file `path` (comments allowed) as a `kind` ("scene" or "study") is read. Refuses,
/// with one line naming the file: a folder or a file that cannot be opened (IoError), text that
/// is not JSON, with nlohmann's line and column, and a key given twice in one object, with its
/// path ("scene 'a.json': settings.spacing: key given twice in one object") (SceneError).
Json readJsonFile(const std::string& path, const std::string& kind = "scene");

/// Apply a `-D path=value` override to `document`. `value` is parsed as JSON if it is valid
/// JSON (numbers, arrays, true/false, quoted strings) and taken as a plain string otherwise.
/// Missing objects on the path are created; indexing past an array's end is a SceneError.
void applyOverride(Json& document, const std::string& assignment);

/// The key among `candidates` closest to `key` (edit distance), or "" if none is close.
std::string closestKey(const std::string& key, const std::vector<std::string>& candidates);

} // namespace vdbio
} // namespace ghostfx
