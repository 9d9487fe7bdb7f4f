#pragma once

// Helpers of the integration tests: run the mjslam program, read its files.
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <csignal>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "rundir/csv_reader.h"

namespace mjslam::testing {

/// A fresh, empty folder under the temporary directory, private to this
/// process (ctest runs tests of one suite in parallel processes).
inline std::string FreshDir(const std::string& name) {
  const std::filesystem::path dir = std::filesystem::temp_directory_path() / "mjslam_it" /
                                    std::to_string(::getpid()) / name;
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  return dir.string();
}

/// Path of the mjslam program (the environment's MJSLAM_TEST_PROGRAM when
/// set: to show that a test fails with an older binary) and of the default
/// config.
inline std::string Program() {
  const char* other = std::getenv("MJSLAM_TEST_PROGRAM");
  return other != nullptr && *other != '\0' ? std::string(other)
                                            : std::string(MJSLAM_BINARY_DIR) + "/mjslam";
}
inline std::string DefaultConfig() {
  return std::string(MJSLAM_SOURCE_DIR) + "/configs/default.yaml";
}

/// Runs a shell command; returns its exit status (or -1).
inline int Shell(const std::string& command) {
  const int status = std::system(command.c_str());
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

// Sends SIGTERM to `child` after `after_ms`, waits for it, and returns the
// seconds from the signal to its end; `*status` gets its wait status.
inline double StopAfter(pid_t child, int after_ms, int* status) {
  std::this_thread::sleep_for(std::chrono::milliseconds(after_ms));
  ::kill(child, SIGTERM);
  const auto signalled = std::chrono::steady_clock::now();
  ::waitpid(child, status, 0);
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - signalled).count();
}

/// Whole text of a file.
inline std::string ReadText(const std::string& path) {
  std::ifstream in(path);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

/// A table without the columns whose name ends with `suffix` (e.g. "_us",
/// the measured processing times, which differ from run to run).
inline rundir::CsvTable DropColumns(const rundir::CsvTable& table, const std::string& suffix) {
  rundir::CsvTable out;
  out.path = table.path;
  std::vector<int> keep;
  for (int i = 0; i < static_cast<int>(table.columns.size()); ++i) {
    const std::string& c = table.columns[i];
    if (c.size() >= suffix.size() && c.compare(c.size() - suffix.size(), suffix.size(), suffix) == 0) {
      continue;
    }
    keep.push_back(i);
    out.columns.push_back(c);
  }
  for (const std::vector<double>& row : table.rows) {
    std::vector<double> kept;
    for (const int i : keep) kept.push_back(row[i]);
    out.rows.push_back(std::move(kept));
  }
  return out;
}

}  // namespace mjslam::testing
