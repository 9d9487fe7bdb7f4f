#include "rundir/summary.h"

#include <cmath>
#include <stdexcept>

#include "rundir/layout.h"
#include "rundir/manifest.h"
#include "rundir/run_files.h"

namespace mjslam::rundir {

nlohmann::json ToJson(const RunSummary& summary) {
  auto time_or_null = [](const std::optional<double>& t) {
    return t ? nlohmann::json(*t) : nlohmann::json(nullptr);
  };
  nlohmann::json json;
  json["run"] = {{"duration_s", summary.duration_s},
                 {"distance_m", summary.distance_m},
                 {"collisions", summary.collisions},
                 {"contact_steps", summary.contact_steps},
                 {"termination_reason", summary.termination_reason},
                 {"driver", summary.driver},
                 {"pose_source", summary.pose_source},
                 {"explored_fraction", summary.explored_fraction},
                 {"reachable_area_m2", summary.reachable_area_m2},
                 {"t_explored_90_s", time_or_null(summary.t_explored_90_s)},
                 {"t_explored_99_s", time_or_null(summary.t_explored_99_s)}};
  for (const RunSummary::Filter& f : summary.filters) {
    json["filters"][f.name] = {
        {"final_pose_error", {{"x", f.error_x}, {"y", f.error_y}, {"th", f.error_th}}},
        {"num_features", f.num_features},
        {"processing_s", f.processing_s},
        {"open_loop_s", f.open_loop_s},
        {"scans_processed", f.scans_processed},
        {"scans_skipped", f.scans_skipped},
        {"innovation_check",
         {{"verdict", f.innovation_inconsistent_since_s ? "inconsistent" : "consistent"},
          {"inconsistent_since_s", time_or_null(f.innovation_inconsistent_since_s)},
          {"windows", f.innovation_windows},
          {"failed_windows", f.innovation_failed_windows},
          {"longest_failed_streak", f.innovation_longest_failed_streak},
          {"mean_nis", std::isfinite(f.innovation_mean_nis) ? nlohmann::json(f.innovation_mean_nis)
                                                            : nlohmann::json(nullptr)},
          {"near_miss_windows", f.near_miss_windows},
          {"near_miss_failed_windows", f.near_miss_failed_windows},
          {"near_miss_fraction", std::isfinite(f.near_miss_fraction)
                                     ? nlohmann::json(f.near_miss_fraction)
                                     : nlohmann::json(nullptr)},
          {"near_miss_since_s", time_or_null(f.near_miss_since_s)},
          {"copies", f.copies},
          {"copied_scans", f.copied_scans},
          {"map_copied_at_s", time_or_null(f.map_copied_at_s)}}}};
    if (!f.submap_starts_s.empty()) {
      json["filters"][f.name]["submaps"] = {{"count", f.submap_starts_s.size() + 1},
                                            {"started_at_s", f.submap_starts_s}};
    }
  }
  return json;
}

nlohmann::json ReadSummary(const std::string& dir) {
  const std::string path = PathIn(dir, kSummaryFile);
  nlohmann::json summary = ReadJsonFile(path, nlohmann::json::object());
  if (!summary.is_object()) throw std::runtime_error(path + ": expected a JSON object");
  return summary;
}

void WriteSummary(const std::string& dir, const nlohmann::json& summary) {
  WriteJsonAtomically(PathIn(dir, kSummaryFile), summary);
}

}  // namespace mjslam::rundir
