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
  Flush();
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
  std::size_t written = 0;
  while (written < buffer_.size()) {
    const ssize_t n = ::write(fd_, buffer_.data() + written, buffer_.size() - written);
    if (n < 0) {
      if (errno == EINTR) continue;
      throw std::runtime_error(path_ + ": write failed: " + std::strerror(errno));
    }
    written += static_cast<std::size_t>(n);
  }
  buffer_.clear();
}

}  // namespace mjslam::rundir
