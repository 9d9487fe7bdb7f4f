// Diagnostic: replays one filter on a run directory (as association_trace
// does) and, for each scan between T_FROM and T_TO, prints the true motion
// against the recorded command, the pose error after the prediction and
// after the step, and each observation's outcome with its nearest NIS.
//
//   step_trace RUN_DIR [classical|selective] T_FROM T_TO
//
// Not part of the test suite: built on request (target step_trace).
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>

#include "tests/tools/association_audit.h"

namespace {

using namespace mjslam;

void Trace(const std::string& dir, const std::string& name, double t_from, double t_to) {
  const app::RunConfig config = app::LoadRunConfig(dir + "/config.yaml", {});
  const rundir::Recording recording(dir + "/scans.csv", "", config.laser.num_beams);
  slam::EkfSlam filter(
      config.slam.ekf,
      name == "selective" ? slam::CorrectionMode::kSelective : slam::CorrectionMode::kClassical,
      recording.Step(0).X_WR_true, recording.X_RS(),
      Rng(config.run.seed).Fork("slam." + name + ".selection"));
  Twist2 applied;
  double previous_t = 0.0;
  Pose2 previous_true = recording.Step(0).X_WR_true;
  for (std::size_t i = 0; i < recording.num_steps(); ++i) {
    const rundir::RecordedStep step = recording.Step(i);
    if (step.t_s > t_to) break;
    SensorRecord record = testing::audit_detail::RecordOf(step, config, i, previous_t, applied);
    previous_t = step.t_s;
    applied = step.command;
    slam::ScanFeatures features;
    if (record.has_scan) features = slam::ExtractFeatures(record.scan, config.slam.features);
    const bool shown = step.t_s >= t_from;
    if (!shown) {
      filter.Step(record, record.has_scan ? &features : nullptr);
      previous_true = step.X_WR_true;
      continue;
    }
    // The prediction alone, then the correction on a record of no motion.
    filter.Step(record, nullptr);
    const Pose2 predicted = filter.X_WR();
    SensorRecord still = record;
    still.dt_s = 0.0;
    const slam::StepReport report = filter.Step(still, record.has_scan ? &features : nullptr);
    const Pose2 corrected = filter.X_WR();
    const Pose2& truth = step.X_WR_true;
    std::printf("t=%.1f true dth %+.4f, command w dt %+.4f (v %.3f w %+.3f); heading error "
                "predicted %+.4f corrected %+.4f (sd %.4f); position error %.4f; %d obs, %d matched, "
                "%d new, %d ambiguous\n",
                step.t_s, WrapAngle(truth.theta - previous_true.theta), record.command.w_radps * record.dt_s,
                record.command.v_mps, record.command.w_radps, WrapAngle(predicted.theta - truth.theta),
                WrapAngle(corrected.theta - truth.theta), std::sqrt(filter.pose_covariance()(2, 2)),
                std::hypot(corrected.x - truth.x, corrected.y - truth.y), report.num_observed,
                report.num_matched, report.num_new, report.num_ambiguous);
    if (filter.slam_state().calibrated()) {
      const Eigen::VectorXd c = filter.slam_state().calibration();
      std::printf("    calibration q_d %+.4f q_th %+.4f k %+.4f b %+.4f s %+.5f\n", c(0), c(1),
                  c(2), c(3), c(4));
    }
    for (int o = 0; o < report.num_observed; ++o) {
      const slam::AssociationOutcome outcome = report.association.outcome[o];
      if (o < static_cast<int>(features.lines.size())) {
        const slam::LineObservation& l = features.lines[o];
        std::printf("    (rho %.3f alpha %+.3f, beams %d-%d)", l.rho_m, l.alpha_rad, l.first_beam,
                    l.last_beam);
      }
      std::printf("    %s %d: %s, nearest NIS %.1f\n",
                  o < static_cast<int>(features.lines.size()) ? "line" : "corner", o,
                  outcome == slam::AssociationOutcome::kMatched ? "matched"
                  : outcome == slam::AssociationOutcome::kNew   ? "NEW"
                                                                : "ambiguous",
                  report.nearest_nis[o]);
    }
    previous_true = truth;
  }
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 5) {
    std::fprintf(stderr, "usage: step_trace RUN_DIR classical|selective T_FROM T_TO\n");
    return 2;
  }
  try {
    Trace(argv[1], argv[2], std::atof(argv[3]), std::atof(argv[4]));
  } catch (const std::exception& error) {
    std::fprintf(stderr, "step_trace: %s\n", error.what());
    return 1;
  }
  return 0;
}
