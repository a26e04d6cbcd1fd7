/// @file   StudyPlot.cc
#include "StudyPlot.h"

#include <ghostfx/sph/Exceptions.h>
#include <ghostfx/vdbio/AtomicFile.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <fcntl.h>
#include <filesystem>
#include <sstream>
#include <limits>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

extern char** environ;

namespace ghostfx {
namespace cmd {

namespace fs = std::filesystem;

std::vector<std::size_t> paretoFront(const std::vector<PlotPoint>& points)
{
    std::vector<std::size_t> order;
    for (std::size_t i = 0; i < points.size(); ++i) {
        if (std::isfinite(points[i].x) && std::isfinite(points[i].y)) order.push_back(i);
    }
    std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
        const PlotPoint &pa = points[a], &pb = points[b];
        return pa.x != pb.x ? pa.x < pb.x : pa.y != pb.y ? pa.y < pb.y : a < b;
    });
    // In (x, y) order, every point before a group of identical points has x < or y < than the
    // group with the other coordinate <=, so it beats the group exactly when its y is <= the
    // group's y: the group is on the front when its y is below all earlier ones.
    std::vector<std::size_t> front;
    double lowestEarlierY = std::numeric_limits<double>::infinity();
    for (std::size_t begin = 0; begin < order.size();) {
        const PlotPoint& p = points[order[begin]];
        std::size_t end = begin + 1;
        while (end < order.size() && points[order[end]].x == p.x && points[order[end]].y == p.y) {
            ++end;
        }
        if (p.y < lowestEarlierY) {
            front.insert(front.end(), order.begin() + begin, order.begin() + end);
        }
        lowestEarlierY = std::min(lowestEarlierY, p.y);
        begin = end;
    }
    return front;
}

namespace {

/// A CSV field: quoted (quotes doubled) where it holds a comma, a quote or a line break.
std::string csvField(const std::string& s)
{
    if (s.find_first_of(",\"\n\r") == std::string::npos) return s;
    std::string out = "\"";
    for (char c : s) out += c == '"' ? std::string("\"\"") : std::string(1, c);
    return out + "\"";
}

/// `s` in single quotes for a POSIX shell.
std::string shellQuoted(const std::string& s)
{
    std::string out = "'";
    for (char c : s) out += c == '\'' ? std::string("'\\''") : std::string(1, c);
    return out + "'";
}

std::string python()
{
    const char* env = std::getenv("GHOSTFX_PYTHON");
    return env && *env ? env : GHOSTFX_PYTHON_EXECUTABLE;
}

} // namespace

void writePlotPoints(const std::string& path, const std::string& xName, const std::string& yName,
                     const std::vector<PlotPoint>& points)
{
    std::vector<char> onFront(points.size(), 0);
    for (std::size_t i : paretoFront(points)) onFront[i] = 1;
    std::ostringstream out;
    out.precision(17);
    out << "series,label," << csvField(xName) << "," << csvField(yName) << ",pareto\n";
    for (std::size_t i = 0; i < points.size(); ++i) {
        const PlotPoint& p = points[i];
        out << csvField(p.series) << "," << csvField(p.label) << "," << p.x << "," << p.y << ","
            << int(onFront[i]) << "\n";
    }
    vdbio::writeTextFile(path, out.str(), "plot points");
}

std::string plotScript()
{
    if (const char* env = std::getenv("GHOSTFX_PLOT_SCRIPT"); env && *env) return env;
    std::error_code ec;
    const fs::path self = fs::read_symlink("/proc/self/exe", ec);
    if (!ec) {
        const fs::path installed =
            self.parent_path().parent_path() / GHOSTFX_DATA_DIR / "plot_study.py";
        if (fs::exists(installed, ec)) return installed.string();
    }
    const fs::path source = fs::path(GHOSTFX_SOURCE_DIR) / "scripts" / "plot_study.py";
    return fs::exists(source, ec) ? source.string() : std::string();
}

std::string plotCommand(const std::string& points, const std::string& image,
                        const std::string& title)
{
    const std::string script = plotScript();
    return python() + " " + shellQuoted(script.empty() ? "plot_study.py" : script) + " "
           + shellQuoted(points) + " -o " + shellQuoted(image)
           + (title.empty() ? "" : " --title " + shellQuoted(title));
}

std::string drawPlot(const std::string& points, const std::string& image, const std::string& title)
{
    const std::string script = plotScript();
    if (script.empty()) {
        return "the plotting script plot_study.py was not found (set GHOSTFX_PLOT_SCRIPT)";
    }
    std::vector<std::string> args = {python(), script, points, "-o", image};
    if (!title.empty()) args.insert(args.end(), {"--title", title});
    std::vector<char*> argv;
    for (std::string& a : args) argv.push_back(a.data());
    argv.push_back(nullptr);

    // The script's messages go to a log beside the points; its last line is the reason.
    const std::string log = points + ".log";
    posix_spawn_file_actions_t actions;
    posix_spawn_file_actions_init(&actions);
    posix_spawn_file_actions_addopen(&actions, STDOUT_FILENO, log.c_str(),
                                     O_WRONLY | O_CREAT | O_TRUNC, 0644);
    posix_spawn_file_actions_adddup2(&actions, STDOUT_FILENO, STDERR_FILENO);
    pid_t pid = 0;
    const int err = posix_spawnp(&pid, args[0].c_str(), &actions, nullptr, argv.data(), environ);
    posix_spawn_file_actions_destroy(&actions);
    if (err != 0) return msg("cannot start '", args[0], "': ", std::strerror(err));
    int status = 0;
    while (::waitpid(pid, &status, 0) < 0) {
        if (errno != EINTR) return msg("waiting for the plotting script: ", std::strerror(errno));
    }
    const std::string last = vdbio::lastLineOf(log);
    if (WIFEXITED(status) && WEXITSTATUS(status) == 0) {
        std::error_code ec;
        fs::remove(log, ec);
        return "";
    }
    return last.empty() ? msg("the plotting script failed (", args[0], " ", script, ")") : last;
}

} // namespace cmd
} // namespace ghostfx
