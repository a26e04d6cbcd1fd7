/// @file   Stats.h
/// @brief  Per-step statistics of a run, in an HDF5 file and a CSV file beside it.
/// @details One row per solver step, columns in a fixed order chosen by the caller (frame, step,
///          time, dt, particle counts, max speed, density error, phase timings, memory...). Both
///          files are rewritten atomically with every row so far at each flush() (once per frame),
///          so a killed run leaves complete files of its last flushed frame, and a resumed run
///          reloads the rows up to its checkpoint (resumeFrom) and carries on.
///
///          HDF5 layout: root attributes `format` = "ghostfx statistics", `schema_version`,
///          `units` (the naming convention below, as text); group `/steps` with one 1-D double
///          dataset per column (each with a `unit` attribute) and the attribute `columns`, the
///          column names in order. CSV: a header line with the column names, then one line per
///          row, numbers in the shortest form that reads back to the same double. A run with
///          dynamic solids adds the group `/bodies` (BodyTable.h), given by setBodies().
///
///          Units follow the column name (statsUnit): `time`, `dt` and `t_*` in s (`t_*` are
///          wall-clock seconds of a solver phase), `*speed*` in m/s, `count_*`, `frame`, `step`
///          dimensionless counts, `density_error_*` relative to the rest density, `bytes*` in
///          bytes; anything else has no unit recorded ("").
#pragma once

#include <ghostfx/vdbio/BodyTable.h>

#include <cstddef>
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

namespace ghostfx {
namespace vdbio {

/// One row: (column name, value) pairs in column order.
struct StatsRow
{
    std::vector<std::pair<std::string, double>> values;
};

/// The rows of a statistics file.
struct StatsTable
{
    std::vector<std::string> columns;
    std::vector<std::vector<double>> rows; ///< rows[r][c] is column c of row r
};

/// The unit of a column by its name (see the file comment), "" if none is known.
std::string statsUnit(const std::string& column);

/// Read the HDF5 statistics file `h5Path`. Throws IoError naming the file if it is missing,
/// not a ghostfx statistics file, or malformed.
StatsTable readStats(const std::string& h5Path);

class StatsWriter
{
public:
    /// @param h5Path   HDF5 file to write; @param csvPath  CSV file to write. Nothing is written
    ///                 before the first flush().
    StatsWriter(std::string h5Path, std::string csvPath);

    /// Add one row. The first row (or the rows reloaded by resumeFrom) fixes the columns; a row
    /// with other names or another order throws ValueError naming the first mismatch.
    void append(const StatsRow& row);

    /// Rewrite both files atomically with every row so far. Without columns (no row yet and
    /// nothing reloaded) there is nothing to write and the files are left alone. Throws
    /// IoError naming the file if one cannot be written.
    void flush();

    /// On resume: replace the rows in memory by those in the HDF5 file with `step` <= `step`
    /// (a missing file: start empty, columns unset). The files themselves change at the next
    /// flush(). Throws IoError if the file exists but cannot be read or has no "step" column.
    void resumeFrom(std::int64_t step);

    /// The dynamic solids' rows (BodyTable.h) the HDF5 file holds from the next flush() on,
    /// as the group `/bodies`; none: no such group.
    void setBodies(std::vector<BodyRow> rows) { mBodies = std::move(rows); }

    std::size_t rows() const { return mTable.rows.size(); }
    const StatsTable& table() const { return mTable; }
    const std::string& h5Path() const { return mH5Path; }
    const std::string& csvPath() const { return mCsvPath; }

private:
    std::string mH5Path, mCsvPath;
    StatsTable mTable;
    std::vector<BodyRow> mBodies;
};

} // namespace vdbio
} // namespace ghostfx
