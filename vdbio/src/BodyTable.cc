/// @file   BodyTable.cc
/// @brief  Dynamic solids' rows in CSV and in the statistics file's `/bodies` group (BodyTable.h).
#include "BodyTableH5.h"

#include <ghostfx/sph/Exceptions.h>
#include <ghostfx/vdbio/AtomicFile.h>

#include <charconv>
#include <filesystem>
#include <fstream>
#include <sstream>

namespace ghostfx {
namespace vdbio {

namespace {

constexpr const char* BODIES = "bodies";

/// The shortest decimal text that reads back as the same double.
std::string formatNumber(double value)
{
    char buffer[64];
    const auto result = std::to_chars(buffer, buffer + sizeof(buffer), value);
    return std::string(buffer, result.ptr);
}

/// A CSV field: as it is, or in double quotes (quotes doubled) if it holds , " or a line break.
std::string csvField(const std::string& text)
{
    if (text.find_first_of(",\"\r\n") == std::string::npos) return text;
    std::string quoted = "\"";
    for (char c : text) quoted += c == '"' ? std::string("\"\"") : std::string(1, c);
    return quoted + "\"";
}

/// The fields of one CSV line (RFC 4180 quotes); false if a quote is left open.
bool splitCsv(const std::string& line, std::vector<std::string>& fields)
{
    fields.assign(1, std::string());
    bool quoted = false;
    for (std::size_t i = 0; i < line.size(); ++i) {
        const char c = line[i];
        if (quoted && c == '"' && i + 1 < line.size() && line[i + 1] == '"') {
            fields.back() += '"';
            ++i;
        } else if (c == '"') {
            quoted = !quoted;
        } else if (c == ',' && !quoted) {
            fields.emplace_back();
        } else {
            fields.back() += c;
        }
    }
    return !quoted;
}

bool parseNumber(const std::string& text, double& value)
{
    const char* end = text.data() + text.size();
    const auto result = std::from_chars(text.data(), end, value);
    return result.ec == std::errc() && result.ptr == end;
}

/// One data line of bodies.csv; throws IoError naming the file and line.
BodyRow parseRow(const std::string& path, int lineNumber, const std::string& line)
{
    std::vector<std::string> fields;
    const std::size_t count = bodyColumns().size();
    if (!splitCsv(line, fields) || fields.size() != count) {
        throw IoError(msg("bodies '", path, "': line ", lineNumber, " has ", fields.size(),
                          " fields, expected ", count, " (", "frame,time,name,...)"));
    }
    BodyRow row;
    double frame = 0;
    bool ok = parseNumber(fields[0], frame) && parseNumber(fields[1], row.time);
    row.frame = int(frame);
    row.name = fields[2];
    for (std::size_t v = 0; v < BODY_VALUES; ++v)
        ok = ok && parseNumber(fields[3 + v], row.values[v]);
    if (!ok || double(row.frame) != frame) {
        throw IoError(msg("bodies '", path, "': line ", lineNumber,
                          ": expected numbers in every "
                          "column but 'name'"));
    }
    return row;
}

void writeStringAttribute(H5::H5Object& object, const std::string& name, const std::string& value)
{
    const H5::StrType type(H5::PredType::C_S1, H5T_VARIABLE);
    H5::Attribute attr = object.createAttribute(name, type, H5::DataSpace(H5S_SCALAR));
    attr.write(type, value);
}

/// The values of numeric column `c` of bodyColumns() over `rows`.
std::vector<double> columnValues(const std::vector<BodyRow>& rows, std::size_t c)
{
    std::vector<double> values;
    values.reserve(rows.size());
    for (const BodyRow& r : rows)
        values.push_back(c == 0 ? double(r.frame) : c == 1 ? r.time : r.values[c - 3]);
    return values;
}

} // namespace

const std::vector<std::string>& bodyColumns()
{
    static const std::vector<std::string> columns = {"frame", "time", "name", "x",  "y",  "z",
                                                     "qw",    "qx",   "qy",   "qz", "vx", "vy",
                                                     "vz",    "wx",   "wy",   "wz"};
    return columns;
}

std::string bodyUnit(const std::string& column)
{
    if (column == "frame" || column[0] == 'q') return "1";
    if (column == "time") return "s";
    if (column[0] == 'v') return "m/s";
    if (column[0] == 'w') return "rad/s";
    return "m";
}

void writeBodiesCsv(const std::string& path, const std::vector<BodyRow>& rows)
{
    std::string text;
    for (const std::string& c : bodyColumns()) text += (text.empty() ? "" : ",") + c;
    text += '\n';
    for (const BodyRow& r : rows) {
        text += msg(r.frame, ",", formatNumber(r.time), ",", csvField(r.name));
        for (double v : r.values) text += "," + formatNumber(v);
        text += '\n';
    }
    writeTextFile(path, text, "bodies");
}

std::vector<BodyRow> readBodiesCsv(const std::string& path)
{
    std::ifstream in(path, std::ios::binary);
    if (!in) throw IoError(msg("bodies '", path, "': cannot open it"));
    std::string line, header;
    std::getline(in, header);
    std::string expected;
    for (const std::string& c : bodyColumns()) expected += (expected.empty() ? "" : ",") + c;
    if (header != expected) {
        throw IoError(
            msg("bodies '", path, "': line 1 is '", header, "', expected '", expected, "'"));
    }
    std::vector<BodyRow> rows;
    for (int n = 2; std::getline(in, line); ++n) {
        if (!line.empty()) rows.push_back(parseRow(path, n, line));
    }
    return rows;
}

void writeBodiesGroup(H5::H5File& file, const std::vector<BodyRow>& rows)
{
    if (rows.empty()) return;
    H5::Group group = file.createGroup(BODIES);
    const H5::StrType stringType(H5::PredType::C_S1, H5T_VARIABLE);
    const std::vector<std::string>& columns = bodyColumns();
    std::vector<const char*> names;
    for (const std::string& c : columns) names.push_back(c.c_str());
    const hsize_t columnCount = columns.size(), count = rows.size();
    group.createAttribute("columns", stringType, H5::DataSpace(1, &columnCount))
        .write(stringType, names.data());
    for (std::size_t c = 0; c < columns.size(); ++c) {
        if (columns[c] == "name") continue;
        H5::DataSet set =
            group.createDataSet(columns[c], H5::PredType::NATIVE_DOUBLE, H5::DataSpace(1, &count));
        set.write(columnValues(rows, c).data(), H5::PredType::NATIVE_DOUBLE);
        writeStringAttribute(set, "unit", bodyUnit(columns[c]));
    }
    std::vector<const char*> bodyNames;
    for (const BodyRow& r : rows) bodyNames.push_back(r.name.c_str());
    group.createDataSet("name", stringType, H5::DataSpace(1, &count))
        .write(bodyNames.data(), stringType);
}

std::vector<BodyRow> readStatsBodies(const std::string& h5Path)
{
    H5::Exception::dontPrint();
    try {
        H5::H5File h5(h5Path, H5F_ACC_RDONLY);
        if (!h5.nameExists(BODIES)) return {};
        H5::Group group = h5.openGroup(BODIES);
        H5::DataSet nameSet = group.openDataSet("name");
        hsize_t count = 0;
        nameSet.getSpace().getSimpleExtentDims(&count);
        std::vector<BodyRow> rows(count);
        std::vector<char*> names(count, nullptr);
        if (count > 0) nameSet.read(names.data(), H5::StrType(H5::PredType::C_S1, H5T_VARIABLE));
        for (hsize_t r = 0; r < count; ++r) {
            rows[r].name = names[r] ? names[r] : "";
            H5free_memory(names[r]);
        }
        const std::vector<std::string>& columns = bodyColumns();
        std::vector<double> values(count);
        for (std::size_t c = 0; c < columns.size(); ++c) {
            if (columns[c] == "name") continue;
            H5::DataSet set = group.openDataSet(columns[c]);
            hsize_t n = 0;
            set.getSpace().getSimpleExtentDims(&n);
            if (n != count) {
                throw IoError(msg("statistics '", h5Path, "': '/bodies/", columns[c], "' has ", n,
                                  " rows, '/bodies/name' ", count));
            }
            if (count > 0) set.read(values.data(), H5::PredType::NATIVE_DOUBLE);
            for (hsize_t r = 0; r < count; ++r) {
                if (c == 0) rows[r].frame = int(values[r]);
                else if (c == 1) rows[r].time = values[r];
                else rows[r].values[c - 3] = values[r];
            }
        }
        return rows;
    } catch (const H5::Exception& e) {
        throw IoError(
            msg("statistics '", h5Path, "': cannot read '/bodies' (", e.getDetailMsg(), ")"));
    }
}

void BodyLog::flush() const
{
    if (!mRows.empty()) writeBodiesCsv(mCsvPath, mRows);
}

void BodyLog::resumeFrom(int frame)
{
    mRows.clear();
    std::error_code ec;
    if (!std::filesystem::exists(mCsvPath, ec)) return;
    for (BodyRow& row : readBodiesCsv(mCsvPath)) {
        if (row.frame <= frame) mRows.push_back(std::move(row));
    }
}

} // namespace vdbio
} // namespace ghostfx
