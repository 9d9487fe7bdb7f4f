#include "app/jobs/calibrate.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <limits>
#include <stdexcept>
#include <string>
#include <variant>

#include <Eigen/Dense>

#include "common/angles.h"
#include "rundir/rows.h"
#include "slam/motion_model.h"

namespace mjslam::app {
namespace {

constexpr double kInfinity = std::numeric_limits<double>::infinity();

// One record's input error, after the skid and the run's systematic part
// are removed (Calibrate, steps 1-2), and the odometry increment.
struct RecordError {
  double d = 0.0;
  double dth = 0.0;
  double e_d = 0.0;
  double e_th = 0.0;
  double e_lateral = 0.0;
};

// Sums of a window of records: the errors and the regressors of the
// variance models.
struct WindowSums {
  double records = 0.0;
  double distance = 0.0;  // sum |d|
  double turn = 0.0;      // sum |dth|
  double turn2 = 0.0;     // sum dth^2
  double e_d = 0.0;
  double e_th = 0.0;
  double e_lateral = 0.0;
};

std::vector<WindowSums> Windows(const std::vector<std::vector<RecordError>>& runs, int size) {
  std::vector<WindowSums> windows;
  for (const std::vector<RecordError>& run : runs) {
    for (std::size_t start = 0; start + size <= run.size(); start += size) {
      WindowSums w;
      for (int i = 0; i < size; ++i) {
        const RecordError& r = run[start + i];
        w.records += 1.0;
        w.distance += std::abs(r.d);
        w.turn += std::abs(r.dth);
        w.turn2 += r.dth * r.dth;
        w.e_d += r.e_d;
        w.e_th += r.e_th;
        w.e_lateral += r.e_lateral;
      }
      // A robot that stands still has no slip to measure (its odometry and
      // its true pose do not change).
      if (w.distance > 0.0 || w.turn > 0.0) windows.push_back(w);
    }
  }
  return windows;
}

// Non-negative coefficients c of y ~ X c, least squares weighted by
// 1 / (X c)^2 and iterated (the Gaussian quasi-likelihood of a variance),
// over the subsets of the columns whose fit is non-negative.
Eigen::VectorXd FitVariance(const Eigen::MatrixXd& X, const Eigen::VectorXd& y) {
  const int n = static_cast<int>(X.cols());
  Eigen::VectorXd weights = Eigen::VectorXd::Ones(X.rows());
  Eigen::VectorXd best = Eigen::VectorXd::Zero(n);
  for (int iteration = 0; iteration < 6; ++iteration) {
    double best_cost = std::numeric_limits<double>::infinity();
    for (int subset = 1; subset < (1 << n); ++subset) {
      std::vector<int> columns;
      for (int j = 0; j < n; ++j) {
        if (subset & (1 << j)) columns.push_back(j);
      }
      Eigen::MatrixXd A(X.rows(), columns.size());
      for (std::size_t j = 0; j < columns.size(); ++j) A.col(j) = X.col(columns[j]);
      const Eigen::VectorXd sw = weights.cwiseSqrt();
      const Eigen::VectorXd c =
          (sw.asDiagonal() * A).colPivHouseholderQr().solve(sw.asDiagonal() * y);
      if ((c.array() < 0.0).any() || !c.allFinite()) continue;
      const double cost = (sw.asDiagonal() * (A * c - y)).squaredNorm();
      if (cost < best_cost) {
        best_cost = cost;
        best.setZero();
        for (std::size_t j = 0; j < columns.size(); ++j) best(columns[j]) = c(j);
      }
    }
    // Weights 1 / variance^2, bounded where a fit predicts (almost) none.
    const Eigen::VectorXd predicted = (X * best).cwiseMax(1e-6 * y.mean() + 1e-300);
    weights = predicted.cwiseProduct(predicted).cwiseInverse();
    weights /= weights.mean();
  }
  return best;
}

// The odometry process model of `p`; when `p`'s is of kind command (its
// odometry noise unused), the built-in one with `p`'s integration.
slam::OdometryProcessModel OdometryModelOf(const slam::EkfParams& p) {
  if (const auto* m = std::get_if<slam::OdometryProcessModel>(&p.process_model)) return *m;
  slam::OdometryProcessModel m;
  m.integration = slam::IntegrationOf(p.process_model);
  return m;
}

double Variance(const slam::OdometryProcessModel& m, const WindowSums& w, int component) {
  const slam::OdometryNoiseParams& n = m.noise;
  auto sq = [](double v) { return v * v; };
  if (component == 0) {
    return sq(n.distance_std_m) * w.records + sq(n.distance_std_m_per_sqrt_m) * w.distance +
           sq(n.distance_std_m_per_sqrt_rad) * w.turn;
  }
  if (component == 1) {
    return sq(n.heading_std_rad) * w.records + sq(n.heading_std_rad_per_sqrt_m) * w.distance +
           sq(n.heading_std_rad_per_sqrt_rad) * w.turn;
  }
  return sq(m.lateral.slip_std_m_per_rad) * w.turn2 + sq(m.lateral.slip_std_m_per_sqrt_m) * w.distance;
}

WindowCheck Check(const std::vector<std::vector<RecordError>>& runs, const slam::EkfParams& p,
                  int size) {
  WindowCheck check;
  check.window_records = size;
  const slam::OdometryProcessModel model = OdometryModelOf(p);
  std::array<double, 3> sums{0.0, 0.0, 0.0};
  for (const WindowSums& w : Windows(runs, size)) {
    const std::array<double, 3> e{w.e_d, w.e_th, w.e_lateral};
    for (int c = 0; c < 3; ++c) {
      const double variance = Variance(model, w, c);
      sums[c] += variance > 0.0 ? e[c] * e[c] / variance : (e[c] == 0.0 ? 0.0 : kInfinity);
    }
    ++check.windows;
  }
  const double n = std::max(check.windows, 1);
  check.distance = sums[0] / n;
  check.heading = sums[1] / n;
  check.lateral = sums[2] / n;
  return check;
}

// The run's least-squares q_d, q_th, k (weighted by the given model's
// variances); zero when its motion does not determine them.
RunSystematics FitSystematics(const std::string& name, const std::vector<RecordError>& records,
                              const slam::EkfParams& p) {
  RunSystematics result;
  result.name = name;
  result.records = static_cast<int>(records.size());
  const double b = p.axle_track_m * p.axle_track_m / 4.0;
  const slam::OdometryProcessModel model = OdometryModelOf(p);
  Eigen::Matrix3d normal = Eigen::Matrix3d::Zero();
  Eigen::Vector3d rhs = Eigen::Vector3d::Zero();
  for (const RecordError& r : records) {
    WindowSums w;
    w.records = 1.0;
    w.distance = std::abs(r.d);
    w.turn = std::abs(r.dth);
    const double wd = 1.0 / std::max(Variance(model, w, 0), 1e-12);
    const double wth = 1.0 / std::max(Variance(model, w, 1), 1e-12);
    const Eigen::Vector3d jd(r.d, 0.0, b * r.dth);
    const Eigen::Vector3d jth(0.0, r.dth, r.d);
    normal += wd * jd * jd.transpose() + wth * jth * jth.transpose();
    rhs += wd * jd * r.e_d + wth * jth * r.e_th;
  }
  Eigen::FullPivLU<Eigen::Matrix3d> lu(normal);
  if (lu.rank() < 3) return result;
  const Eigen::Vector3d x = lu.solve(rhs);
  result.distance_scale = x(0);
  result.heading_scale = x(1);
  result.heading_per_m_rad = x(2);
  return result;
}

void RequireFinitePose(const Pose2& pose, const RunMotion& run, std::size_t i, const char* what) {
  if (!std::isfinite(pose.x) || !std::isfinite(pose.y) || !std::isfinite(pose.theta)) {
    throw std::invalid_argument("calibrate: " + run.name + ": record " + std::to_string(i + 1) +
                               ": the " + what + " pose is not finite");
  }
}

// Three significant digits: what the fit can tell, and what --write writes.
std::string Text3(double value) {
  char text[32];
  std::snprintf(text, sizeof text, "%.3g", value);
  return text;
}

double Round3(double value) { return std::strtod(Text3(value).c_str(), nullptr); }

}  // namespace

Calibration Calibrate(const std::vector<RunMotion>& runs, const slam::EkfParams& model,
                      int window_records) {
  if (window_records < 1) {
    throw std::invalid_argument("calibrate: --window-records: expected a value >= 1 (got " +
                                std::to_string(window_records) + ")");
  }
  const double a = model.control_point_offset_m;
  const slam::OdometryNoiseParams& given_noise = OdometryModelOf(model).noise;
  // Step 1: each record's errors, the lateral one with no skid, and the
  // skid's regressor d dth / dt.
  std::vector<std::vector<RecordError>> errors(runs.size());
  std::vector<std::vector<double>> skid_regressor(runs.size());
  double skid_num = 0.0;
  double skid_den = 0.0;
  for (std::size_t r = 0; r < runs.size(); ++r) {
    const RunMotion& run = runs[r];
    for (std::size_t i = 1; i < run.t_s.size(); ++i) {
      RequireFinitePose(run.X_WR_true[i], run, i, "true");
      RequireFinitePose(run.X_OR[i], run, i, "odometry");
      const double dt = run.t_s[i] - run.t_s[i - 1];
      if (!(dt >= 0.0) || !std::isfinite(dt)) {
        throw std::invalid_argument("calibrate: " + run.name + ": record " + std::to_string(i + 1) +
                                    ": time does not increase");
      }
      if (dt == 0.0) continue;
      const slam::MotionInput odometry =
          slam::OdometryInput(run.X_OR[i - 1], run.X_OR[i], a, given_noise);
      const slam::MotionInput truth =
          slam::OdometryInput(run.X_WR_true[i - 1], run.X_WR_true[i], a, given_noise);
      const Pose2& X0 = run.X_WR_true[i - 1];
      const Eigen::Vector3d predicted =
          slam::PredictPose(Eigen::Vector3d(X0.x, X0.y, X0.theta), truth.increment, a);
      const double phi = X0.theta + 0.5 * truth.increment.y();
      const double dx = run.X_WR_true[i].x - predicted.x();
      const double dy = run.X_WR_true[i].y - predicted.y();
      RecordError e;
      e.d = odometry.increment.x();
      e.dth = odometry.increment.y();
      e.e_d = truth.increment.x() - e.d;
      e.e_th = WrapAngle(truth.increment.y() - e.dth);
      e.e_lateral = -std::sin(phi) * dx + std::cos(phi) * dy;
      const double g = e.d * e.dth / dt;
      // PredictPose moves R by -skid g across the heading.
      skid_num -= e.e_lateral * g;
      skid_den += g * g;
      errors[r].push_back(e);
      skid_regressor[r].push_back(g);
    }
  }
  Calibration result;
  result.fitted = model;
  slam::OdometryProcessModel fitted = OdometryModelOf(model);
  fitted.lateral.skid_s = skid_den > 0.0 ? Round3(std::max(0.0, skid_num / skid_den)) : 0.0;
  // Step 2: the skid and each run's systematic part removed.
  for (std::size_t r = 0; r < runs.size(); ++r) {
    for (std::size_t i = 0; i < errors[r].size(); ++i) {
      errors[r][i].e_lateral += fitted.lateral.skid_s * skid_regressor[r][i];
    }
    const RunSystematics s = FitSystematics(runs[r].name, errors[r], model);
    const double b = model.axle_track_m * model.axle_track_m / 4.0;
    for (RecordError& e : errors[r]) {
      e.e_d -= s.distance_scale * e.d + s.heading_per_m_rad * b * e.dth;
      e.e_th -= s.heading_scale * e.dth + s.heading_per_m_rad * e.d;
    }
    result.runs.push_back(s);
    result.records += static_cast<int>(errors[r].size());
  }
  // Step 3: the variances over windows.
  const std::vector<WindowSums> windows = Windows(errors, window_records);
  if (windows.size() < 50) {
    throw std::invalid_argument("calibrate: " + std::to_string(windows.size()) + " windows of " +
                                std::to_string(window_records) +
                                " records: expected at least 50 (give more or longer runs)");
  }
  const int n = static_cast<int>(windows.size());
  // The slip's variance grows with the distance rolled and the angle turned;
  // a floor per record would make the model depend on the record rate, and
  // is left at 0.
  Eigen::MatrixXd X3(n, 2);
  Eigen::MatrixXd X2(n, 2);
  Eigen::VectorXd yd(n), yth(n), ylat(n);
  for (int i = 0; i < n; ++i) {
    const WindowSums& w = windows[i];
    X3.row(i) << w.distance, w.turn;
    X2.row(i) << w.distance, w.turn2;
    yd(i) = w.e_d * w.e_d;
    yth(i) = w.e_th * w.e_th;
    ylat(i) = w.e_lateral * w.e_lateral;
  }
  const Eigen::VectorXd cd = FitVariance(X3, yd);
  const Eigen::VectorXd cth = FitVariance(X3, yth);
  const Eigen::VectorXd clat = FitVariance(X2, ylat);
  slam::OdometryNoiseParams& noise = fitted.noise;
  noise.distance_std_m = 0.0;
  noise.distance_std_m_per_sqrt_m = Round3(std::sqrt(cd(0)));
  noise.distance_std_m_per_sqrt_rad = Round3(std::sqrt(cd(1)));
  noise.heading_std_rad = 0.0;
  noise.heading_std_rad_per_sqrt_m = Round3(std::sqrt(cth(0)));
  noise.heading_std_rad_per_sqrt_rad = Round3(std::sqrt(cth(1)));
  fitted.lateral.slip_std_m_per_sqrt_m = Round3(std::sqrt(clat(0)));
  fitted.lateral.slip_std_m_per_rad = Round3(std::sqrt(clat(1)));
  result.fitted.process_model = fitted;
  for (int size : {1, window_records, 5 * window_records}) {
    result.given_checks.push_back(Check(errors, model, size));
    result.fitted_checks.push_back(Check(errors, result.fitted, size));
  }
  return result;
}

std::vector<std::string> RunDirectories(const std::vector<std::string>& paths) {
  namespace fs = std::filesystem;
  std::vector<std::string> dirs;
  for (const std::string& path : paths) {
    if (fs::is_regular_file(fs::path(path) / "trajectory.csv")) {
      dirs.push_back(path);
      continue;
    }
    std::vector<std::string> runs;
    const fs::path runs_dir = fs::path(path) / "runs";
    if (fs::is_directory(runs_dir)) {
      for (const fs::directory_entry& entry : fs::directory_iterator(runs_dir)) {
        if (fs::is_regular_file(entry.path() / "trajectory.csv")) runs.push_back(entry.path().string());
      }
    }
    if (runs.empty()) {
      throw std::runtime_error(path + ": neither a run directory (trajectory.csv) nor a sweep "
                                      "directory (runs/run_*/trajectory.csv)");
    }
    std::sort(runs.begin(), runs.end());
    dirs.insert(dirs.end(), runs.begin(), runs.end());
  }
  return dirs;
}

RunMotion ReadRunMotion(const std::string& run_dir) {
  const std::string path = run_dir + "/trajectory.csv";
  RunMotion run;
  run.name = run_dir;
  for (const rundir::TrajectoryRow& row : rundir::ReadTrajectoryRows(path)) {
    run.t_s.push_back(row.t_s);
    run.X_WR_true.push_back(row.X_WR_true);
    run.X_OR.push_back(row.X_WR_odometry);
  }
  if (!run.X_WR_true.empty() && !std::isfinite(run.X_WR_true.front().x)) {
    throw std::runtime_error(path + ": no true pose (an imported log): calibrate needs runs "
                                    "of the simulator");
  }
  return run;
}

std::string CalibrationYaml(const Calibration& calibration, const std::string& base,
                            const std::string& header) {
  const slam::OdometryProcessModel m = OdometryModelOf(calibration.fitted);
  const slam::OdometryNoiseParams& n = m.noise;
  std::string yaml;
  for (std::size_t start = 0; start < header.size();) {
    const std::size_t end = header.find('\n', start);
    yaml += "# " + header.substr(start, end - start) + "\n";
    if (end == std::string::npos) break;
    start = end + 1;
  }
  if (!base.empty()) yaml += "base: " + base + "\n";
  // The whole process model: a base of kind command would otherwise give
  // the odometry kind's built-in integration.
  yaml += "slam:\n  ekf:\n    process_model:\n      kind: odometry\n";
  yaml += "      integration: " + m.integration + "\n";
  yaml += "      noise:\n";
  yaml += "        distance_std_m: " + Text3(n.distance_std_m) + "\n";
  yaml += "        distance_std_m_per_sqrt_m: " + Text3(n.distance_std_m_per_sqrt_m) + "\n";
  yaml += "        distance_std_m_per_sqrt_rad: " + Text3(n.distance_std_m_per_sqrt_rad) + "\n";
  yaml += "        heading_std_rad: " + Text3(n.heading_std_rad) + "\n";
  yaml += "        heading_std_rad_per_sqrt_m: " + Text3(n.heading_std_rad_per_sqrt_m) + "\n";
  yaml += "        heading_std_rad_per_sqrt_rad: " + Text3(n.heading_std_rad_per_sqrt_rad) + "\n";
  yaml += "      lateral:\n";
  yaml += "        slip_std_m_per_rad: " + Text3(m.lateral.slip_std_m_per_rad) + "\n";
  yaml += "        slip_std_m_per_sqrt_m: " + Text3(m.lateral.slip_std_m_per_sqrt_m) + "\n";
  yaml += "        skid_s: " + Text3(m.lateral.skid_s) + "\n";
  return yaml;
}

std::string CalibrationReport(const Calibration& calibration, const slam::EkfParams& given) {
  std::string text;
  char line[256];
  auto add = [&](const char* key, double before, double after) {
    std::snprintf(line, sizeof line, "  %-52s %10.3g %10.3g\n", key, before, after);
    text += line;
  };
  std::snprintf(line, sizeof line, "%zu runs, %d records\n  %-52s %10s %10s\n",
                calibration.runs.size(), calibration.records, "slam.ekf key", "given", "fitted");
  text += line;
  const slam::OdometryProcessModel g = OdometryModelOf(given);
  const slam::OdometryProcessModel f = OdometryModelOf(calibration.fitted);
  add("process_model.noise.distance_std_m", g.noise.distance_std_m, f.noise.distance_std_m);
  add("process_model.noise.distance_std_m_per_sqrt_m", g.noise.distance_std_m_per_sqrt_m,
      f.noise.distance_std_m_per_sqrt_m);
  add("process_model.noise.distance_std_m_per_sqrt_rad", g.noise.distance_std_m_per_sqrt_rad,
      f.noise.distance_std_m_per_sqrt_rad);
  add("process_model.noise.heading_std_rad", g.noise.heading_std_rad, f.noise.heading_std_rad);
  add("process_model.noise.heading_std_rad_per_sqrt_m", g.noise.heading_std_rad_per_sqrt_m,
      f.noise.heading_std_rad_per_sqrt_m);
  add("process_model.noise.heading_std_rad_per_sqrt_rad", g.noise.heading_std_rad_per_sqrt_rad,
      f.noise.heading_std_rad_per_sqrt_rad);
  add("process_model.lateral.slip_std_m_per_rad", g.lateral.slip_std_m_per_rad,
      f.lateral.slip_std_m_per_rad);
  add("process_model.lateral.slip_std_m_per_sqrt_m", g.lateral.slip_std_m_per_sqrt_m,
      f.lateral.slip_std_m_per_sqrt_m);
  add("process_model.lateral.skid_s", g.lateral.skid_s, f.lateral.skid_s);
  text += "\nmean (error / sigma)^2 over windows (1 when the model is right):\n";
  std::snprintf(line, sizeof line, "  %8s %8s   %-26s   %-26s\n", "records", "windows",
                "given: distance heading lat", "fitted: distance heading lat");
  text += line;
  for (std::size_t i = 0; i < calibration.given_checks.size(); ++i) {
    const WindowCheck& a = calibration.given_checks[i];
    const WindowCheck& b = calibration.fitted_checks[i];
    std::snprintf(line, sizeof line, "  %8d %8d   %8.3f %8.3f %8.3f   %8.3f %8.3f %8.3f\n",
                  a.window_records, a.windows, a.distance, a.heading, a.lateral, b.distance,
                  b.heading, b.lateral);
    text += line;
  }
  text += "\nsystematic errors per run (self-calibration's q_d, q_th, k rad/m):\n";
  for (const RunSystematics& s : calibration.runs) {
    std::snprintf(line, sizeof line, "  %+9.5f %+9.5f %+9.5f  %6d  %s\n", s.distance_scale,
                  s.heading_scale, s.heading_per_m_rad, s.records, s.name.c_str());
    text += line;
  }
  return text;
}

}  // namespace mjslam::app
