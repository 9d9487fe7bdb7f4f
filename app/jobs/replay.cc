#include "app/jobs/replay.h"

#include <exception>

#include "app/engine/closed_loop.h"
#include "app/jobs/progress.h"
#include "app/engine/filter_bank.h"
#include "app/jobs/version.h"
#include "common/interrupt.h"
#include "config/config.h"
#include "rundir/csv_writer.h"
#include "rundir/layout.h"
#include "rundir/manifest.h"
#include "rundir/recording.h"
#include "rundir/rows.h"
#include "rundir/run_files.h"

namespace mjslam::app {

bool Replay(const RunConfig& config, const ReplayOptions& options) {
  config.ValidateOrThrow();
  const rundir::Recording recording(options.scans_path, options.trajectory_path,
                                    config.laser.num_beams);
  const std::string& dir = options.out_dir;
  const rundir::RunDirectoryLock lock(dir);
  rundir::WriteFileAtomically(rundir::PathIn(dir, rundir::kConfigFile), config::ToYaml(config));
  rundir::ManifestWriter manifest(dir, {{"mode", "replay"},
                                        {"scans_file", options.scans_path},
                                        {"trajectory_file", recording.trajectory_path()},
                                        {"mjslam_version", MjslamVersion()},
                                        {"git_commit", MjslamGitCommit()},
                                        {"config_file", options.config_path},
                                        {"command_line", options.command_line}});
  return ReplayRecording(config, recording, dir, &manifest);
}

bool ReplayRecording(const RunConfig& config, const rundir::Recording& recording,
                     const std::string& dir, rundir::ManifestWriter* manifest) {
  manifest->SetLaserMount(recording.X_RS());
  manifest->Write();
  bool interrupted = false;
  try {
    // The same loop as a run, its records read from the recording.
    ClosedLoop loop(config, recording);
    rundir::CsvWriter trajectory(rundir::PathIn(dir, rundir::kTrajectoryFile),
                                 rundir::TrajectoryColumns(loop.filters().names()));
    Progress progress("replay", static_cast<double>(loop.num_steps()));
    while (!loop.Done()) {
      if (InterruptRequested()) {
        interrupted = true;
        break;
      }
      const LoopStep& step = loop.Step();
      rundir::AddTrajectoryRow(step.row, &trajectory);
      progress.Update(static_cast<double>(step.index));
    }
    progress.Finish();
    trajectory.Flush();
    WriteMaps(loop.filters(), dir);
  } catch (const std::exception& error) {
    manifest->Fail(error.what());
    throw;
  }
  manifest->Finish(interrupted ? "interrupted" : "completed");
  return !interrupted;
}

}  // namespace mjslam::app
