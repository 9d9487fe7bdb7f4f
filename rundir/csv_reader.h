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

  /// Index of `column`; throws std::runtime_error naming the file and column
  /// when it is missing.
  int ColumnIndex(const std::string& column) const;
};

/// Reads a CSV file of numbers (empty fields read as NaN); the columns named
/// in `text_columns` may hold any text, kept in CsvTable::text. Throws
/// std::runtime_error naming the file, line and column of the first bad field
/// or a row with the wrong number of fields.
CsvTable ReadCsv(const std::string& path, const std::vector<std::string>& text_columns = {});

}  // namespace mjslam::rundir
