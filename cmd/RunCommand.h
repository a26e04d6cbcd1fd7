/// @file   RunCommand.h
/// @brief  `ghostfx run`: a scene to a VDB frame sequence, with checkpoints, statistics,
///         previews, progress and clean interruption.
#pragma once

#include "Command.h"

#include <string>
#include <vector>

namespace ghostfx {
namespace cmd {

struct RunOptions
{
    std::string scene;                ///< scene .json (or role-tagged .vdb)
    std::string frames;               ///< "A-B" or "B": overrides settings.frame_range
    int threads = 0;                  ///< 0: all cores
    std::string out;                  ///< overrides outputs.directory
    std::vector<std::string> defines; ///< -D path=value
    std::string resume;               ///< checkpoint to continue from
    bool quiet = false;
    /// Write each frame before simulating the next, instead of overlapping (FrameWriter.h).
    bool serialOutput = false;
    /// Progress display: "auto" (bar on a terminal, log lines otherwise), "bar", "log", "none".
    std::string progress = "auto";
    /// Folder of sampled shapes kept between runs (LiquidScene.h, processSampleCache); empty:
    /// $GHOSTFX_SAMPLE_CACHE, else the per-user default; "off": none.
    std::string sampleCache;
};

/// Parse "--frames A-B" or "--frames B" (whole numbers in [1, MAX_FRAME], first <= last) into
/// `first` and `last` (B alone keeps `first`); ValueError naming the text otherwise.
void parseFrames(const std::string& text, int& first, int& last);

/// Run a scene; returns the exit code: 0, or 128 + the signal's number for a run that SIGINT,
/// SIGTERM or SIGUSR1 stopped after a frame and its checkpoint (StopSignals.h). Throws
/// ghostfx::Error on bad input.
int runScene(const RunOptions& options);

} // namespace cmd
} // namespace ghostfx
