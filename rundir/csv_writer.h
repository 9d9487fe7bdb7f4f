#pragma once

#include <sys/types.h>

#include <string>
#include <string_view>
#include <vector>

namespace mjslam::rundir {

/// Writes a CSV file so that an interrupted or failed run never leaves a
/// corrupt one: rows are buffered whole and handed to the kernel with one
/// write() per flush, so the file always ends at a row boundary. Numbers are
/// printed shortest round-trip, so reading them back gives the same doubles.
class CsvWriter {
 public:
  /// Creates (truncates) `path` and writes the header. Throws
  /// std::runtime_error naming the file when it cannot be opened.
  CsvWriter(const std::string& path, const std::vector<std::string>& columns);
  ~CsvWriter();
  CsvWriter(const CsvWriter&) = delete;
  CsvWriter& operator=(const CsvWriter&) = delete;

  /// Appends one field to the current row.
  void Add(double value);
  void Add(int value);
  void Add(std::string_view text);
  /// An empty field.
  void AddEmpty();
  /// Ends the current row; checks it has as many fields as the header.
  void EndRow();
  /// Hands every complete row to the kernel. On a write error (a full
  /// disk, a file size limit) cuts the file back to the end of the last row
  /// that was whole before this flush, drops the rows not written and throws
  /// std::runtime_error naming the file and the reason; later rows are
  /// dropped too (the file stays as it was cut).
  void Flush();

  const std::string& path() const { return path_; }

 private:
  void Separator();

  std::string path_;
  int fd_ = -1;
  // Bytes of whole rows in the file; a failed flush cuts the file back here.
  off_t rows_end_ = 0;
  // A flush failed: nothing more is written.
  bool failed_ = false;
  int num_columns_ = 0;
  int fields_in_row_ = 0;
  std::string row_;
  std::string buffer_;
};

/// Shortest round-trip text of a double ("nan" and "inf" spelled so).
std::string FormatDouble(double value);

/// `text` as one field of a CSV line (RFC 4180): as is, or, when it holds a
/// comma, a double quote or a line end, in double quotes with each double
/// quote doubled.
std::string CsvField(const std::string& text);

}  // namespace mjslam::rundir
