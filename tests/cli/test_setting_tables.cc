/// @file   test_setting_tables.cc
/// @brief  docs/scene-format.md's settings tables against the settings tables of the solvers
///         (ghostfx/sph/SettingSpec.h): each declared scene key has a row with its default,
///         range and unit as declared, and the doc has no row that is not declared.
#include <ghostfx/gas/GasSettings.h>
#include <ghostfx/gas/PhaseTransition.h>
#include <ghostfx/ghost/GhostSettings.h>
#include <ghostfx/ghost/Whitewater.h>
#include <ghostfx/sph/SettingSpec.h>

#include <gtest/gtest.h>

#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

namespace {

using namespace ghostfx;

const std::string DOC = std::string(GHOSTFX_SOURCE_DIR) + "/docs/scene-format.md";
const char* HEADER = "| key | default | range | unit | meaning |";

/// A doc row's cells, without backticks and surrounding blanks.
struct DocRow
{
    std::string defaultText, range, unit;
};

std::string trimmed(std::string s)
{
    std::string out;
    for (char c : s)
        if (c != '`') out += c;
    const std::size_t a = out.find_first_not_of(' '), b = out.find_last_not_of(' ');
    return a == std::string::npos ? std::string() : out.substr(a, b - a + 1);
}

/// The cells of a table line "| a | b \| c |": split at each '|' that is not escaped.
std::vector<std::string> cellsOf(const std::string& line)
{
    std::vector<std::string> cells;
    std::string cell;
    for (std::size_t i = 1; i < line.size(); ++i) {
        if (line[i] == '|' && line[i - 1] != '\\') {
            cells.push_back(trimmed(cell));
            cell.clear();
        } else {
            cell += line[i];
        }
    }
    return cells;
}

/// The rows, by key, of the table that follows the line `heading` in the doc; fails the test
/// when the heading is missing or its table has another header.
std::map<std::string, DocRow> docTable(const std::string& heading)
{
    std::ifstream in(DOC);
    std::string line;
    while (std::getline(in, line) && line != heading) {}
    EXPECT_EQ(line, heading) << DOC << " has no heading '" << heading << "'";
    while (std::getline(in, line) && line.rfind("|", 0) != 0) {}
    EXPECT_EQ(line, HEADER) << "the table under '" << heading << "'";
    std::getline(in, line); // |---|---|...
    std::map<std::string, DocRow> rows;
    while (std::getline(in, line) && line.rfind("|", 0) == 0) {
        const std::vector<std::string> c = cellsOf(line);
        EXPECT_EQ(c.size(), 5u) << line;
        if (c.size() == 5) rows[c[0]] = DocRow{c[1], c[2], c[3]};
    }
    return rows;
}

/// Every scene key of `table` has its row under `heading`, with the declared default, range
/// and unit, and every row of that doc table is a declared key.
template <typename S>
void expectDocMatches(const std::string& heading, const sph::SettingTable<S>& table)
{
    const std::map<std::string, DocRow> doc = docTable(heading);
    const S defaults;
    std::map<std::string, bool> declared;
    for (const sph::SettingSpec<S>& row : table.rows) {
        if (!row.key) continue;
        declared[row.key] = true;
        const auto it = doc.find(row.key);
        if (it == doc.end()) {
            ADD_FAILURE() << "'" << heading << "' has no row for declared key " << row.key;
            continue;
        }
        EXPECT_EQ(it->second.defaultText, row.defaultShown(defaults)) << row.key << ": default";
        EXPECT_EQ(it->second.range, row.rangeShown()) << row.key << ": range";
        EXPECT_EQ(it->second.unit, row.unit) << row.key << ": unit";
    }
    for (const auto& [key, row] : doc)
        EXPECT_TRUE(declared.count(key)) << "'" << heading << "' documents undeclared key " << key;
}

TEST(SettingTables, LiquidSettingsAreDocumentedAsDeclared)
{
    expectDocMatches("### settings of a liquid scene", ghost::liquidSettingTable());
}

TEST(SettingTables, DfsphSettingsAreDocumentedAsDeclared)
{
    expectDocMatches("### settings.dfsph (liquids with `pressure` `dfsph`)",
                     ghost::dfsphSettingTable());
}

TEST(SettingTables, WhitewaterSettingsAreDocumentedAsDeclared)
{
    expectDocMatches("### settings.whitewater (liquid scenes with `outputs.whitewater`)",
                     ghost::whitewaterSettingTable());
}

TEST(SettingTables, GasSettingsAreDocumentedAsDeclared)
{
    expectDocMatches("### settings.gas (gas scenes and boiling)", gas::gasSettingTable());
}

TEST(SettingTables, PhaseTransitionSettingsAreDocumentedAsDeclared)
{
    expectDocMatches("## heaters and phase_transition", gas::phaseSettingTable());
}

// The defaults of the declarations are the structs' own: a table row reads and writes its field.
TEST(SettingTables, RowsReachTheirFields)
{
    ghost::GhostSettings s;
    for (const auto& row : ghost::liquidSettingTable().rows) {
        if (row.key && std::string(row.key) == "stiffness") row.setNumber(s, 5000);
        if (row.key && std::string(row.key) == "solid_slip") row.setChoice(s, "no_slip");
    }
    EXPECT_EQ(s.stiffness, ghost::Real(5000));
    EXPECT_EQ(s.solidSlip, ghost::SolidSlip::NoSlip);
    for (const auto& row : ghost::dfsphSettingTable().rows) {
        if (std::string(row.key) == "kept_gradients_gb") {
            EXPECT_EQ(row.numberOf(s.dfsph), 4.0);
            row.setNumber(s.dfsph, 1);
        }
    }
    EXPECT_EQ(s.dfsph.keptGradientLimit, 1024.0 * 1024.0 * 1024.0);
}

} // namespace
