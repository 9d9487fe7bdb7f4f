#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <csignal>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

#include <gtest/gtest.h>

#include "rundir/csv_reader.h"
#include "rundir/csv_writer.h"
#include "rundir/manifest.h"

namespace mjslam::rundir {
namespace {

std::string TempPath(const std::string& name) {
  const std::filesystem::path dir = std::filesystem::temp_directory_path() / "mjslam_csv_test";
  std::filesystem::create_directories(dir);
  return (dir / name).string();
}

TEST(CsvTest, DoublesRoundTripExactly) {
  const std::string path = TempPath("round_trip.csv");
  const std::vector<double> values = {0.1, 1.0 / 3.0, -2.5e-300, 123456789.123456789, 0.0};
  {
    CsvWriter writer(path, {"a", "b"});
    for (const double v : values) {
      writer.Add(v);
      writer.Add(-v);
      writer.EndRow();
    }
  }
  const CsvTable table = ReadCsv(path);
  ASSERT_EQ(table.columns, (std::vector<std::string>{"a", "b"}));
  ASSERT_EQ(table.rows.size(), values.size());
  for (std::size_t i = 0; i < values.size(); ++i) {
    EXPECT_EQ(table.rows[i][0], values[i]);
    EXPECT_EQ(table.rows[i][1], -values[i]);
  }
  EXPECT_EQ(table.ColumnIndex("b"), 1);
  EXPECT_THROW(table.ColumnIndex("c"), std::runtime_error);
}

TEST(CsvTest, UnflushedRowsAreWholeAfterFlush) {
  const std::string path = TempPath("flush.csv");
  CsvWriter writer(path, {"x"});
  writer.Add(1.0);
  writer.EndRow();
  writer.Flush();
  writer.Add(2.0);  // a row in progress is not written
  std::ifstream in(path);
  std::stringstream text;
  text << in.rdbuf();
  EXPECT_EQ(text.str(), "x\n1\n");
  writer.EndRow();
}

TEST(CsvTest, EmptyFieldsReadAsNan) {
  const std::string path = TempPath("empty.csv");
  {
    CsvWriter writer(path, {"a", "b", "c"});
    writer.Add(1);
    writer.AddEmpty();
    writer.AddEmpty();
    writer.EndRow();
  }
  const CsvTable table = ReadCsv(path);
  ASSERT_EQ(table.rows.size(), 1u);
  EXPECT_EQ(table.rows[0][0], 1.0);
  EXPECT_TRUE(std::isnan(table.rows[0][1]));
  EXPECT_TRUE(std::isnan(table.rows[0][2]));
}

TEST(CsvTest, ReadsWindowsLineEnds) {
  // Files saved by spreadsheets and Python's csv module end lines with CRLF.
  const std::string path = TempPath("crlf.csv");
  std::ofstream(path) << "a,b\r\n1,2.5\r\n3,\r\n";
  const CsvTable table = ReadCsv(path);
  EXPECT_EQ(table.columns, (std::vector<std::string>{"a", "b"}));
  ASSERT_EQ(table.rows.size(), 2u);
  EXPECT_EQ(table.rows[0][1], 2.5);
  EXPECT_TRUE(std::isnan(table.rows[1][1]));
}

TEST(CsvTest, HeaderAloneIsTheTablesColumns) {
  // The header without the rows (a bad row below does not matter), with
  // ReadCsv's rules: CRLF, a trailing empty column; a header cut short or a
  // missing file throws naming the file.
  const std::string path = TempPath("header.csv");
  std::ofstream(path) << "t,classical_x,\r\nnot a number\n";
  EXPECT_EQ(ReadCsvHeader(path), (std::vector<std::string>{"t", "classical_x", ""}));
  const std::string cut = TempPath("header_cut.csv");
  std::ofstream(cut) << "t,classical_x";
  EXPECT_THROW(ReadCsvHeader(cut), std::runtime_error);
  try {
    ReadCsvHeader(TempPath("no_such.csv"));
    FAIL() << "no error";
  } catch (const std::runtime_error& error) {
    EXPECT_NE(std::string(error.what()).find("no_such.csv"), std::string::npos);
  }
}

TEST(CsvTest, BadInputNamesFileLineAndColumn) {
  const std::string path = TempPath("bad.csv");
  std::ofstream(path) << "t,x\n0,1\n0.1,abc\n";
  try {
    ReadCsv(path);
    FAIL() << "expected an error";
  } catch (const std::runtime_error& error) {
    EXPECT_NE(std::string(error.what()).find(path + ":3: column x"), std::string::npos)
        << error.what();
    EXPECT_NE(std::string(error.what()).find("abc"), std::string::npos);
  }
  std::ofstream(path) << "t,x\n0,1,2\n";
  EXPECT_THROW(ReadCsv(path), std::runtime_error);
  EXPECT_THROW(ReadCsv(TempPath("missing.csv")), std::runtime_error);
}

TEST(CsvTest, UnwritableFileIsAnErrorNamingIt) {
  try {
    CsvWriter writer("/nonexistent-folder/x.csv", {"a"});
    FAIL();
  } catch (const std::runtime_error& error) {
    EXPECT_NE(std::string(error.what()).find("/nonexistent-folder/x.csv"), std::string::npos);
  }
}

// A file size limit stands for a full disk: write() fails the same way
// (EFBIG instead of ENOSPC) once the file reaches it, after writing part of
// the buffer. The writer runs in a child process, whose limit ends with it.
TEST(CsvTest, FullDiskLeavesWholeRowsAndNamesTheFile) {
  const std::string path = TempPath("full.csv");
  const std::string message_path = TempPath("full.message");
  std::filesystem::remove(path);
  const pid_t child = ::fork();
  ASSERT_GE(child, 0);
  if (child == 0) {
    std::signal(SIGXFSZ, SIG_IGN);
    const rlimit limit{10000, 10000};
    ::setrlimit(RLIMIT_FSIZE, &limit);
    std::string message = "no error";
    try {
      CsvWriter writer(path, {"t", "x", "y"});
      for (int i = 0; i < 100000; ++i) {
        writer.Add(i * 0.1);
        writer.Add(1.0 / (i + 3));
        writer.Add(-2.0 / (i + 7));
        writer.EndRow();
        // Flushes of a few rows, as a run's: the one that hits the limit
        // is written in part.
        if (i % 7 == 6) writer.Flush();
      }
      writer.Flush();
    } catch (const std::exception& error) {
      message = error.what();
    }
    std::ofstream(message_path) << message;
    ::_exit(0);
  }
  int status = 0;
  ::waitpid(child, &status, 0);
  ASSERT_TRUE(WIFEXITED(status));
  std::ifstream message_in(message_path);
  std::stringstream message;
  message << message_in.rdbuf();
  EXPECT_NE(message.str().find(path + ": write failed"), std::string::npos) << message.str();
  EXPECT_NE(message.str().find("last whole row"), std::string::npos) << message.str();
  // The file ends at a row boundary and reads back whole.
  std::ifstream in(path);
  std::stringstream text;
  text << in.rdbuf();
  ASSERT_FALSE(text.str().empty());
  EXPECT_EQ(text.str().back(), '\n');
  EXPECT_LE(text.str().size(), 10000u);
  const CsvTable table = ReadCsv(path);
  EXPECT_GT(table.rows.size(), 100u);
}

// Issue 32, item 9: a manifest that does not fit (a full disk; here a file
// size limit of 100 bytes) left a file cut short (0 bytes on a full disk) and
// was reported as "std::exception": now the error names the file, a new
// manifest is not left behind and an old one keeps its contents.
TEST(CsvTest, AManifestThatDoesNotFitIsNotLeftHalfWritten) {
  const std::string dir = TempPath("manifest_full");
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir + "/new");
  std::filesystem::create_directories(dir + "/old");
  std::ofstream(dir + "/old/manifest.json") << "{\"status\": \"old\"}\n";
  const std::string message_path = dir + "/message";
  const pid_t child = ::fork();
  ASSERT_GE(child, 0);
  if (child == 0) {
    std::signal(SIGXFSZ, SIG_IGN);
    const rlimit limit{100, 100};
    ::setrlimit(RLIMIT_FSIZE, &limit);
    std::string message;
    for (const char* sub : {"/new", "/old"}) {
      try {
        ManifestWriter manifest(dir + sub, {{"padding", std::string(1000, 'x')}});
        message += "no error\n";
      } catch (const std::exception& error) {
        message += std::string(error.what()) + "\n";
      }
    }
    std::ofstream(message_path) << message;
    ::_exit(0);
  }
  int status = 0;
  ::waitpid(child, &status, 0);
  ASSERT_TRUE(WIFEXITED(status));
  std::ifstream message_in(message_path);
  std::stringstream message;
  message << message_in.rdbuf();
  EXPECT_NE(message.str().find(dir + "/new/manifest.json: write failed: File too large"),
            std::string::npos) << message.str();
  EXPECT_EQ(message.str().find("std::exception"), std::string::npos) << message.str();
  EXPECT_FALSE(std::filesystem::exists(dir + "/new/manifest.json"));
  std::ifstream old(dir + "/old/manifest.json");
  std::stringstream old_text;
  old_text << old.rdbuf();
  EXPECT_EQ(old_text.str(), "{\"status\": \"old\"}\n");
}

}  // namespace
}  // namespace mjslam::rundir
