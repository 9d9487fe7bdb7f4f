#include "app/engine/cpu_profile.h"

#include <cstdio>
#include <string>
#include <utility>
#include <vector>

namespace mjslam::app {

std::string PhaseCpuReport(const PhaseCpu& cpu, double sim_time_s, double process_cpu_s) {
  const std::vector<std::pair<const char*, double>> phases = {
      {"physics", cpu.physics_s},   {"laser", cpu.laser_s},       {"odometry", cpu.odometry_s},
      {"coverage", cpu.coverage_s}, {"filters", cpu.filters_s},   {"explorer", cpu.explorer_s},
      {"files", cpu.files_s},       {"video", cpu.video_s}};
  double in_phases_s = 0.0;
  for (const auto& phase : phases) in_phases_s += phase.second;
  const double total_s = cpu.run_total_s;
  std::string text;
  char line[160];
  std::snprintf(line, sizeof(line), "profile: %.1f s simulated; CPU seconds by phase:\n",
                sim_time_s);
  text += line;
  const auto add_row = [&](const char* name, double seconds) {
    std::snprintf(line, sizeof(line), "  %-26s %9.4f s %5.1f %%  %9.1f sim s/CPU s\n", name,
                  seconds, total_s > 0.0 ? 100.0 * seconds / total_s : 0.0,
                  seconds > 0.0 ? sim_time_s / seconds : 0.0);
    text += line;
  };
  for (const auto& phase : phases) add_row(phase.first, phase.second);
  add_row("rest of the run", total_s - in_phases_s);
  add_row("run (all phases + rest)", total_s);
  add_row("run without the filters", total_s - cpu.filters_s);
  add_row("process (loading included)", process_cpu_s);
  return text;
}

}  // namespace mjslam::app
