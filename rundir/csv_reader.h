#pragma once

#include <string>
#include <vector>

namespace mjslam::rundir {

/// A numeric CSV file with a header row, read whole.
struct CsvTable {
  std::string path;
  std::vector<std::string> columns;
  std::vector<std::vector<double>> rows;
  /// The fields of the text columns (NaN in `rows`), by row.
  std::vector<std::vector<std::string>> text;
  /// The line of the file each row was read from (1 is the header).
  std::vector<int> lines;

  /// Index of `column`; throws std::runtime_error naming the file and column
  /// when it is missing.
  int ColumnIndex(const std::string& column) const;
};

/// Reads a CSV file of numbers (empty fields read as NaN; "nan", "inf" as
/// written by FormatDouble); the columns named in `text_columns` may hold any
/// text, kept in CsvTable::text. Throws std::runtime_error naming the file,
/// line and column of the first bad field, of a number beyond the range of a
/// double, or of a row with the wrong number of fields, and when the last row
/// has no line end (every writer ends its rows with one: such a file was cut
/// short, maybe inside its last field).
CsvTable ReadCsv(const std::string& path, const std::vector<std::string>& text_columns = {});

/// The columns of a CSV file's header line alone, with ReadCsv's rules;
/// throws as ReadCsv does for an unreadable file or a header cut short.
std::vector<std::string> ReadCsvHeader(const std::string& path);

/// Checks that the table's columns start with `expected`, in order. Throws
/// std::runtime_error naming the file and the first column that differs.
void CheckLeadingColumns(const CsvTable& table, const std::vector<std::string>& expected);

/// Checks that `column` of every row is a finite time (seconds) greater than
/// the row before's. Throws std::runtime_error naming the file, line, column
/// and the value.
void CheckIncreasingTimes(const CsvTable& table, int column);

/// Checks that the `count` columns from `first` of every row are finite and
/// in [lo, hi]. Throws std::runtime_error naming the file, line, column and
/// the value.
void CheckValuesInRange(const CsvTable& table, int first, int count, double lo, double hi);

}  // namespace mjslam::rundir
