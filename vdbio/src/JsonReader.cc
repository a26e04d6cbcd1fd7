/// @file   JsonReader.cc
#include <ghostfx/vdbio/JsonReader.h>

#include <ghostfx/sph/Exceptions.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <limits>
#include <memory>

namespace ghostfx {
namespace vdbio {

namespace {

/// Short rendering of a value for messages.
std::string shortDump(const Json& value)
{
    std::string text = value.dump();
    if (text.size() > 60) text = text.substr(0, 57) + "...";
    return text;
}

/// The magnitudes a scene number may have, 0 aside: every setting and coordinate becomes a Real,
/// a float in the default build, where a larger one would be infinite and a smaller one 0 or
/// a denormal.
constexpr double LARGEST_NUMBER = double(std::numeric_limits<float>::max());
constexpr double SMALLEST_NUMBER = double(std::numeric_limits<float>::min());

const char* typeWanted(const double*) { return "a number, 0 or of magnitude 1.2e-38 to 3.4e38"; }
const char* typeWanted(const int*) { return "an integer"; }
const char* typeWanted(const std::int64_t*) { return "an integer"; }
const char* typeWanted(const std::uint64_t*) { return "an integer >= 0"; }
const char* typeWanted(const bool*) { return "true or false"; }
const char* typeWanted(const std::string*) { return "a string"; }
const char* typeWanted(const std::array<double, 3>*)
{
    return "an array of 3 numbers (each 0 or of magnitude 1.2e-38 to 3.4e38)";
}
const char* typeWanted(const std::vector<double>*)
{
    return "an array of numbers (each 0 or of magnitude 1.2e-38 to 3.4e38)";
}
const char* typeWanted(const std::vector<std::string>*) { return "an array of strings"; }

bool convert(const Json& v, double& out)
{
    if (!v.is_number()) return false;
    out = v.get<double>();
    const double magnitude = std::abs(out);
    return magnitude == 0 || (magnitude >= SMALLEST_NUMBER && magnitude <= LARGEST_NUMBER);
}
bool convert(const Json& v, std::int64_t& out)
{
    if (v.is_number_integer()) {
        out = v.get<std::int64_t>();
        return true;
    }
    // 2.0 is accepted as an integer, 2.5 is not.
    if (v.is_number_float()) {
        const double d = v.get<double>();
        if (std::isfinite(d) && d == std::floor(d) && std::abs(d) < 9e15) {
            out = std::int64_t(d);
            return true;
        }
    }
    return false;
}
bool convert(const Json& v, int& out)
{
    std::int64_t wide = 0;
    if (!convert(v, wide) || wide < std::numeric_limits<int>::min()
        || wide > std::numeric_limits<int>::max()) {
        return false;
    }
    out = int(wide);
    return true;
}
bool convert(const Json& v, std::uint64_t& out)
{
    if (v.is_number_unsigned()) {
        out = v.get<std::uint64_t>();
        return true;
    }
    std::int64_t wide = 0;
    if (!convert(v, wide) || wide < 0) return false;
    out = std::uint64_t(wide);
    return true;
}
bool convert(const Json& v, bool& out)
{
    if (!v.is_boolean()) return false;
    out = v.get<bool>();
    return true;
}
bool convert(const Json& v, std::string& out)
{
    if (!v.is_string()) return false;
    out = v.get<std::string>();
    return true;
}
bool convert(const Json& v, std::array<double, 3>& out)
{
    if (!v.is_array() || v.size() != 3) return false;
    for (int i = 0; i < 3; ++i) {
        if (!convert(v[i], out[i])) return false;
    }
    return true;
}
bool convert(const Json& v, std::vector<double>& out)
{
    if (!v.is_array()) return false;
    out.resize(v.size());
    for (std::size_t i = 0; i < v.size(); ++i) {
        if (!convert(v[i], out[i])) return false;
    }
    return true;
}
bool convert(const Json& v, std::vector<std::string>& out)
{
    if (!v.is_array()) return false;
    out.resize(v.size());
    for (std::size_t i = 0; i < v.size(); ++i) {
        if (!convert(v[i], out[i])) return false;
    }
    return true;
}

std::size_t editDistance(const std::string& a, const std::string& b)
{
    std::vector<std::size_t> row(b.size() + 1);
    for (std::size_t j = 0; j <= b.size(); ++j) row[j] = j;
    for (std::size_t i = 1; i <= a.size(); ++i) {
        std::size_t diagonal = row[0];
        row[0] = i;
        for (std::size_t j = 1; j <= b.size(); ++j) {
            const std::size_t above = row[j];
            const bool same = std::tolower(static_cast<unsigned char>(a[i - 1]))
                              == std::tolower(static_cast<unsigned char>(b[j - 1]));
            row[j] = std::min({row[j] + 1, row[j - 1] + 1, diagonal + (same ? 0 : 1)});
            diagonal = above;
        }
    }
    return row[b.size()];
}

} // namespace

std::string closestKey(const std::string& key, const std::vector<std::string>& candidates)
{
    std::string best;
    std::size_t bestDistance = std::numeric_limits<std::size_t>::max();
    for (const std::string& c : candidates) {
        const std::size_t d = editDistance(key, c);
        if (d < bestDistance) {
            bestDistance = d;
            best = c;
        }
    }
    // Close means: a few typos, relative to the length of the words.
    const std::size_t allowed = std::max<std::size_t>(2, std::max(key.size(), best.size()) / 3);
    return bestDistance <= allowed ? best : std::string();
}

JsonObject::JsonObject()
    : mDocument(std::make_shared<const Json>(Json::object()))
    , mValue(mDocument.get())
{}

JsonObject::JsonObject(std::shared_ptr<const Json> document, const Json* value, std::string path,
                       std::string source, std::string kind)
    : mDocument(std::move(document))
    , mValue(value)
    , mPath(std::move(path))
    , mSource(std::move(source))
    , mKind(std::move(kind))
{
    if (!mValue || !mValue->is_object()) {
        throw SceneError(msg(mKind, " '", mSource, "': ", mPath.empty() ? "the document" : mPath,
                             " = ", mValue ? shortDump(*mValue) : "null",
                             ": expected an object { ... }"));
    }
}

std::string JsonObject::pathOf(const std::string& key) const
{
    // An empty key names the object itself ("solids[0].geometry", not "solids[0].geometry.").
    return mPath.empty() || key.empty() ? mPath + key : mPath + "." + key;
}

bool JsonObject::has(const std::string& key) const
{
    const Json* v = raw(key);
    return v && !v->is_null();
}

const Json* JsonObject::raw(const std::string& key) const
{
    mKnown.insert(key);
    auto it = mValue->find(key);
    return it == mValue->end() ? nullptr : &*it;
}

void JsonObject::fail(const std::string& key, const std::string& what) const
{
    throw SceneError(msg(mKind, " '", mSource, "': ", pathOf(key), ": ", what));
}

void JsonObject::failValue(const std::string& key, const std::string& what) const
{
    const Json* v = raw(key);
    throw SceneError(msg(mKind, " '", mSource, "': ", pathOf(key), " = ",
                         v ? shortDump(*v) : "null", ": ", what));
}

template <typename T>
T JsonObject::get(const std::string& key, const T& fallback) const
{
    const Json* v = raw(key);
    if (!v || v->is_null()) return fallback;
    T out{};
    if (!convert(*v, out)) failValue(key, std::string("expected ") + typeWanted(&out));
    return out;
}

template <typename T>
T JsonObject::require(const std::string& key) const
{
    const Json* v = raw(key);
    T out{};
    if (!v || v->is_null()) {
        fail(key, std::string("missing; expected ") + typeWanted(&out));
    }
    if (!convert(*v, out)) failValue(key, std::string("expected ") + typeWanted(&out));
    return out;
}

template double JsonObject::get(const std::string&, const double&) const;
template int JsonObject::get(const std::string&, const int&) const;
template std::int64_t JsonObject::get(const std::string&, const std::int64_t&) const;
template std::uint64_t JsonObject::get(const std::string&, const std::uint64_t&) const;
template bool JsonObject::get(const std::string&, const bool&) const;
template std::string JsonObject::get(const std::string&, const std::string&) const;
template std::array<double, 3> JsonObject::get(const std::string&,
                                               const std::array<double, 3>&) const;
template std::vector<double> JsonObject::get(const std::string&, const std::vector<double>&) const;
template std::vector<std::string> JsonObject::get(const std::string&,
                                                  const std::vector<std::string>&) const;
template double JsonObject::require(const std::string&) const;
template int JsonObject::require(const std::string&) const;
template std::int64_t JsonObject::require(const std::string&) const;
template std::uint64_t JsonObject::require(const std::string&) const;
template bool JsonObject::require(const std::string&) const;
template std::string JsonObject::require(const std::string&) const;
template std::array<double, 3> JsonObject::require(const std::string&) const;
template std::vector<double> JsonObject::require(const std::string&) const;
template std::vector<std::string> JsonObject::require(const std::string&) const;

double JsonObject::positive(const std::string& key, double fallback) const
{
    const double v = get<double>(key, fallback);
    if (!(v > 0)) failValue(key, "expected a number > 0");
    return v;
}

double JsonObject::nonNegative(const std::string& key, double fallback) const
{
    const double v = get<double>(key, fallback);
    if (!(v >= 0)) failValue(key, "expected a number >= 0");
    return v;
}

double JsonObject::inRange(const std::string& key, double fallback, double lo, double hi) const
{
    const double v = get<double>(key, fallback);
    if (!(v >= lo && v <= hi)) failValue(key, msg("expected a number in [", lo, ", ", hi, "]"));
    return v;
}

std::string JsonObject::choice(const std::string& key, const std::string& fallback,
                               const std::vector<std::string>& choices) const
{
    const std::string v = get<std::string>(key, fallback);
    if (std::find(choices.begin(), choices.end(), v) != choices.end()) return v;
    std::string list;
    for (const std::string& c : choices) list += (list.empty() ? "'" : ", '") + c + "'";
    const std::string near = closestKey(v, choices);
    failValue(key,
              "expected one of " + list + (near.empty() ? "" : " (did you mean '" + near + "'?)"));
}

JsonObject JsonObject::object(const std::string& key) const
{
    const Json* v = raw(key);
    if (!v || v->is_null()) fail(key, "missing; expected an object { ... }");
    return JsonObject(mDocument, v, pathOf(key), mSource, mKind);
}

std::optional<JsonObject> JsonObject::optionalObject(const std::string& key) const
{
    if (!has(key)) return std::nullopt;
    return JsonObject(mDocument, raw(key), pathOf(key), mSource, mKind);
}

std::vector<JsonObject> JsonObject::objects(const std::string& key) const
{
    std::vector<JsonObject> out;
    const Json* v = raw(key);
    if (!v || v->is_null()) return out;
    if (!v->is_array()) failValue(key, "expected an array [ {...}, ... ]");
    for (std::size_t i = 0; i < v->size(); ++i) {
        out.emplace_back(mDocument, &(*v)[i], msg(pathOf(key), "[", i, "]"), mSource, mKind);
    }
    return out;
}

void JsonObject::finish() const
{
    for (auto it = mValue->begin(); it != mValue->end(); ++it) {
        if (mKnown.count(it.key())) continue;
        const std::vector<std::string> known(mKnown.begin(), mKnown.end());
        const std::string near = closestKey(it.key(), known);
        std::string hint;
        if (!near.empty()) {
            hint = " (did you mean '" + near + "'?)";
        } else if (!known.empty()) {
            hint = " (valid keys here:";
            for (const std::string& k : known) hint += " " + k;
            hint += ")";
        }
        fail(it.key(), "unknown key" + hint);
    }
}

void applyOverride(Json& document, const std::string& assignment)
{
    const std::size_t eq = assignment.find('=');
    if (eq == std::string::npos || eq == 0) {
        throw SceneError(
            msg("-D '", assignment, "': expected path=value, e.g. settings.stiffness=5000"));
    }
    const std::string path = assignment.substr(0, eq);
    const std::string text = assignment.substr(eq + 1);
    Json value = Json::parse(text, nullptr, /*allow_exceptions=*/false);
    if (value.is_discarded()) value = text;

    // Walk "a.b[2].c": names separated by dots, array indices in brackets.
    Json* node = &document;
    std::size_t i = 0;
    std::string walked;
    while (i < path.size()) {
        if (path[i] == '[') {
            const std::size_t close = path.find(']', i);
            if (close == std::string::npos) {
                throw SceneError(msg("-D ", path, ": unclosed '[' in the path"));
            }
            const std::string digits = path.substr(i + 1, close - i - 1);
            if (digits.empty() || !std::all_of(digits.begin(), digits.end(), ::isdigit)) {
                throw SceneError(msg("-D ", path, ": '[", digits, "]' is not an array index"));
            }
            const std::size_t index = std::stoul(digits);
            if (!node->is_array() || index >= node->size()) {
                throw SceneError(msg("-D ", path, ": ", walked.empty() ? "the document" : walked,
                                     " has no element [", index, "] (",
                                     node->is_array() ? node->size() : 0, " elements)"));
            }
            node = &(*node)[index];
            walked += path.substr(i, close - i + 1);
            i = close + 1;
            if (i < path.size() && path[i] == '.') ++i;
            continue;
        }
        std::size_t end = path.find_first_of(".[", i);
        if (end == std::string::npos) end = path.size();
        const std::string name = path.substr(i, end - i);
        if (name.empty()) throw SceneError(msg("-D ", path, ": empty name in the path"));
        if (node->is_null()) *node = Json::object();
        if (!node->is_object()) {
            throw SceneError(msg("-D ", path, ": ", walked, " is not an object"));
        }
        node = &(*node)[name];
        walked += (walked.empty() ? "" : ".") + name;
        i = end;
        if (i < path.size() && path[i] == '.') ++i;
    }
    *node = value;
}

namespace {

/// Follows a parse (nlohmann's parser callback) to name where it is in the document, as the
/// readers' messages do ("settings.spacing", "solids[1].name"), and refuses a key given twice
/// in one object: nlohmann keeps the last value silently.
class DuplicateKeyCheck
{
public:
    DuplicateKeyCheck(std::string kind, std::string path)
        : mKind(std::move(kind))
        , mFile(std::move(path))
    {}

