#pragma once

#include <string>

#include "common/cpu_time.h"

namespace mjslam::app {

/// CPU seconds a simulated run spent in each of its phases, as `mjslam run
/// --profile` prints them. Measured with ThreadCpuSeconds()
/// (common/cpu_time.h): ClosedLoop reads the clock at the start of a step and
/// at the end of each phase (CpuLaps), so the few assignments between two
/// phases are charged to the second; the files and the video have a
/// ScopedCpuTimer each. What is not in a phase (setup, the maps and summary
/// at the end) is the rest of RunSimulation's CPU time.
struct PhaseCpu {
  /// The physics: Simulator::Advance (mj_step) and the contact count.
  double physics_s = 0.0;
  /// The laser: the exact cast (Simulator::CastLaser) and its noise.
  double laser_s = 0.0;
  /// Wheel odometry from the simulator's wheel angles.
  double odometry_s = 0.0;
  /// The explored fraction: TrueCoverage::Observe and ExploredFraction.
  double coverage_s = 0.0;
  /// The filters' own steps (FilterBank::Step) and their trajectory.csv
  /// columns.
  double filters_s = 0.0;
  /// The driver: the explorer (or the tour) and SetCommand.
  double explorer_s = 0.0;
  /// The rows of trajectory.csv, scans.csv and explorer.csv.
  double files_s = 0.0;
  /// The live video (render.video).
  double video_s = 0.0;
  /// The whole of RunSimulation (setup, every step, the files at the end).
  double run_total_s = 0.0;
};

/// Adds the calling thread's CPU time from construction to destruction to
/// *total_s.
class ScopedCpuTimer {
 public:
  explicit ScopedCpuTimer(double* total_s) : total_s_(total_s), start_s_(ThreadCpuSeconds()) {}
  ~ScopedCpuTimer() { *total_s_ += ThreadCpuSeconds() - start_s_; }
  ScopedCpuTimer(const ScopedCpuTimer&) = delete;
  ScopedCpuTimer& operator=(const ScopedCpuTimer&) = delete;

 private:
  double* total_s_;
  double start_s_;
};

/// Charges the calling thread's CPU time to phases that follow one another,
/// with one clock read per phase boundary (a ScopedCpuTimer per phase reads
/// the clock twice; on this project's virtual machines each read of a
/// thread's CPU clock is a system call). Start() begins a lap; Charge()
/// adds the time since the last read to a phase and begins the next lap.
class CpuLaps {
 public:
  /// Begins a lap now.
  void Start() { last_s_ = ThreadCpuSeconds(); }
  /// Adds the CPU time since the last Start() or Charge() to *total_s.
  void Charge(double* total_s) {
    const double now_s = ThreadCpuSeconds();
    *total_s += now_s - last_s_;
    last_s_ = now_s;
  }

 private:
  double last_s_ = 0.0;
};

/// The text `mjslam run --profile` prints: each phase's CPU seconds and
/// share, the rest of the run, the process's CPU time (`process_cpu_s`,
/// loading included), and simulated seconds per CPU second for the run
/// and for the run without the filters' own steps. `sim_time_s` > 0.
std::string PhaseCpuReport(const PhaseCpu& cpu, double sim_time_s, double process_cpu_s);

}  // namespace mjslam::app
