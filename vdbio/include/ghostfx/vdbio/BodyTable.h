/// @file   BodyTable.h
/// @brief  The motion of a run's dynamic solids: one row per body per simulated frame, in
///         `bodies.csv` in the output folder and in the `/bodies` group of the statistics file.
/// @details A row is the body's state at the end of its frame: the frame number, the time (s),
///          the solid's name, its centre of mass x y z (m, world), its orientation as a unit
///          quaternion qw qx qy qz (turning the solid's own frame, the frame its level set is
///          given in, into the world about the centre of mass), the velocity of its centre vx vy
///          vz (m/s) and its angular velocity wx wy wz (rad/s, world axes).
///
///          CSV: the header `frame,time,name,x,y,z,qw,qx,qy,qz,vx,vy,vz,wx,wy,wz`, then one line
///          per row, numbers in the shortest form that reads back to the same double, a name
///          holding a comma or a quote in double quotes (RFC 4180). HDF5 (Stats.h): the group
///          `/bodies` with the attribute `columns` (the CSV's header, in order), one 1-D double
///          dataset per numeric column with a `unit` attribute, and the dataset `name` of
///          variable-length strings.
///
///          Both files are rewritten atomically with every row so far at each flush (once per
///          frame), as the statistics are; a resumed run reloads the rows up to its checkpoint's
///          frame (BodyLog::resumeFrom) and carries on without repeating one.
#pragma once

#include <array>
#include <string>
#include <vector>

namespace ghostfx {
namespace vdbio {

/// How many numbers follow the name in a row: x y z, qw qx qy qz, vx vy vz, wx wy wz.
constexpr std::size_t BODY_VALUES = 13;

struct BodyRow
{
    int frame = 0;
    double time = 0; ///< s
    std::string name;
    std::array<double, BODY_VALUES> values{}; ///< in the order of bodyColumns() after "name"
};

/// The columns, in order: frame, time, name, x, y, z, qw, qx, qy, qz, vx, vy, vz, wx, wy, wz.
const std::vector<std::string>& bodyColumns();
/// The unit of a numeric column of bodyColumns(): "1", "s", "m", "m/s" or "rad/s".
std::string bodyUnit(const std::string& column);

/// Write `rows` as bodies.csv text to `path`, atomically. IoError naming the file on failure.
void writeBodiesCsv(const std::string& path, const std::vector<BodyRow>& rows);
/// Read a bodies.csv file. IoError naming the file and line if it is missing or malformed.
std::vector<BodyRow> readBodiesCsv(const std::string& path);
/// Read the `/bodies` group of the statistics file `h5Path` (empty without one). IoError
/// naming the file if it cannot be read or the group is malformed.
std::vector<BodyRow> readStatsBodies(const std::string& h5Path);

/// The rows of a run, kept in memory and rewritten to the CSV file at each flush().
class BodyLog
{
public:
    explicit BodyLog(std::string csvPath) : mCsvPath(std::move(csvPath)) {}

    void append(BodyRow row) { mRows.push_back(std::move(row)); }
    /// Rewrite the CSV file with every row so far (nothing before the first row).
    void flush() const;
    /// On resume: the rows of the CSV file with frame <= `frame` (a missing file: none).
    void resumeFrom(int frame);

    const std::vector<BodyRow>& rows() const { return mRows; }
    const std::string& csvPath() const { return mCsvPath; }

private:
    std::string mCsvPath;
    std::vector<BodyRow> mRows;
};

} // namespace vdbio
} // namespace ghostfx