    /// Where the parse is, as a key path ("" at the top). `failed`: the parse stopped in a
    /// value not yet begun, so the innermost array's element is the next one.
    std::string where(bool failed = false) const
    {
        std::string path;
        for (std::size_t k = 0; k < mStack.size(); ++k) {
            const Level& level = mStack[k];
            const bool next = failed && k + 1 == mStack.size();
            if (level.array) path += msg("[", next ? level.elements : level.elements - 1, "]");
            else if (!level.key.empty()) path += (path.empty() ? "" : ".") + level.key;
        }
        return path;
    }

    bool operator()(int /*depth*/, Json::parse_event_t event, Json& parsed)
    {
        using Event = Json::parse_event_t;
        if (event == Event::object_start || event == Event::array_start
            || event == Event::value) {
            if (!mStack.empty() && mStack.back().array) ++mStack.back().elements;
        }
        if (event == Event::object_start || event == Event::array_start) {
            mStack.push_back(Level{event == Event::array_start, 0, {}, {}});
        } else if (event == Event::object_end || event == Event::array_end) {
            mStack.pop_back();
            valueDone();
        } else if (event == Event::value) {
            valueDone();
        } else if (event == Event::key) {
            Level& level = mStack.back();
            level.key = parsed.get<std::string>();
            if (!level.keys.insert(level.key).second) {
                throw SceneError(msg(mKind, " '", mFile, "': ", where(),
                                     ": key given twice in one object (which one is meant?)"));
            }
        }
        return true;
    }

private:
    /// A value of the innermost object is complete: the parse is between its keys.
    void valueDone()
    {
        if (!mStack.empty() && !mStack.back().array) mStack.back().key.clear();
    }

