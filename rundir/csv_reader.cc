#include "rundir/csv_reader.h"

#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <limits>
#include <sstream>
#include <stdexcept>

#include "rundir/csv_writer.h"

namespace mjslam::rundir {
namespace {

std::vector<std::string> SplitFields(const std::string& line) {
  std::vector<std::string> fields;
  std::string field;
  std::istringstream in(line);
  while (std::getline(in, field, ',')) fields.push_back(field);
  if (!line.empty() && line.back() == ',') fields.emplace_back();
  return fields;
}

}  // namespace

int CsvTable::ColumnIndex(const std::string& column) const {
  for (std::size_t i = 0; i < columns.size(); ++i) {
    if (columns[i] == column) return static_cast<int>(i);
  }
  throw std::runtime_error(path + ": missing column '" + column + "'");
}

namespace {

// Reads the header line of `in` (file `path`) into its columns.
std::vector<std::string> ReadHeaderLine(std::istream& in, const std::string& path) {
  std::string line;
  if (!std::getline(in, line)) throw std::runtime_error(path + ": empty file, expected a header");
  if (in.eof()) throw std::runtime_error(path + ":1: the header has no line end (the file was cut short)");
  if (!line.empty() && line.back() == '\r') line.pop_back();  // CRLF line ends
  return SplitFields(line);
}

}  // namespace

std::vector<std::string> ReadCsvHeader(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error(path + ": cannot read");
  return ReadHeaderLine(in, path);
}

CsvTable ReadCsv(const std::string& path, const std::vector<std::string>& text_columns) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error(path + ": cannot read");
  CsvTable table;
  table.path = path;
  table.columns = ReadHeaderLine(in, path);
  std::string line;
  std::vector<bool> is_text(table.columns.size(), false);
  for (std::size_t i = 0; i < table.columns.size(); ++i) {
    for (const std::string& name : text_columns) is_text[i] = is_text[i] || name == table.columns[i];
  }
  int line_number = 1;
  while (std::getline(in, line)) {
    ++line_number;
    // getline stops at the end of the file without a line end only on a
    // last row that was cut short.
    if (in.eof() && !line.empty()) {
      throw std::runtime_error(path + ":" + std::to_string(line_number) +
                               ": the last row has no line end (the file was cut short)");
    }
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (line.empty()) continue;
    const std::vector<std::string> fields = SplitFields(line);
    if (fields.size() != table.columns.size()) {
      throw std::runtime_error(path + ":" + std::to_string(line_number) + ": expected " +
                               std::to_string(table.columns.size()) + " fields (got " +
                               std::to_string(fields.size()) + ")");
    }
    std::vector<double> row(fields.size());
    std::vector<std::string> text;
    for (std::size_t i = 0; i < fields.size(); ++i) {
      if (is_text[i]) {
        text.push_back(fields[i]);
        row[i] = std::numeric_limits<double>::quiet_NaN();
        continue;
      }
      if (fields[i].empty()) {
        row[i] = std::numeric_limits<double>::quiet_NaN();
        continue;
      }
      char* end = nullptr;
      errno = 0;
      row[i] = std::strtod(fields[i].c_str(), &end);
      if (end == fields[i].c_str() || *end != '\0' || (errno == ERANGE && std::isinf(row[i]))) {
        throw std::runtime_error(path + ":" + std::to_string(line_number) + ": column " +
                                 table.columns[i] + ": expected a number (got '" + fields[i] +
                                 "')");
      }
    }
    table.rows.push_back(std::move(row));
    table.text.push_back(std::move(text));
    table.lines.push_back(line_number);
  }
  return table;
}

void CheckLeadingColumns(const CsvTable& table, const std::vector<std::string>& expected) {
  for (std::size_t c = 0; c < expected.size(); ++c) {
    if (c >= table.columns.size() || table.columns[c] != expected[c]) {
      throw std::runtime_error(table.path + ": expected column " + std::to_string(c + 1) +
                               " to be " + expected[c]);
    }
  }
}

void CheckIncreasingTimes(const CsvTable& table, int column) {
  for (std::size_t r = 0; r < table.rows.size(); ++r) {
    const double t = table.rows[r][column];
    const bool increasing = r == 0 || t > table.rows[r - 1][column];
    if (!std::isfinite(t) || !increasing) {
      throw std::runtime_error(table.path + ":" + std::to_string(table.lines[r]) + ": column " +
                               table.columns[column] +
                               (std::isfinite(t) ? ": expected a time after the row before's"
                                                 : ": expected a finite time") +
                               " (got " + FormatDouble(t) + ")");
    }
  }
}

void CheckValuesInRange(const CsvTable& table, int first, int count, double lo, double hi) {
  for (std::size_t r = 0; r < table.rows.size(); ++r) {
    for (int c = first; c < first + count; ++c) {
      const double value = table.rows[r][c];
      if (value >= lo && value <= hi) continue;  // false for NaN
      throw std::runtime_error(table.path + ":" + std::to_string(table.lines[r]) + ": column " +
                               table.columns[c] + ": expected a number in [" + FormatDouble(lo) +
                               ", " + FormatDouble(hi) + "] (got " + FormatDouble(value) + ")");
    }
  }
}

}  // namespace mjslam::rundir
