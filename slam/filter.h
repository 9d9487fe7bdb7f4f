#pragma once

// The filter interface and its registry by kind: any estimator the closed
// loop runs beside the paper's two (slam/README.md, "Bring your own filter").
#include <functional>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "common/map_feature.h"
#include "common/params.h"
#include "common/pose2.h"
#include "common/records.h"
#include "common/rng.h"
#include "slam/ekf_slam.h"
#include "slam/observations.h"
#include "slam/slam_params.h"

namespace mjslam::slam {

/// One filter of the run: an estimator of the pose of R in W (and of a map)
/// from the records and the features extracted once per scan for all
/// filters. The closed loop (app::FilterBank) gives every filter the same
/// records, times each Step, and writes each filter's columns of
/// trajectory.csv, its map and its summary by its name. Like EkfSlam, a
/// filter has no clock, files or printing.
class Filter {
 public:
  virtual ~Filter() = default;

  /// Predicts over record.dt_s from the record's input (its odometry pose
  /// X_OR or its held command), then, when `features` is not null, corrects
  /// with the scan's lines and corners (in the sensor frame S). The first
  /// record predicts no motion. Returns what the step did: at least
  /// num_features; num_matched, num_updated and nis_sum feed the command
  /// period's cost model and the innovation check (zero for a filter that
  /// never corrects). Throws SlamInputError on bad data.
  virtual StepReport Step(const SensorRecord& record, const ScanFeatures* features) = 0;
  /// Estimated pose of R (the point h) in W.
  virtual Pose2 X_WR() const = 0;
  /// Covariance of (x, y, th) of R: metres, radians.
  virtual Eigen::Matrix3d pose_covariance() const = 0;
  /// The map in W, each feature with its 2x2 marginal covariance (empty for
  /// a filter without one).
  virtual std::vector<MapFeature> Map() const = 0;
  /// L, the number of map features.
  virtual int num_features() const = 0;
  /// A filter that keeps its map in submaps: the times (records' t_s) at
  /// which each submap after the first began, in order; empty for others.
  virtual std::vector<double> SubmapStartTimes() const { return {}; }
};

/// What a filter is built from: its entry and the run's SLAM settings with
/// the entry's own applied (`slam.ekf.max_updates`, `selection_policy` and
/// `timing` replaced where the entry sets them).
struct FilterSettings {
  FilterParams filter;
  SlamParams slam;
};

/// The filters of `slam`: its `filters`, or when the list is empty the
/// paper's two, {name: classical, kind: ekf, update: classical} and
/// {name: selective, kind: ekf, update: selective}.
std::vector<FilterParams> ResolvedFilters(const SlamParams& slam);
/// FilterSettings of `filter` within `slam`.
FilterSettings SettingsOf(const SlamParams& slam, const FilterParams& filter);
/// The names of ResolvedFilters(slam), in order.
std::vector<std::string> FilterNamesOf(const SlamParams& slam);

/// Builds a filter: its settings, the known initial pose X_WR0 of R, the
/// laser mount X_RS on R, and a stream forked from the run seed by the
/// filter's name ("slam.<name>.selection"), its own for any draws.
using FilterFactory = std::function<std::unique_ptr<Filter>(
    const FilterSettings& settings, const Pose2& X_WR0, const Pose2& X_RS, Rng rng)>;

/// The kinds of filter a run can name in `slam.filters[i].kind`. Kind "ekf"
/// is built in; another library adds its kinds with a FilterRegistration
/// (examples/dead_reckoning_filter.cc), so that a new filter is one class
/// and one registration, with no edit to the closed loop.
class FilterRegistry {
 public:
  /// The registry of the program, with "ekf" in it.
  static FilterRegistry& Global();

  /// Adds kind `kind`. `validate`, if given, checks an entry of that kind
  /// (keys relative to the entry, as FilterParams::Validate). Aborts if the
  /// kind is already registered.
  void Register(const std::string& kind, FilterFactory factory,
                std::function<std::vector<ParamProblem>(const FilterParams&)> validate = {});
  /// Whether `kind` is registered.
  bool Has(const std::string& kind) const;
  /// The registered kinds, sorted.
  std::vector<std::string> Kinds() const;
  /// The problems of an entry of a registered kind (none for a kind without
  /// a validator).
  std::vector<ParamProblem> Validate(const FilterParams& filter) const;
  /// A filter of settings.filter.kind; throws ParamError for a kind that is
  /// not registered.
  std::unique_ptr<Filter> Make(const FilterSettings& settings, const Pose2& X_WR0,
                               const Pose2& X_RS, const Rng& run_rng) const;

 private:
  struct Kind {
    FilterFactory factory;
    std::function<std::vector<ParamProblem>(const FilterParams&)> validate;
  };
  std::map<std::string, Kind> kinds_;
};

/// Registers a kind in FilterRegistry::Global() when constructed: a static
/// object of this type in a filter's .cc (linked into the program as an
/// object file) is the filter's one registration.
struct FilterRegistration {
  FilterRegistration(const std::string& kind, FilterFactory factory,
                     std::function<std::vector<ParamProblem>(const FilterParams&)> validate = {}) {
    FilterRegistry::Global().Register(kind, std::move(factory), std::move(validate));
  }
};

}  // namespace mjslam::slam
