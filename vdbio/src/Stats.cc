/// @file   Stats.cc
/// @brief  Per-step statistics in HDF5 and CSV (layout in Stats.h), HDF5 1.10 C++ API.
#include <ghostfx/vdbio/Stats.h>

#include "BodyTableH5.h"

#include <ghostfx/sph/Exceptions.h>
#include <ghostfx/vdbio/AtomicFile.h>

#include <H5Cpp.h>

#include <algorithm>
#include <charconv>
#include <filesystem>
#include <fstream>
#include <set>

namespace ghostfx {
namespace vdbio {

namespace {

constexpr const char* FORMAT = "ghostfx statistics";
constexpr int SCHEMA_VERSION = 1;
constexpr const char* STEPS = "steps";
constexpr const char* UNITS =
    "one row per solver step; time, dt and t_* in s (t_*: wall-clock seconds of a solver phase); "
    "*speed* in m/s; frame, step and count_* are counts; density_error_* relative to the rest "
    "density; bytes* in bytes; each dataset's 'unit' attribute repeats its unit";

bool startsWith(const std::string& s, const char* prefix) { return s.rfind(prefix, 0) == 0; }

std::string detailOf(const H5::Exception& e)
{
    std::string detail = e.getDetailMsg();
    return detail.empty() ? std::string("HDF5 error") : detail;
}

/// The shortest decimal text that reads back as the same double.
std::string formatNumber(double value)
{
    char buffer[64];
    const auto result = std::to_chars(buffer, buffer + sizeof(buffer), value);
    return std::string(buffer, result.ptr);
}

void writeStringAttribute(H5::H5Object& object, const std::string& name, const std::string& value)
{
    const H5::StrType type(H5::PredType::C_S1, H5T_VARIABLE);
    H5::Attribute attr = object.createAttribute(name, type, H5::DataSpace(H5S_SCALAR));
    attr.write(type, value);
}

void writeH5(const std::string& file, const StatsTable& table, const std::vector<BodyRow>& bodies)
{
    H5::H5File h5(file, H5F_ACC_TRUNC);
    writeStringAttribute(h5, "format", FORMAT);
    const int version = SCHEMA_VERSION;
    h5.createAttribute("schema_version", H5::PredType::NATIVE_INT, H5::DataSpace(H5S_SCALAR))
        .write(H5::PredType::NATIVE_INT, &version);
    writeStringAttribute(h5, "units", UNITS);

    H5::Group steps = h5.createGroup(STEPS);
    const H5::StrType stringType(H5::PredType::C_S1, H5T_VARIABLE);
    const hsize_t columnCount = table.columns.size();
    std::vector<const char*> names;
    for (const std::string& c : table.columns) names.push_back(c.c_str());
    H5::Attribute columns =
        steps.createAttribute("columns", stringType, H5::DataSpace(1, &columnCount));
    if (columnCount > 0) columns.write(stringType, names.data());

    const hsize_t rows = table.rows.size();
    std::vector<double> values(table.rows.size());
    for (std::size_t c = 0; c < table.columns.size(); ++c) {
        H5::DataSet set = steps.createDataSet(table.columns[c], H5::PredType::NATIVE_DOUBLE,
                                              H5::DataSpace(1, &rows));
        for (std::size_t r = 0; r < table.rows.size(); ++r) values[r] = table.rows[r][c];
        if (rows > 0) set.write(values.data(), H5::PredType::NATIVE_DOUBLE);
        writeStringAttribute(set, "unit", statsUnit(table.columns[c]));
    }
    writeBodiesGroup(h5, bodies);
}

void writeCsv(const std::string& file, const StatsTable& table)
{
    std::ofstream out(file, std::ios::binary);
    if (!out) throw IoError(msg("statistics '", file, "': cannot create it"));
    for (std::size_t c = 0; c < table.columns.size(); ++c) {
        out << (c ? "," : "") << table.columns[c];
    }
    out << '\n';
    for (const auto& row : table.rows) {
        for (std::size_t c = 0; c < row.size(); ++c) out << (c ? "," : "") << formatNumber(row[c]);
        out << '\n';
    }
    out.flush();
    if (!out) throw IoError(msg("statistics '", file, "': write failed"));
}

/// Column names must be usable as HDF5 dataset names and as CSV header fields as they are.
void checkColumnName(const std::string& name)
{
    if (name.empty() || name == "." || name.find_first_of("/,\"\n\r") != std::string::npos) {
        throw ValueError(msg("statistics column '", name,
                             "': expected a non-empty name without "
                             "'/', ',', quotes or line breaks"));
    }
}

} // namespace

std::string statsUnit(const std::string& column)
{
    if (column == "time" || column == "dt" || startsWith(column, "t_")) return "s";
    if (column.find("speed") != std::string::npos) return "m/s";
    if (column == "frame" || column == "step" || startsWith(column, "count_")) return "1";
    if (startsWith(column, "density_error")) return "1 (relative to the rest density)";
    if (startsWith(column, "bytes")) return "bytes";
    return "";
}

StatsTable readStats(const std::string& h5Path)
{
    H5::Exception::dontPrint();
    auto fail = [&](const std::string& what) -> IoError {
        return IoError(msg("statistics '", h5Path, "': ", what));
    };
    std::error_code ec;
    if (!std::filesystem::exists(h5Path, ec)) throw fail("no such file");
    try {
        if (!H5::H5File::isHdf5(h5Path)) throw fail("not an HDF5 file");
        H5::H5File h5(h5Path, H5F_ACC_RDONLY);
        std::string format;
        if (h5.attrExists("format")) {
            H5::Attribute attr = h5.openAttribute("format");
            if (attr.getTypeClass() == H5T_STRING) attr.read(attr.getStrType(), format);
        }
        if (format != FORMAT) throw fail("not a ghostfx statistics file");
        if (!h5.nameExists(STEPS)) throw fail("missing group '/steps'");
        H5::Group steps = h5.openGroup(STEPS);
        if (!steps.attrExists("columns")) throw fail("missing attribute '/steps/columns'");

        StatsTable table;
        H5::Attribute columns = steps.openAttribute("columns");
        const hssize_t count = columns.getSpace().getSimpleExtentNpoints();
        if (columns.getTypeClass() != H5T_STRING) throw fail("'/steps/columns' is not text");
        if (count > 0) {
            const H5::StrType type(H5::PredType::C_S1, H5T_VARIABLE);
            std::vector<char*> names(std::size_t(count), nullptr);
            columns.read(type, names.data());
            for (char* name : names) {
                table.columns.emplace_back(name ? name : "");
                H5free_memory(name);
            }
        }
        std::vector<std::vector<double>> data;
        for (const std::string& column : table.columns) {
            if (!steps.nameExists(column)) throw fail(msg("missing dataset '/steps/", column, "'"));
            H5::DataSet set = steps.openDataSet(column);
            H5::DataSpace space = set.getSpace();
            if (set.getTypeClass() != H5T_FLOAT || space.getSimpleExtentNdims() != 1) {
                throw fail(msg("dataset '/steps/", column, "' is not a 1-D floating-point array"));
            }
            hsize_t n = 0;
            space.getSimpleExtentDims(&n);
            if (!data.empty() && n != data.front().size()) {
                throw fail(msg("dataset '/steps/", column, "' has ", n, " rows, '/steps/",
                               table.columns.front(), "' ", data.front().size()));
            }
            data.emplace_back(std::size_t(n));
            if (n > 0) set.read(data.back().data(), H5::PredType::NATIVE_DOUBLE);
        }
        const std::size_t rows = data.empty() ? 0 : data.front().size();
        table.rows.assign(rows, std::vector<double>(table.columns.size()));
        for (std::size_t c = 0; c < data.size(); ++c) {
            for (std::size_t r = 0; r < rows; ++r) table.rows[r][c] = data[c][r];
        }
        return table;
    } catch (const H5::Exception& e) {
        throw fail(msg("cannot read it (", detailOf(e), ")"));
    }
}

StatsWriter::StatsWriter(std::string h5Path, std::string csvPath)
    : mH5Path(std::move(h5Path))
    , mCsvPath(std::move(csvPath))
{}

void StatsWriter::append(const StatsRow& row)
{
    if (mTable.columns.empty()) {
        if (row.values.empty()) throw ValueError("statistics row: no columns");
        std::set<std::string> seen;
        for (const auto& [name, value] : row.values) {
            checkColumnName(name);
            if (!seen.insert(name).second) {
                throw ValueError(msg("statistics row: column '", name, "' appears twice"));
            }
        }
        for (const auto& [name, value] : row.values) mTable.columns.push_back(name);
    } else {
        const auto& columns = mTable.columns;
        for (std::size_t c = 0; c < std::max(columns.size(), row.values.size()); ++c) {
            const std::string expected = c < columns.size() ? columns[c] : "(none)";
            const std::string got = c < row.values.size() ? row.values[c].first : "(none)";
            if (expected != got) {
                throw ValueError(msg("statistics row ", mTable.rows.size(), ": column ", c, " is '",
                                     got, "', expected '", expected,
                                     "' (the columns "
                                     "are fixed by the first row: ",
                                     columns.size(), " columns, this row has ", row.values.size(),
                                     ")"));
            }
        }
    }
    std::vector<double> values;
    values.reserve(row.values.size());
    for (const auto& [name, value] : row.values) values.push_back(value);
    mTable.rows.push_back(std::move(values));
}

void StatsWriter::flush()
{
    if (mTable.columns.empty()) return;
    H5::Exception::dontPrint();
    writeAtomically(mH5Path, [&](const std::string& tmp) {
        try {
            writeH5(tmp, mTable, mBodies);
        } catch (const H5::Exception& e) {
            throw IoError(msg("statistics '", mH5Path, "': cannot write it (", detailOf(e), ")"));
        }
    });
    writeAtomically(mCsvPath, [&](const std::string& tmp) {
        try {
            writeCsv(tmp, mTable);
        } catch (const IoError&) {
            throw IoError(msg("statistics '", mCsvPath, "': cannot write it"));
        }
    });
}

void StatsWriter::resumeFrom(std::int64_t step)
{
    std::error_code ec;
    if (!std::filesystem::exists(mH5Path, ec)) {
        mTable = StatsTable();
        return;
    }
    StatsTable table = readStats(mH5Path);
    const auto it = std::find(table.columns.begin(), table.columns.end(), "step");
    if (it == table.columns.end()) {
        throw IoError(msg("statistics '", mH5Path, "': no 'step' column, so the rows up to step ",
                          step, " cannot be told apart"));
    }
    const std::size_t c = std::size_t(it - table.columns.begin());
    std::vector<std::vector<double>> kept;
    for (auto& row : table.rows) {
        if (row[c] <= double(step)) kept.push_back(std::move(row));
    }
    table.rows = std::move(kept);
    mTable = std::move(table);
}

} // namespace vdbio
} // namespace ghostfx
