#include "rundir/layout.h"

namespace mjslam::rundir {

const std::vector<std::string>& DefaultFilterNames() {
  static const std::vector<std::string> kNames = {"classical", "selective"};
  return kNames;
}

std::string MapFile(const std::string& filter_name) { return "map_" + filter_name + ".csv"; }

std::string PathIn(const std::string& dir, const std::string& file) { return dir + "/" + file; }

std::vector<std::string> RecordedTrajectoryColumns() {
  return {"t", "true_x", "true_y", "true_th", "odom_x", "odom_y", "odom_th", "cmd_v", "cmd_w"};
}

const std::vector<std::string>& FilterColumnSuffixes() {
  static const std::vector<std::string> kSuffixes = {
      "x",     "y",        "th",        "pxx", "pxy",    "pxth",      "pyy", "pyth",
      "pthth", "nfeat",    "nmatched",  "nupdated", "us", "period", "open_loop", "nees",
      "processed"};
  return kSuffixes;
}

std::vector<std::string> FilterColumns(const std::string& filter_name) {
  std::vector<std::string> columns;
  for (const std::string& suffix : FilterColumnSuffixes()) columns.push_back(filter_name + "_" + suffix);
  return columns;
}

std::vector<std::string> TrajectoryFilterNames(const std::vector<std::string>& columns) {
  std::vector<std::string> names;
  for (const std::string& column : columns) {
    if (column.size() <= 2 || column.compare(column.size() - 2, 2, "_x") != 0) continue;
    const std::string name = column.substr(0, column.size() - 2);
    if (name != "true" && name != "odom") names.push_back(name);
  }
  return names;
}

std::vector<std::string> TrajectoryColumns(const std::vector<std::string>& filter_names) {
  std::vector<std::string> columns = RecordedTrajectoryColumns();
  columns.push_back("explored");
  for (const std::string& name : filter_names) {
    for (const std::string& column : FilterColumns(name)) columns.push_back(column);
  }
  return columns;
}

std::vector<std::string> ScanColumns(int num_beams) {
  std::vector<std::string> columns = {"t", "x", "y", "th"};
  for (int i = 0; i < num_beams; ++i) columns.push_back("r" + std::to_string(i));
  return columns;
}

std::vector<std::string> ExplorerColumns() { return {"t", "kind", "index", "x", "y"}; }

std::vector<std::string> ReferenceColumns() { return {"t", "x", "y", "th"}; }

std::vector<std::string> MapColumns() {
  return {"id", "type", "p0", "p1", "c00", "c01", "c11", "ax", "ay", "bx", "by"};
}

std::vector<std::string> NeesColumns(const std::vector<std::string>& filter_names) {
  std::vector<std::string> columns = {"t"};
  for (const std::string& name : filter_names) columns.push_back(name + "_anees");
  for (const char* column : {"lower", "upper", "n_runs"}) columns.emplace_back(column);
  return columns;
}

std::vector<std::string> DivergenceColumns() { return {"num_points", "pair", "mean", "variance"}; }

std::string HeaderLine(const std::vector<std::string>& columns) {
  std::string line;
  for (std::size_t i = 0; i < columns.size(); ++i) line += (i > 0 ? "," : "") + columns[i];
  return line + "\n";
}

}  // namespace mjslam::rundir
