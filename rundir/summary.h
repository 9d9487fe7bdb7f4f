#pragma once

#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace mjslam::rundir {

/// What `mjslam run` writes to summary.json (docs/run_directory.md);
/// `mjslam evaluate` merges its metrics into the same file later.
struct RunSummary {
  /// Simulated time, seconds; path length of R, metres.
  double duration_s = 0.0;
  double distance_m = 0.0;
  /// Contact events between the chassis and a wall, and steps in contact.
  int collisions = 0;
  int contact_steps = 0;
  /// no_frontier, unreachable, time_limit or interrupted.
  std::string termination_reason;
  /// control.driver and control.pose_source of the run.
  std::string driver;
  std::string pose_source;
  /// Explored fraction at the end, reachable area (m^2), and the times the
  /// explored fraction first reached 0.9 and 0.99 (none: never; JSON null).
  double explored_fraction = 0.0;
  double reachable_area_m2 = 0.0;
  std::optional<double> t_explored_90_s;
  std::optional<double> t_explored_99_s;

  /// One filter's end state.
  struct Filter {
    /// Its name (DefaultFilterNames()).
    std::string name;
    /// Estimate minus truth of the final pose (x, y metres; th radians,
    /// wrapped).
    double error_x = 0.0;
    double error_y = 0.0;
    double error_th = 0.0;
    int num_features = 0;
    /// Accumulated processing time behind the command period, and open-loop
    /// time on its own command timeline, seconds.
    double processing_s = 0.0;
    double open_loop_s = 0.0;
    /// Scans the filter processed, and scans it skipped because it was busy
    /// (realtime timing; 0 with every_scan).
    int scans_processed = 0;
    int scans_skipped = 0;
    /// The check against its own innovations (slam::InnovationCheck):
    /// windows judged and failed, the longest failing streak, the mean NIS
    /// of the matched observations over the run (NaN: none), and the start
    /// of the first sustained failure (none: consistent).
    int innovation_windows = 0;
    int innovation_failed_windows = 0;
    int innovation_longest_failed_streak = 0;
    double innovation_mean_nis = 0.0;
    std::optional<double> innovation_inconsistent_since_s;
    /// Its near-miss test: windows judged and failed, the fraction of all
    /// observations that were near misses (NaN: none), and the start of the
    /// first sustained failure of that test (none: never).
    int near_miss_windows = 0;
    int near_miss_failed_windows = 0;
    double near_miss_fraction = 0.0;
    std::optional<double> near_miss_since_s;
    /// Its copy test: new features within the near-miss NIS of a mapped
    /// feature over the run, scans with too many, and the time of the first
    /// such scan (none: never).
    long copies = 0;
    int copied_scans = 0;
    std::optional<double> map_copied_at_s;
    /// A filter of submaps (slam::Filter::SubmapStartTimes): when each
    /// submap after the first began, seconds (empty: none, not written).
    std::vector<double> submap_starts_s;
  };
  std::vector<Filter> filters;
};

/// The JSON of `summary` (keys `run` and `filters.<name>`).
nlohmann::json ToJson(const RunSummary& summary);

/// Reads `dir`/summary.json: an object, empty when the file is missing.
/// Throws std::runtime_error naming the file when it is not a JSON object.
nlohmann::json ReadSummary(const std::string& dir);

/// Writes `summary` to `dir`/summary.json atomically, replacing the file.
void WriteSummary(const std::string& dir, const nlohmann::json& summary);

}  // namespace mjslam::rundir