    struct Level
    {
        bool array;
        std::size_t elements; ///< of an array: values begun so far
        std::set<std::string> keys;
        std::string key; ///< of an object: the key being read
    };

    std::string mKind, mFile;
    std::vector<Level> mStack;
};

} // namespace

Json readJsonFile(const std::string& path, const std::string& kind)
{
    namespace fs = std::filesystem;
    std::error_code ec;
    if (fs::is_directory(path, ec)) {
        throw IoError(msg(kind, " '", path, "': is a folder; expected a ", kind, " file (.json)"));
    }
    std::ifstream in(path);
    if (!in) throw IoError(msg(kind, " '", path, "': cannot open the file"));
    // The parser copies its callback: the check is shared so its place survives a parse error.
    const auto check = std::make_shared<DuplicateKeyCheck>(kind, path);
    try {
        return Json::parse(
            in, [check](int depth, Json::parse_event_t event, Json& parsed) {
                return (*check)(depth, event, parsed);
            },
            true, /*ignore_comments=*/true);
    } catch (const Json::parse_error& e) {
        // nlohmann's message: "[json.exception.parse_error.101] parse error at line 3, column
        // 25: syntax error while parsing value - invalid literal; last read: '...'".
        const std::string what = e.what();
        const std::size_t at = what.find(" at line "), colon = what.find(": ", at);
        const std::string place = at == std::string::npos || colon == std::string::npos
                                      ? std::string()
                                      : what.substr(at, colon - at);
        const std::string detail = colon == std::string::npos ? what : what.substr(colon + 2);
        const std::string key = check->where(/*failed=*/true);
        const bool special = detail.find("last read: '") != std::string::npos
                             && (detail.find("N'") != std::string::npos
                                 || detail.find("I'") != std::string::npos);
        throw SceneError(msg(kind, " '", path, "': not valid JSON", place,
                             key.empty() ? std::string() : " (in " + key + ")", ": ", detail,
                             special ? "; NaN and Infinity are not JSON numbers" : ""));
    }
}

} // namespace vdbio
} // namespace ghostfx
