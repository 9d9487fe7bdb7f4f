#pragma once

#include <string>
#include <vector>

#include "common/map_feature.h"

namespace mjslam::rundir {

/// The map CSV files of a run directory (map_classical.csv,
/// map_selective.csv, ground_truth_map.csv): one row per feature,
/// MapColumns() of rundir/layout.h (docs/run_directory.md).

/// Reads a map CSV. Throws std::runtime_error naming the file, line and
/// value for an unknown type or a missing field.
FeatureMap ReadMapCsv(const std::string& path);

/// Writes a map CSV, atomically. Corner kinds are not written (the columns
/// have no place for them).
void WriteMapCsv(const std::string& path, const FeatureMap& map);

}  // namespace mjslam::rundir
