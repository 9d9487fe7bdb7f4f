// mjslam render and the render at the end of mjslam run: the files, the MP4
// read by ffprobe, index.html loaded in headless Chromium (every image and
// the video resolve), sweep directories, bad input.
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <memory>

#include <gtest/gtest.h>

#include "rundir/csv_reader.h"
#include "renders/image.h"
#include "tests/integration/run_helpers.h"
#include "rundir/layout.h"

namespace mjslam::testing {
namespace {

namespace fs = std::filesystem;

std::string Output(const std::string& command) {
  std::string text;
  std::unique_ptr<FILE, int (*)(FILE*)> pipe(popen(command.c_str(), "r"), pclose);
  char buffer[512];
  while (pipe && fgets(buffer, sizeof(buffer), pipe.get()) != nullptr) text += buffer;
  return text;
}

// The data-status attribute the page's own check sets once every image and
// the video have loaded ("ok") or not ("error: ...").
std::string PageStatus(const std::string& page) {
  const std::string dom = Output(
      "timeout 60 chromium --headless --no-sandbox --disable-gpu --virtual-time-budget=10000 "
      "--dump-dom file://" + fs::absolute(page).string() + " 2>/dev/null");
  const std::string key = "data-status=\"";
  const std::size_t at = dom.find(key);
  if (at == std::string::npos) return "no page (is Debian's chromium installed?)";
  return dom.substr(at + key.size(), dom.find('"', at + key.size()) - at - key.size());
}

// One 2 s run of the default config rendered at 320 x 240 at its end, then
// rendered again by `mjslam render` with the optional columns and files (one
// test, so that the run and the page loads are paid once).
TEST(RenderTest, RunAndRenderLeaveImageVideoPlotsAndAPageThatLoads) {
  const std::string dir = FreshDir("render");
  ASSERT_EQ(Shell(Program() + " run --quiet --config " + DefaultConfig() +
                  " --duration 2 --set render.enabled=true --set render.width=320"
                  " --set render.height=240 --out " + dir + " 2> " + dir + ".log"),
            0)
      << ReadText(dir + ".log");
  const renders::Image final_image = renders::ReadPng(dir + "/final.png");
  EXPECT_EQ(final_image.width, 320);
  EXPECT_EQ(final_image.height, 240);
  for (const char* name : {"video.mp4", "plot_pose_error.png", "plot_processing_time.png", "index.html"}) {
    EXPECT_TRUE(fs::exists(dir + "/" + name)) << name;
  }
  // The closed loop's columns give the explored and open-loop plots.
  EXPECT_TRUE(fs::exists(dir + "/plot_explored.png"));
  EXPECT_TRUE(fs::exists(dir + "/plot_open_loop_time.png"));
  for (const fs::directory_entry& entry : fs::directory_iterator(dir)) {
    EXPECT_EQ(entry.path().filename().string().find(".tmp"), std::string::npos) << entry.path();
  }
  // 2 s at 30 frames per second of video and 3 simulated seconds per second:
  // frames at t = 0, 0.1, ..., 2.0.
  const std::string probe = Output(
      "ffprobe -v error -count_frames -select_streams v:0 -show_entries "
      "stream=width,height,nb_read_frames -of default=noprint_wrappers=1 " + dir + "/video.mp4");
  EXPECT_NE(probe.find("width=320"), std::string::npos) << probe;
  EXPECT_NE(probe.find("height=240"), std::string::npos) << probe;
  EXPECT_NE(probe.find("nb_read_frames=21"), std::string::npos) << probe;
  EXPECT_EQ(PageStatus(dir + "/index.html"), "ok");

  // A run from before the closed loop (no explored, f_period, f_open_loop,
  // f_nees columns, no explorer.csv) renders without those plots.
  const std::string older = FreshDir("render_older");
  fs::copy(dir, older, fs::copy_options::recursive | fs::copy_options::overwrite_existing);
  for (const char* name : {"explorer.csv", "plot_explored.png", "plot_open_loop_time.png"}) {
    fs::remove(older + "/" + name);
  }
  {
    const rundir::CsvTable table = rundir::ReadCsv(rundir::PathIn(dir, rundir::kTrajectoryFile));
    std::vector<std::size_t> kept;
    for (std::size_t c = 0; c < table.columns.size(); ++c) {
      const std::string& name = table.columns[c];
      const bool optional = name == "explored" || name.find("_period") != std::string::npos ||
                            name.find("_open_loop") != std::string::npos ||
                            name.find("_nees") != std::string::npos;
      if (!optional) kept.push_back(c);
    }
    std::ifstream in(rundir::PathIn(dir, rundir::kTrajectoryFile));
    std::ofstream out(rundir::PathIn(older, rundir::kTrajectoryFile));
    std::string line;
    while (std::getline(in, line)) {
      std::vector<std::string> cells;
      std::stringstream fields(line);
      std::string cell;
      while (std::getline(fields, cell, ',')) cells.push_back(cell);
      if (line.back() == ',') cells.push_back("");
      for (std::size_t k = 0; k < kept.size(); ++k) out << (k ? "," : "") << cells[kept[k]];
      out << "\n";
    }
  }
  ASSERT_EQ(Shell(Program() + " render --quiet --no-video --width 320 --height 240 " + older + " 2> " +
                  older + ".log"),
            0)
      << ReadText(older + ".log");
  EXPECT_FALSE(fs::exists(older + "/plot_open_loop_time.png"));
  EXPECT_FALSE(fs::exists(older + "/plot_explored.png"));
  EXPECT_EQ(PageStatus(older + "/index.html"), "ok");
  const std::string extended = older;

  // The page's check can fail: without one of its plots it says which.
  fs::remove(extended + "/plot_processing_time.png");
  const std::string status = PageStatus(extended + "/index.html");
  EXPECT_EQ(status.rfind("error", 0), 0u) << status;
  EXPECT_NE(status.find("plot_processing_time.png"), std::string::npos) << status;
}

TEST(RenderCommandTest, SweepDirectoryGetsPlotsAndPage) {
  const std::string dir = FreshDir("sweep");
  fs::create_directories(dir + "/runs/a");
  std::ofstream(dir + "/nees.csv") << "t,classical_anees,selective_anees,lower,upper,n_runs\n"
                                      "0,3.1,2.9,2.2,3.9,10\n0.1,3.5,3.0,2.2,3.9,10\n0.2,4.2,3.2,2.2,3.9,10\n";
  std::ofstream(dir + "/divergence.csv") << "num_points,pair,mean,variance\n"
                                            "10,classical_selective,0.5,0.2\n100,classical_selective,0.4,0.05\n"
                                            "10,selective_truth,0.8,0.3\n100,selective_truth,0.7,0.1\n";
  std::ofstream(rundir::PathIn(dir, rundir::kSummaryFile)) << R"({"runs": 1})";
  ASSERT_EQ(Shell(Program() + " render " + dir + " 2> " + dir + ".log"), 0) << ReadText(dir + ".log");
  EXPECT_TRUE(fs::exists(dir + "/plot_nees.png"));
  EXPECT_TRUE(fs::exists(dir + "/plot_divergence.png"));
  EXPECT_EQ(PageStatus(dir + "/index.html"), "ok");
}

TEST(RenderCommandTest, MissingRunFileIsAnErrorNamingIt) {
  const std::string dir = FreshDir("not_a_run");
  std::ofstream(rundir::PathIn(dir, rundir::kManifestFile)) << "{}";
  EXPECT_EQ(Shell(Program() + " render --quiet " + dir + " 2> " + dir + ".log"), 1);
  EXPECT_NE(ReadText(dir + ".log").find(rundir::PathIn(dir, rundir::kConfigFile)), std::string::npos) << ReadText(dir + ".log");
  EXPECT_FALSE(fs::exists(dir + "/final.png"));
  EXPECT_FALSE(fs::exists(dir + "/index.html"));
}

}  // namespace
}  // namespace mjslam::testing
