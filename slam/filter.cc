#include "slam/filter.h"

#include <algorithm>
#include <set>
#include <utility>
#include <variant>

#include "common/check.h"
#include "slam/ekf_filter.h"
#include "slam/submap_filter.h"

namespace mjslam::slam {
namespace {

// Names a filter may not take: the other pose sources, and the prefixes of
// trajectory.csv's recorded columns (true_x, odom_x, cmd_v).
const std::set<std::string> kReservedNames = {"odometry", "ground_truth", "true", "odom", "cmd"};

bool IsFilterName(const std::string& name) {
  if (name.empty() || name[0] < 'a' || name[0] > 'z') return false;
  return std::all_of(name.begin(), name.end(), [](char c) {
    return (c >= 'a' && c <= 'z') || (c >= '0' && c <= '9') || c == '_';
  });
}

std::vector<std::string> Names(const char* const* begin, const char* const* end) {
  return std::vector<std::string>(begin, end);
}

// Kind ekf: its update rule.
std::vector<ParamProblem> ValidateEkfFilter(const FilterParams& filter) {
  ParamChecker check;
  check.OneOf("update", filter.update, {"classical", "selective"});
  return check.problems();
}

// Kind submaps: its update rule and submap size.
std::vector<ParamProblem> ValidateSubmapFilter(const FilterParams& filter) {
  ParamChecker check;
  check.OneOf("update", filter.update, {"classical", "selective"});
  check.Require(filter.submap_max_features >= 1, "submap_max_features",
                filter.submap_max_features, "a value >= 1");
  return check.problems();
}

}  // namespace

std::vector<ParamProblem> FilterParams::Validate() const {
  ParamChecker check;
  check.Require(IsFilterName(name) && kReservedNames.count(name) == 0, "name", name,
                "a name of lower-case letters, digits and '_' that starts with a letter, "
                "not odometry, ground_truth, true, odom or cmd");
  const FilterRegistry& registry = FilterRegistry::Global();
  std::string kinds;
  for (const std::string& k : registry.Kinds()) kinds += (kinds.empty() ? "" : ", ") + k;
  check.Require(registry.Has(kind), "kind", kind, "a registered kind (" + kinds + ")");
  check.Require(max_updates >= 0, "max_updates", max_updates,
                "a value >= 1, or 0 for slam.ekf.max_updates");
  if (!selection_policy.empty()) {
    check.OneOf("selection_policy", selection_policy,
                Names(std::begin(kSelectionPolicyNames), std::end(kSelectionPolicyNames)));
  }
  if (!timing.empty()) check.OneOf("timing", timing, {"every_scan", "realtime"});
  check.Positive("process_noise_scale", process_noise_scale);
  if (registry.Has(kind)) {
    for (const ParamProblem& p : registry.Validate(*this)) {
      check.Require(false, p.key, p.value, p.expected);
    }
  }
  return check.problems();
}

std::vector<ParamProblem> ValidateFilters(const std::vector<FilterParams>& filters) {
  ParamChecker check;
  for (std::size_t i = 0; i < filters.size(); ++i) {
    const std::string key = "filters[" + std::to_string(i) + "]";
    check.Merge(key, filters[i].Validate());
    for (std::size_t j = 0; j < i; ++j) {
      check.Require(filters[j].name != filters[i].name, key + ".name", filters[i].name,
                    "a name no other filter has (filters[" + std::to_string(j) + "] has it)");
    }
  }
  return check.problems();
}

namespace {

// Every standard deviation of a process model's noise times `k`.
void ScaleNoise(double k, CommandNoiseParams* noise) {
  for (double* std : {&noise->v_std_mps, &noise->v_fraction, &noise->w_std_radps,
                      &noise->w_fraction, &noise->change_fraction}) {
    *std *= k;
  }
}
void ScaleNoise(double k, OdometryNoiseParams* noise) {
  for (double* std : {&noise->distance_std_m, &noise->distance_std_m_per_sqrt_m,
                      &noise->distance_std_m_per_sqrt_rad, &noise->heading_std_rad,
                      &noise->heading_std_rad_per_sqrt_m, &noise->heading_std_rad_per_sqrt_rad}) {
    *std *= k;
  }
}

}  // namespace

std::vector<FilterParams> ResolvedFilters(const SlamParams& slam) {
  if (!slam.filters.empty()) return slam.filters;
  FilterParams classical;
  classical.name = "classical";
  classical.update = "classical";
  FilterParams selective;
  selective.name = "selective";
  selective.update = "selective";
  return {classical, selective};
}

FilterSettings SettingsOf(const SlamParams& slam, const FilterParams& filter) {
  FilterSettings settings{filter, slam};
  if (filter.max_updates > 0) settings.slam.ekf.max_updates = filter.max_updates;
  if (!filter.selection_policy.empty()) {
    settings.slam.ekf.selection_policy = filter.selection_policy;
  }
  if (!filter.timing.empty()) settings.slam.timing = filter.timing;
  if (filter.process_noise_scale != 1.0) {
    std::visit([&](auto& model) { ScaleNoise(filter.process_noise_scale, &model.noise); },
               settings.slam.ekf.process_model);
  }
  return settings;
}

std::vector<std::string> FilterNamesOf(const SlamParams& slam) {
  std::vector<std::string> names;
  for (const FilterParams& f : ResolvedFilters(slam)) names.push_back(f.name);
  return names;
}

FilterRegistry& FilterRegistry::Global() {
  // Built on first use (also from another object's static registration), with
  // the built-in kinds.
  static FilterRegistry* registry = [] {
    auto* r = new FilterRegistry();
    r->Register(
        "ekf",
        [](const FilterSettings& settings, const Pose2& X_WR0, const Pose2& X_RS, Rng rng) {
          return std::make_unique<EkfFilter>(settings, X_WR0, X_RS, std::move(rng));
        },
        ValidateEkfFilter);
    r->Register(
        "submaps",
        [](const FilterSettings& settings, const Pose2& X_WR0, const Pose2& X_RS, Rng rng) {
          return std::make_unique<SubmapFilter>(settings, X_WR0, X_RS, std::move(rng));
        },
        ValidateSubmapFilter);
    return r;
  }();
  return *registry;
}

void FilterRegistry::Register(
    const std::string& kind, FilterFactory factory,
    std::function<std::vector<ParamProblem>(const FilterParams&)> validate) {
  MJSLAM_CHECK(!kind.empty() && factory);
  const bool added = kinds_.emplace(kind, Kind{std::move(factory), std::move(validate)}).second;
  MJSLAM_CHECK(added);  // one registration per kind
}

bool FilterRegistry::Has(const std::string& kind) const { return kinds_.count(kind) > 0; }

std::vector<std::string> FilterRegistry::Kinds() const {
  std::vector<std::string> kinds;
  for (const auto& [kind, unused] : kinds_) kinds.push_back(kind);
  return kinds;
}

std::vector<ParamProblem> FilterRegistry::Validate(const FilterParams& filter) const {
  const auto it = kinds_.find(filter.kind);
  if (it == kinds_.end() || !it->second.validate) return {};
  return it->second.validate(filter);
}

std::unique_ptr<Filter> FilterRegistry::Make(const FilterSettings& settings, const Pose2& X_WR0,
                                             const Pose2& X_RS, const Rng& run_rng) const {
  const auto it = kinds_.find(settings.filter.kind);
  if (it == kinds_.end()) {
    throw ParamError("slam.filters: " + settings.filter.name + ": kind " + settings.filter.kind +
                     " is not registered");
  }
  // The filter's own stream, forked by name (as the paper's two always were).
  return it->second.factory(settings, X_WR0, X_RS,
                            run_rng.Fork("slam." + settings.filter.name + ".selection"));
}

}  // namespace mjslam::slam
