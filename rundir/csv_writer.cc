#include "rundir/csv_writer.h"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstring>
#include <stdexcept>

#include "common/check.h"

namespace mjslam::rundir {
namespace {

// Flush when this many bytes of complete rows are waiting.
constexpr std::size_t kFlushBytes = 1 << 16;

}  // namespace

std::string FormatDouble(double value) {
  if (std::isnan(value)) return "nan";
  if (std::isinf(value)) return value > 0 ? "inf" : "-inf";
  char text[32];
  const auto result = std::to_chars(text, text + sizeof(text), value);
  return std::string(text, result.ptr);
}

CsvWriter::CsvWriter(const std::string& path, const std::vector<std::string>& columns)
    : path_(path), num_columns_(static_cast<int>(columns.size())) {
  fd_ = ::open(path.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd_ < 0) {
    throw std::runtime_error(path + ": cannot open for writing: " + std::strerror(errno));
  }
  for (const std::string& column : columns) Add(column);
  EndRow();
  try {
    Flush();
  } catch (const std::exception&) {
    ::close(fd_);  // the destructor does not run for a constructor that throws
    throw;
  }
}

CsvWriter::~CsvWriter() {
  try {
    Flush();
  } catch (const std::exception&) {
    // A destructor must not throw; the rows already written stay complete.
  }
  if (fd_ >= 0) ::close(fd_);
}

void CsvWriter::Separator() {
  if (fields_in_row_ > 0) row_ += ',';
  ++fields_in_row_;
}

void CsvWriter::Add(double value) {
  Separator();
  row_ += FormatDouble(value);
}

void CsvWriter::Add(int value) {
  Separator();
  row_ += std::to_string(value);
}

void CsvWriter::Add(std::string_view text) {
  Separator();
  row_ += text;
}

void CsvWriter::AddEmpty() { Separator(); }

void CsvWriter::EndRow() {
  MJSLAM_CHECK(fields_in_row_ == num_columns_);
  row_ += '\n';
  buffer_ += row_;
  row_.clear();
  fields_in_row_ = 0;
  if (buffer_.size() >= kFlushBytes) Flush();
}

void CsvWriter::Flush() {
  if (failed_) {
    buffer_.clear();
    return;
  }
  std::size_t written = 0;
  while (written < buffer_.size()) {
    const ssize_t n = ::write(fd_, buffer_.data() + written, buffer_.size() - written);
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) {
      // A part of the buffer may be on disk: cut the file back to its last
      // whole row, so that it never ends inside one.
      const std::string reason = std::strerror(errno);
      failed_ = true;
      buffer_.clear();
      const bool cut = ::ftruncate(fd_, rows_end_) == 0;
      throw std::runtime_error(path_ + ": write failed: " + reason +
                               (cut ? " (the file ends at its last whole row)"
                                    : " (and it could not be cut back to its last whole row)"));
    }
    written += static_cast<std::size_t>(n);
  }
  rows_end_ += static_cast<off_t>(written);
  buffer_.clear();
}

std::string CsvField(const std::string& text) {
  if (text.find_first_of(",\"\r\n") == std::string::npos) return text;
  std::string quoted = "\"";
  for (const char c : text) quoted += c == '"' ? std::string("\"\"") : std::string(1, c);
  return quoted + "\"";
}

}  // namespace mjslam::rundir
