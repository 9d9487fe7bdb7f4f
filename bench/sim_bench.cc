// Benchmarks of the simulator's cost per world (sim/README.md, "Local
// contacts and beams"): one control period of physics (Advance(0.1), 50
// steps of 2 ms, the robot turning in place at its start) and one 181-beam
// scan (CastLaser), each with the local physics model and beams (the
// default: sim/README.md, "The local physics model") and with MuJoCo's
// all-pairs collision on the full scene and mj_ray
// (SetLocalWorldGeoms(false)), side by side in one run. Worlds: every worlds/*.xml, plus the files listed
// in MJSLAM_BENCH_WORLDS (colon-separated).
//
//   build/bench/mjslam_sim_bench --benchmark_min_time=0.2

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include <benchmark/benchmark.h>

#include "sim/laser_noise.h"
#include "sim/mujoco_errors.h"
#include "sim/scene.h"
#include "sim/simulator.h"

namespace mjslam::sim {
namespace {

const std::string kRobot = std::string(MJSLAM_SOURCE_DIR) + "/models/pioneer3dx.xml";

std::vector<std::string> Worlds() {
  std::vector<std::string> worlds;
  for (const auto& entry :
       std::filesystem::directory_iterator(std::string(MJSLAM_SOURCE_DIR) + "/worlds")) {
    if (entry.path().extension() == ".xml") worlds.push_back(entry.path().string());
  }
  std::sort(worlds.begin(), worlds.end());
  if (const char* extra = std::getenv("MJSLAM_BENCH_WORLDS")) {
    std::stringstream list(extra);
    std::string path;
    while (std::getline(list, path, ':')) {
      if (!path.empty()) worlds.push_back(path);
    }
  }
  return worlds;
}

// One control period of physics; counters: simulated seconds per CPU second
// of the physics alone, and the world's static geoms.
void Advance(benchmark::State& state, const Scene& scene, bool local) {
  Simulator sim(scene, SimParams{}, RobotParams{});
  sim.SetLocalWorldGeoms(local);
  sim.SetCommand({0.0, 0.5});
  for (auto _ : state) sim.Advance(0.1);
  state.counters["sim_s_per_s"] =
      benchmark::Counter(0.1 * state.iterations(), benchmark::Counter::kIsRate);
}

// One 181-beam scan at the start pose (turning between scans).
void CastLaser(benchmark::State& state, const Scene& scene, bool local) {
  Simulator sim(scene, SimParams{}, RobotParams{});
  sim.SetLocalWorldGeoms(local);
  sim.SetCommand({0.0, 0.5});
  const LaserParams laser;
  int returns = 0;
  for (auto _ : state) {
    const LaserScan scan = sim.CastLaser(laser);
    benchmark::DoNotOptimize(scan.ranges_m.data());
    state.PauseTiming();
    for (const auto hit : scan.has_return) returns += hit;
    sim.Advance(0.01);
    state.ResumeTiming();
  }
  state.counters["returns_per_scan"] =
      static_cast<double>(returns) / static_cast<double>(state.iterations());
}

}  // namespace
}  // namespace mjslam::sim

int main(int argc, char** argv) {
  using namespace mjslam::sim;
  InstallMujocoErrorHandlers();
  // The scenes live until the benchmarks have run.
  std::vector<std::unique_ptr<Scene>> scenes;
  for (const std::string& world : Worlds()) {
    scenes.push_back(std::make_unique<Scene>(world, kRobot));
    const Scene* scene = scenes.back().get();
    const std::string name = std::filesystem::path(world).stem().string();
    for (const bool local : {true, false}) {
      const std::string how = local ? "/local" : "/mujoco";
      benchmark::RegisterBenchmark(("Advance0.1s/" + name + how).c_str(),
                                   [scene, local](benchmark::State& s) { Advance(s, *scene, local); })
          ->Unit(benchmark::kMicrosecond);
      benchmark::RegisterBenchmark(("CastLaser/" + name + how).c_str(),
                                   [scene, local](benchmark::State& s) {
                                     CastLaser(s, *scene, local);
                                   })
          ->Unit(benchmark::kMicrosecond);
    }
  }
  benchmark::Initialize(&argc, argv);
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
