#pragma once

#include <string>
#include <vector>

#include "eval/map_types.h"

namespace mjslam::app {

/// The map CSV files of a run directory (map_classical.csv,
/// map_selective.csv, ground_truth_map.csv): one row per feature,
/// id,type,p0,p1,c00,c01,c11,ax,ay,bx,by (README, "The run directory").

/// Reads a map CSV. Throws std::runtime_error naming the file, line and
/// value for an unknown type or a missing field.
eval::Map ReadMapCsv(const std::string& path);

/// Writes a map CSV, atomically. Corner kinds are not written (the columns
/// have no place for them).
void WriteMapCsv(const std::string& path, const eval::Map& map);

}  // namespace mjslam::app
