#include "realdata/relations.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <set>
#include <sstream>
#include <stdexcept>

#include "common/angles.h"
#include "common/interrupt.h"
#include "realdata/carmen_log.h"

namespace mjslam::realdata {
namespace {

constexpr double kRadToDeg = 180.0 / 3.14159265358979323846;
// The largest relation time, seconds (UNIX time in the year 2286).
constexpr double kMaxRelationTimeS = 1e10;

// Mean and standard deviation (n - 1) of `values`; 0 for the std below 2.
std::pair<double, double> MeanStd(const std::vector<double>& values) {
  if (values.empty()) return {0.0, 0.0};
  double sum = 0.0;
  for (double v : values) sum += v;
  const double mean = sum / values.size();
  if (values.size() < 2) return {mean, 0.0};
  double squares = 0.0;
  for (double v : values) squares += (v - mean) * (v - mean);
  return {mean, std::sqrt(squares / (values.size() - 1))};
}

}  // namespace

std::vector<Relation> ReadRelations(const std::string& path) {
  RequireRegularFile(path);
  std::ifstream in(path);
  if (!in) throw std::runtime_error(path + ": cannot open");
  std::vector<Relation> relations;
  std::string line;
  int line_number = 0;
  while (std::getline(in, line)) {
    ++line_number;
    if (line_number % 1024 == 0) ThrowIfInterrupted("reading the relations");
    if (line.size() > kMaxLogLineBytes) {
      throw std::runtime_error(path + ":" + std::to_string(line_number) + ": line longer than " +
                               std::to_string(kMaxLogLineBytes) + " bytes (not a relations file?)");
    }
    std::istringstream fields(line);
    std::vector<double> values;
    std::string token;
    while (fields >> token) {
      char* end = nullptr;
      const double value = std::strtod(token.c_str(), &end);
      if (end == token.c_str() || *end != '\0' || !std::isfinite(value)) {
        throw std::runtime_error(path + ":" + std::to_string(line_number) +
                                 ": expected a number (got '" + Shown(token) + "')");
      }
      values.push_back(value);
    }
    if (values.empty()) continue;
    if (values.size() != 8) {
      throw std::runtime_error(path + ":" + std::to_string(line_number) +
                               ": expected 8 numbers (t1 t2 dx dy dz droll dpitch dyaw), got " +
                               std::to_string(values.size()));
    }
    // Times as the logs' (UNIX time at most), poses within the run
    // directory's limits: sums and means of them stay finite.
    const bool times_ok = std::abs(values[0]) <= kMaxRelationTimeS && std::abs(values[1]) <= kMaxRelationTimeS;
    bool deltas_ok = true;
    for (std::size_t i = 2; i < 8; ++i) deltas_ok = deltas_ok && std::abs(values[i]) <= 1e6;
    if (!times_ok || !deltas_ok) {
      throw std::runtime_error(path + ":" + std::to_string(line_number) +
                               ": expected times within +-1e10 s and offsets within +-1e6 (got '" +
                               Shown(line) + "')");
    }
    Relation relation;
    relation.t1_s = values[0];
    relation.t2_s = values[1];
    relation.delta = Pose2(values[2], values[3], values[7]);
    relation.line = line_number;
    relations.push_back(relation);
  }
  if (relations.empty()) throw std::runtime_error(path + ": no relations");
  return relations;
}

int NearestPose(const std::vector<TimedPose>& trajectory, double t_s, double tolerance_s) {
  const auto later = std::lower_bound(trajectory.begin(), trajectory.end(), t_s,
                                      [](const TimedPose& p, double t) { return p.t_s < t; });
  int best = -1;
  double best_gap = tolerance_s;
  for (auto it : {later - 1, later}) {
    if (it < trajectory.begin() || it >= trajectory.end()) continue;
    const double gap = std::abs(it->t_s - t_s);
    if (gap <= best_gap) {
      best_gap = gap;
      best = static_cast<int>(it - trajectory.begin());
    }
  }
  return best;
}

RelationErrors ScoreRelations(const std::vector<Relation>& relations,
                              const std::vector<TimedPose>& trajectory,
                              const RelationMatching& matching) {
  std::vector<double> translation, rotation, translation_sq, rotation_sq;
  for (const Relation& relation : relations) {
    const int i = NearestPose(trajectory, relation.t1_s - matching.time_offset_s,
                              matching.tolerance_s);
    const int j = NearestPose(trajectory, relation.t2_s - matching.time_offset_s,
                              matching.tolerance_s);
    if (i < 0 || j < 0) continue;
    const Pose2 delta = trajectory[i].pose.Inverse() * trajectory[j].pose;
    const double dt = (delta.translation() - relation.delta.translation()).norm();
    const double dr = std::abs(WrapAngle(delta.theta - relation.delta.theta)) * kRadToDeg;
    translation.push_back(dt);
    rotation.push_back(dr);
    translation_sq.push_back(dt * dt);
    rotation_sq.push_back(dr * dr);
  }
  RelationErrors errors;
  errors.num_relations = static_cast<int>(relations.size());
  errors.num_matched = static_cast<int>(translation.size());
  std::tie(errors.translation_mean_m, errors.translation_std_m) = MeanStd(translation);
  std::tie(errors.rotation_mean_deg, errors.rotation_std_deg) = MeanStd(rotation);
  std::tie(errors.translation_sq_mean_m2, errors.translation_sq_std_m2) = MeanStd(translation_sq);
  std::tie(errors.rotation_sq_mean_deg2, errors.rotation_sq_std_deg2) = MeanStd(rotation_sq);
  return errors;
}

double BestTimeOffset(const std::vector<Relation>& relations,
                      const std::vector<TimedPose>& trajectory, double tolerance_s,
                      int* num_matched_times, std::size_t max_candidates) {
  if (!(tolerance_s > 0.0) || !std::isfinite(tolerance_s)) {
    throw std::invalid_argument("relation time offset search: the tolerance must be a finite "
                                "number of seconds > 0 (got " + std::to_string(tolerance_s) + ")");
  }
  std::set<double> times;
  for (const Relation& relation : relations) {
    times.insert(relation.t1_s);
    times.insert(relation.t2_s);
  }
  // The search holds every candidate at once: refuse before allocating.
  if (!trajectory.empty() && times.size() > max_candidates / trajectory.size()) {
    throw std::length_error(
        "relation time offset search: " + std::to_string(times.size()) + " relation times x " +
        std::to_string(trajectory.size()) + " poses are more than " +
        std::to_string(max_candidates) + " candidate offsets");
  }
  // Every relation time minus every pose time, sorted: the densest window
  // of width 2 tolerance_s is the offset most times agree on.
  std::vector<double> differences;
  differences.reserve(times.size() * trajectory.size());
  for (double t : times) {
    ThrowIfInterrupted("relation time offset search");
    for (const TimedPose& pose : trajectory) differences.push_back(t - pose.t_s);
  }
  std::sort(differences.begin(), differences.end());
  ThrowIfInterrupted("relation time offset search");
  std::size_t best_first = 0, best_count = 0, first = 0;
  for (std::size_t last = 0; last < differences.size(); ++last) {
    while (differences[last] - differences[first] > 2.0 * tolerance_s) ++first;
    if (last - first + 1 > best_count) {
      best_count = last - first + 1;
      best_first = first;
    }
  }
  const double offset =
      differences.empty() ? 0.0
                          : 0.5 * (differences[best_first] + differences[best_first + best_count - 1]);
  int matched = 0;
  for (double t : times) matched += NearestPose(trajectory, t - offset, tolerance_s) >= 0 ? 1 : 0;
  if (num_matched_times != nullptr) *num_matched_times = matched;
  return offset;
}

}  // namespace mjslam::realdata
