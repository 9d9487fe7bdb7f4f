#pragma once

// The readers of the program's input files as fuzz targets: each takes the
// bytes of one file, reads them as the program would, and checks what it
// accepted. A target returns normally when the input is read, or refused with
// the reader's documented error (std::runtime_error naming the file); any
// other exception, a crash, a hang or a sanitizer report is a finding.
// Driven by libFuzzer (fuzz/libfuzzer_main.cc, a long run by hand) and by the
// test suite's bounded mutation run (tests/fuzz/mutation_test.cc).

#include <string>
#include <string_view>
#include <vector>

namespace mjslam::fuzz {

/// One fuzz target: a name (also its corpus folder, fuzz/corpus/NAME) and the
/// function that reads one input. `scratch_path` is a file the target may
/// write the input to (readers of CSV files read paths).
struct Target {
  const char* name;
  void (*read)(std::string_view input, const std::string& scratch_path);
};

/// The targets: config (a YAML run config: LoadConfigString<RunConfig>; an
/// accepted one must write back as YAML that reads to the same YAML),
/// trajectory (ReadTrajectoryCsv; accepted: increasing finite times, finite
/// poses), scans (ReadScansCsv; accepted: ranges finite and >= 0), map
/// (ReadMapCsv; accepted: finite features), explorer (ReadExplorerCsv),
/// import (a CARMEN log and its relations through app::ImportLog without
/// writing; accepted: scans, a bounded skip report, a finite offset),
/// campaign (LoadCampaign and CampaignCells within 1000 cells; accepted:
/// distinct folders inside the campaign, campaign.csv of whole rows), world
/// (footprint lines through sim::CheckWorldExtent and BoxGrid;
/// accepted: a grid of bounded size holding every box).
/// A check of an accepted input that fails throws std::logic_error.
const std::vector<Target>& Targets();

/// The target named `name`; throws std::invalid_argument if there is none.
const Target& FindTarget(const std::string& name);

}  // namespace mjslam::fuzz
