// The column lists of rundir/layout.h are the single source of the column
// tables of docs/run_directory.md: these tests parse the documented tables
// and fail when either side changes alone.
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "rundir/layout.h"

namespace mjslam::rundir {
namespace {

std::string ReadDocs() {
  std::ifstream in(std::string(MJSLAM_SOURCE_DIR) + "/docs/run_directory.md");
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

std::vector<std::string> Split(const std::string& text, char separator) {
  std::vector<std::string> parts;
  std::string part;
  std::istringstream in(text);
  while (std::getline(in, part, separator)) parts.push_back(part);
  return parts;
}

// The column names of the first table under the heading line `heading`: the
// first `code span` of each row's first cell, split at commas; "..." stands
// for the numbered names between its neighbours (r0,...,r180).
std::vector<std::string> DocumentedColumns(const std::string& docs, const std::string& heading) {
  std::vector<std::string> columns;
  bool in_section = false;
  int table_rows = 0;
  for (const std::string& line : Split(docs, '\n')) {
    if (line.rfind("#", 0) == 0) {
      if (in_section) break;
      in_section = line == heading;
      continue;
    }
    if (!in_section) continue;
    if (line.rfind("|", 0) != 0) {
      if (table_rows > 0) break;  // the end of the first table
      continue;
    }
    if (++table_rows <= 2) continue;  // header and separator
    const std::string cell = line.substr(1, line.find('|', 1) - 1);
    const std::size_t open = cell.find('`');
    const std::size_t close = cell.find('`', open + 1);
    if (open == std::string::npos || close == std::string::npos) {
      ADD_FAILURE() << heading << ": a row without a column name: " << line;
      continue;
    }
    for (const std::string& name : Split(cell.substr(open + 1, close - open - 1), ',')) {
      columns.push_back(name);
    }
  }
  // Expand "..." between two numbered names with the same stem.
  std::vector<std::string> expanded;
  for (std::size_t i = 0; i < columns.size(); ++i) {
    if (columns[i] != "..." || i == 0 || i + 1 == columns.size()) {
      expanded.push_back(columns[i]);
      continue;
    }
    const std::string& first = columns[i - 1];
    const std::string& last = columns[i + 1];
    const std::string stem = first.substr(0, first.find_first_of("0123456789"));
    const int from = std::stoi(first.substr(stem.size()));
    const int to = std::stoi(last.substr(stem.size()));
    for (int k = from + 1; k < to; ++k) expanded.push_back(stem + std::to_string(k));
  }
  return expanded;
}

TEST(LayoutTest, DocumentedTrajectoryColumnsAreTheWrittenOnes) {
  // The table lists the shared columns, then the per-filter ones as f_<suffix>.
  const std::vector<std::string> documented =
      DocumentedColumns(ReadDocs(), "## `trajectory.csv`");
  std::vector<std::string> shared;
  std::vector<std::string> suffixes;
  for (const std::string& column : documented) {
    if (column.rfind("f_", 0) == 0) {
      suffixes.push_back(column.substr(2));
    } else {
      EXPECT_TRUE(suffixes.empty()) << column << " is documented after the per-filter columns";
      shared.push_back(column);
    }
  }
  EXPECT_EQ(suffixes, FilterColumnSuffixes());
  std::vector<std::string> expected = shared;
  for (const std::string& name : DefaultFilterNames()) {
    for (const std::string& suffix : suffixes) expected.push_back(name + "_" + suffix);
  }
  EXPECT_EQ(expected, TrajectoryColumns());
}

TEST(LayoutTest, DocumentedColumnsOfTheOtherFilesAreTheWrittenOnes) {
  const std::string docs = ReadDocs();
  EXPECT_EQ(DocumentedColumns(docs, "## `scans.csv`"), ScanColumns(181));
  EXPECT_EQ(DocumentedColumns(docs, "## `explorer.csv`"), ExplorerColumns());
  EXPECT_EQ(DocumentedColumns(docs, "## Map CSVs"), MapColumns());
  EXPECT_EQ(DocumentedColumns(docs, "## `reference.csv` (imported logs)"), ReferenceColumns());
  EXPECT_EQ(DocumentedColumns(docs, "## `divergence.csv`"), DivergenceColumns());
  EXPECT_EQ(DocumentedColumns(docs, "## `nees.csv` (sweep directory)"), NeesColumns());
}

TEST(LayoutTest, ParserSeesAChangedTable) {
  // A renamed column, a missing row and a missing section all show.
  const std::string docs =
      "## `explorer.csv`\n\n| Column | Meaning |\n|---|---|\n| `t` | time |\n"
      "| `kind` | kind |\n| `idx` | index |\n| `x,y` | point |\n\nText.\n| `z` | not a row |\n";
  EXPECT_EQ(DocumentedColumns(docs, "## `explorer.csv`"),
            (std::vector<std::string>{"t", "kind", "idx", "x", "y"}));
  EXPECT_NE(DocumentedColumns(docs, "## `explorer.csv`"), ExplorerColumns());
  EXPECT_TRUE(DocumentedColumns(docs, "## `scans.csv`").empty());
}

TEST(LayoutTest, EveryFileIsDocumented) {
  const std::string docs = ReadDocs();
  for (const std::string file :
       {kConfigFile, kManifestFile, kSummaryFile, kTrajectoryFile, kScansFile, kExplorerFile,
        kGroundTruthMapFile, kDivergenceFile, kVideoFile, kFinalImageFile, kNeesFile,
        kReferenceFile}) {
    EXPECT_NE(docs.find("`" + file + "`"), std::string::npos) << file;
  }
  for (const std::string& name : DefaultFilterNames()) {
    EXPECT_NE(docs.find("`" + MapFile(name) + "`"), std::string::npos) << name;
  }
}

TEST(LayoutTest, FilterNamesComeFromTheTrajectoryHeader) {
  const std::vector<std::string> names = {"ekf_a", "dead_reckoning", "x"};
  EXPECT_EQ(TrajectoryFilterNames(TrajectoryColumns(names)), names);
  EXPECT_EQ(TrajectoryFilterNames(TrajectoryColumns()), DefaultFilterNames());
  EXPECT_TRUE(TrajectoryFilterNames(RecordedTrajectoryColumns()).empty());
  EXPECT_EQ(HeaderLine(NeesColumns({"a", "b", "c"})), "t,a_anees,b_anees,c_anees,lower,upper,n_runs\n");
}

TEST(LayoutTest, HeaderLineJoinsTheColumns) {
  EXPECT_EQ(HeaderLine(MapColumns()), "id,type,p0,p1,c00,c01,c11,ax,ay,bx,by\n");
  EXPECT_EQ(HeaderLine(NeesColumns()), "t,classical_anees,selective_anees,lower,upper,n_runs\n");
  EXPECT_EQ(PathIn("a/b", kScansFile), "a/b/scans.csv");
}

}  // namespace
}  // namespace mjslam::rundir
