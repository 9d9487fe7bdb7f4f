#include "fuzz/fuzz_targets.h"

#include <cmath>
#include <fstream>
#include <optional>
#include <stdexcept>

#include "app/run_config.h"
#include "config/config.h"
#include "rundir/csv_reader.h"
#include "rundir/layout.h"
#include "rundir/map_csv.h"
#include "rundir/rows.h"

namespace mjslam::fuzz {
namespace {

// Throws std::logic_error (a finding) unless `ok`.
void Expect(bool ok, const std::string& what) {
  if (!ok) throw std::logic_error("accepted input breaks a promise: " + what);
}

void WriteScratch(std::string_view input, const std::string& path) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(input.data(), static_cast<std::streamsize>(input.size()));
  if (!out) throw std::logic_error(path + ": cannot write the fuzz input");
}

// What `read` makes of `input` (written to `scratch_path`), or none when it
// refused it with its documented error.
template <typename Reader>
auto ReadOrRefused(std::string_view input, const std::string& scratch_path, Reader read)
    -> std::optional<decltype(read(scratch_path))> {
  WriteScratch(input, scratch_path);
  try {
    return read(scratch_path);
  } catch (const std::runtime_error&) {
    return std::nullopt;  // refused, with a message
  }
}

void ReadConfig(std::string_view input, const std::string& /*scratch_path*/) {
  app::RunConfig config;
  try {
    config = config::LoadConfigString<app::RunConfig>(std::string(input), "fuzz.yaml");
  } catch (const std::runtime_error&) {
    return;  // refused, with a message
  }
  // What a run writes as its config.yaml reads back to the same config.
  const std::string yaml = config::ToYaml(config);
  const app::RunConfig again = config::LoadConfigString<app::RunConfig>(yaml, "config.yaml");
  Expect(config::ToYaml(again) == yaml, "config.yaml does not read back to itself");
}

// The numbers of the table's rows in `count` columns from `first` are finite.
void ExpectFinite(const rundir::CsvTable& table, int first, int count) {
  for (const std::vector<double>& row : table.rows) {
    for (int c = first; c < first + count; ++c) Expect(std::isfinite(row[c]), "a value not finite");
  }
}

void ExpectIncreasingTimes(const rundir::CsvTable& table) {
  for (std::size_t r = 0; r < table.rows.size(); ++r) {
    Expect(std::isfinite(table.rows[r][0]), "a time not finite");
    Expect(r == 0 || table.rows[r][0] > table.rows[r - 1][0], "a time going backwards");
  }
}

void ReadTrajectory(std::string_view input, const std::string& scratch_path) {
  const auto read = ReadOrRefused(input, scratch_path, rundir::ReadTrajectoryCsv);
  if (!read) return;
  const rundir::CsvTable& table = *read;
  Expect(!table.rows.empty(), "no rows");
  ExpectIncreasingTimes(table);
  ExpectFinite(table, 1, static_cast<int>(rundir::RecordedTrajectoryColumns().size()) - 1);
}

void ReadScans(std::string_view input, const std::string& scratch_path) {
  const auto read = ReadOrRefused(input, scratch_path, rundir::ReadScansCsv);
  if (!read) return;
  const rundir::CsvTable& table = *read;
  ExpectIncreasingTimes(table);
  ExpectFinite(table, 1, static_cast<int>(table.columns.size()) - 1);
  for (const std::vector<double>& row : table.rows) {
    for (std::size_t c = rundir::kScanRangesStart; c < row.size(); ++c) {
      Expect(row[c] >= 0.0, "a negative range");
    }
  }
}

void ReadMap(std::string_view input, const std::string& scratch_path) {
  const auto map = ReadOrRefused(input, scratch_path, rundir::ReadMapCsv);
  if (!map) return;
  for (const MapFeature& f : *map) {
    Expect(f.params.allFinite() && f.covariance.allFinite(), "a feature not finite");
    Expect(f.covariance(0, 0) >= 0.0 && f.covariance(1, 1) >= 0.0, "a negative variance");
  }
}

void ReadExplorer(std::string_view input, const std::string& scratch_path) {
  ReadOrRefused(input, scratch_path, rundir::ReadExplorerCsv);
}

}  // namespace

const std::vector<Target>& Targets() {
  static const std::vector<Target> kTargets = {{"config", ReadConfig},
                                               {"trajectory", ReadTrajectory},
                                               {"scans", ReadScans},
                                               {"map", ReadMap},
                                               {"explorer", ReadExplorer}};
  return kTargets;
}

const Target& FindTarget(const std::string& name) {
  for (const Target& target : Targets()) {
    if (name == target.name) return target;
  }
  throw std::invalid_argument("no fuzz target named '" + name + "'");
}

}  // namespace mjslam::fuzz
