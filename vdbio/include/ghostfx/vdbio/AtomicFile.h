/// @file   AtomicFile.h
/// @brief  Atomic file writes, output folders and Houdini-style frame patterns.
/// @details Every file ghostfx writes goes through writeAtomically(): the content is written to a
///          temporary file beside the target and renamed over it only once complete, so a run
///          killed mid-write leaves the previous version intact (DESIGN.md, Outputs).
#pragma once

#include <functional>
#include <optional>
#include <string>

namespace ghostfx {
namespace vdbio {

/// Write `path` atomically: `write` receives a temporary path in the same folder, writes the
/// whole file there and returns; the temporary is then renamed to `path`. If `write` throws,
/// the temporary is removed, `path` is untouched and the exception propagates.
void writeAtomically(const std::string& path, const std::function<void(const std::string&)>& write);

/// Write `text` to `path` atomically. `what` names the file in errors: IoError "<what>
/// '<path>': write failed (...)".
void writeTextFile(const std::string& path, const std::string& text, const std::string& what);

/// The whole text of `path`, or nothing when it cannot be opened (a missing file).
std::optional<std::string> readTextFile(const std::string& path);

/// The last non-empty line of the text file `path` ("" for none, or a file that cannot be read).
std::string lastLineOf(const std::string& path);

/// Create `dir` (and its parents) if needed and check a file can be created in it; throws
/// IoError "output folder '<dir>': <reason>" otherwise.
void ensureWritableDirectory(const std::string& dir);

/// Expand a frame pattern: `$F4` becomes the frame zero-padded to 4 digits (`$F2`..`$F9` alike),
/// `$F` the frame unpadded. Patterns without `$F` are returned unchanged.
std::string expandFramePattern(const std::string& pattern, int frame);

/// True if `pattern` contains a `$F` token.
bool hasFrameToken(const std::string& pattern);

/// Lower-case extension of `path` including the dot (".vdb"), or "" if none.
std::string extensionOf(const std::string& path);

} // namespace vdbio
} // namespace ghostfx
