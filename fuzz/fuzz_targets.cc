#include "fuzz/fuzz_targets.h"

#include <cmath>
#include <fstream>
#include <set>
#include <sstream>
#include <optional>
#include <stdexcept>

#include "app/batch/campaign.h"
#include "app/jobs/import_log.h"
#include "app/engine/run_config.h"
#include "config/config.h"
#include "realdata/relations.h"
#include "rundir/csv_writer.h"
#include "common/box_grid.h"
#include "sim/scene.h"
#include "rundir/csv_reader.h"
#include "rundir/layout.h"
#include "rundir/map_csv.h"
#include "rundir/rows.h"

namespace mjslam::fuzz {
namespace {

// Throws std::logic_error (a finding) unless `ok`.
void Expect(bool ok, const std::string& what) {
  if (!ok) throw std::logic_error("accepted input breaks a promise: " + what);
}

void WriteScratch(std::string_view input, const std::string& path) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(input.data(), static_cast<std::streamsize>(input.size()));
  if (!out) throw std::logic_error(path + ": cannot write the fuzz input");
}

// What `read` makes of `input` (written to `scratch_path`), or none when it
// refused it with its documented error.
template <typename Reader>
auto ReadOrRefused(std::string_view input, const std::string& scratch_path, Reader read)
    -> std::optional<decltype(read(scratch_path))> {
  WriteScratch(input, scratch_path);
  try {
    return read(scratch_path);
  } catch (const std::runtime_error&) {
    return std::nullopt;  // refused, with a message
  }
}

void ReadConfig(std::string_view input, const std::string& /*scratch_path*/) {
  app::RunConfig config;
  try {
    config = config::LoadConfigString<app::RunConfig>(std::string(input), "fuzz.yaml");
  } catch (const std::runtime_error&) {
    return;  // refused, with a message
  }
  // What a run writes as its config.yaml reads back to the same config.
  const std::string yaml = config::ToYaml(config);
  const app::RunConfig again = config::LoadConfigString<app::RunConfig>(yaml, "config.yaml");
  Expect(config::ToYaml(again) == yaml, "config.yaml does not read back to itself");
}

// The numbers of the table's rows in `count` columns from `first` are finite.
void ExpectFinite(const rundir::CsvTable& table, int first, int count) {
  for (const std::vector<double>& row : table.rows) {
    for (int c = first; c < first + count; ++c) Expect(std::isfinite(row[c]), "a value not finite");
  }
}

void ExpectIncreasingTimes(const rundir::CsvTable& table) {
  for (std::size_t r = 0; r < table.rows.size(); ++r) {
    Expect(std::isfinite(table.rows[r][0]), "a time not finite");
    Expect(r == 0 || table.rows[r][0] > table.rows[r - 1][0], "a time going backwards");
  }
}

void ReadTrajectory(std::string_view input, const std::string& scratch_path) {
  const auto read = ReadOrRefused(input, scratch_path, rundir::ReadTrajectoryCsv);
  if (!read) return;
  const rundir::CsvTable& table = *read;
  Expect(!table.rows.empty(), "no rows");
  ExpectIncreasingTimes(table);
  ExpectFinite(table, 1, static_cast<int>(rundir::RecordedTrajectoryColumns().size()) - 1);
}

void ReadScans(std::string_view input, const std::string& scratch_path) {
  const auto read = ReadOrRefused(input, scratch_path, rundir::ReadScansCsv);
  if (!read) return;
  const rundir::CsvTable& table = *read;
  ExpectIncreasingTimes(table);
  // The true pose: finite, or NaN in every row (an imported log has none).
  const bool no_truth = !table.rows.empty() && std::isnan(table.rows.front()[1]);
  if (!no_truth) ExpectFinite(table, 1, rundir::kScanRangesStart - 1);
  ExpectFinite(table, rundir::kScanRangesStart,
               static_cast<int>(table.columns.size()) - rundir::kScanRangesStart);
  for (const std::vector<double>& row : table.rows) {
    for (std::size_t c = rundir::kScanRangesStart; c < row.size(); ++c) {
      Expect(row[c] >= 0.0, "a negative range");
    }
  }
}

void ReadMap(std::string_view input, const std::string& scratch_path) {
  const auto map = ReadOrRefused(input, scratch_path, rundir::ReadMapCsv);
  if (!map) return;
  for (const MapFeature& f : *map) {
    Expect(f.params.allFinite() && f.covariance.allFinite(), "a feature not finite");
    Expect(f.covariance(0, 0) >= 0.0 && f.covariance(1, 1) >= 0.0, "a negative variance");
  }
}

void ReadExplorer(std::string_view input, const std::string& scratch_path) {
  ReadOrRefused(input, scratch_path, rundir::ReadExplorerCsv);
}

// The import of a CARMEN log with its relations: the input is the log, then
// a line "=RELATIONS=", then the relations file. Read and checked as
// `mjslam import LOG --relations R` does (the offset searched), without the
// replay (ImportOptions::check_only): refused with an error, or accepted.
void ReadImport(std::string_view input, const std::string& scratch_path) {
  static const app::RunConfig config =
      app::LoadRunConfig(std::string(MJSLAM_SOURCE_DIR) + "/configs/real.yaml", {});
  const std::string text(input);
  const std::string marker = "=RELATIONS=\n";
  const std::size_t split = text.find(marker);
  WriteScratch(text.substr(0, split), scratch_path);
  app::ImportOptions options;
  options.log_path = scratch_path;
  options.out_dir = scratch_path + "_unused";
  options.check_only = true;
  options.read.skip_bad_lines = text.size() % 2 == 0;  // both ways, by the input
  if (split != std::string::npos) {
    options.relations_path = scratch_path + ".relations";
    WriteScratch(std::string_view(text).substr(split + marker.size()), options.relations_path);
  }
  app::ImportReport report;
  try {
    report = app::ImportLog(config, options);
  } catch (const std::runtime_error&) {
    return;  // refused, with a message
  }
  Expect(report.num_scans > 0 && report.num_beams >= 2, "an import without scans");
  Expect(report.skipped.size() <= 60, "an unbounded skip report");
  for (const std::string& line : report.skipped) Expect(line.size() < 400, "a long skip line");
  Expect(std::isfinite(report.time_offset_s) || split == std::string::npos,
         "a time offset not finite");
}

// A campaign file: read (LoadCampaign), its cells counted within the limit
// and, when few enough, made; accepted: distinct cell folders that are no
// folder above, and a campaign.csv of whole, quoted rows.
void ReadCampaign(std::string_view input, const std::string& scratch_path) {
  constexpr std::size_t kMaxCells = 1000;
  const auto campaign = ReadOrRefused(input, scratch_path, app::LoadCampaign);
  if (!campaign) return;
  if (app::CampaignCellCount(*campaign, kMaxCells) > kMaxCells) return;  // refused by the limit
  std::vector<app::CampaignCell> cells;
  try {
    ThrowIfProblems(campaign->Validate());
    cells = app::CampaignCells(*campaign);
  } catch (const std::runtime_error&) {
    return;
  }
  std::set<std::string> names;
  for (const app::CampaignCell& cell : cells) {
    Expect(!cell.name.empty() && cell.name[0] != '.' && cell.name.find('/') == std::string::npos,
           "a cell folder outside the campaign");
    Expect(names.insert(cell.name).second, "two cells in one folder");
  }
  std::vector<nlohmann::json> summaries(cells.size());
  for (nlohmann::json& summary : summaries) summary["sweep"]["completed_runs"] = 1;
  const std::string csv = app::CampaignTableCsv(cells, summaries);
  // Every row has the header's number of fields (RFC 4180: quotes hide commas).
  std::size_t fields = 0, row_fields = 1, rows = 0;
  bool quoted = false;
  for (const char c : csv) {
    if (c == '"') quoted = !quoted;
    if (quoted) continue;
    if (c == ',') ++row_fields;
    if (c == '\n') {
      if (rows++ == 0) fields = row_fields;
      Expect(row_fields == fields, "a campaign.csv row with a shifted column");
      row_fields = 1;
    }
  }
  Expect(!quoted && rows == cells.size() + 1, "campaign.csv not made of whole rows");
}

// World geometry: one footprint per line, "box X Y YAW_DEG HX HY" or "disc X
// Y R", and "start X Y". Checked as a world's are (sim::CheckWorldExtent,
// sim.max_world_extent_m = 500), then gridded as the simulator grids them
// (BoxGrid of common/box_grid.h, 1 m cells); accepted: a grid of bounded size holding every box.
void ReadWorld(std::string_view input, const std::string& /*scratch_path*/) {
  std::istringstream lines{std::string(input)};
  std::vector<sim::ObstacleFootprint> obstacles;
  Eigen::Vector2d start = Eigen::Vector2d::Zero();
  for (std::string line; std::getline(lines, line) && obstacles.size() < 10000;) {
    std::istringstream fields(line);
    std::string kind;
    double a = 0, b = 0, c = 0, d = 0, e = 0;
    fields >> kind >> a >> b >> c >> d >> e;
    sim::ObstacleFootprint o;
    if (kind == "box") {
      o.X_WO = Pose2(a, b, c * 3.14159265358979323846 / 180.0);
      o.half_extents_m = Eigen::Vector2d(std::abs(d), std::abs(e));
    } else if (kind == "disc") {
      o.shape = sim::ObstacleFootprint::Shape::kCircle;
      o.X_WO = Pose2(a, b, 0.0);
      o.radius_m = std::abs(c);
    } else if (kind == "start") {
      start = Eigen::Vector2d(a, b);
      continue;
    } else {
      continue;
    }
    obstacles.push_back(o);
  }
  constexpr double kMaxExtentM = 500.0;
  try {
    sim::CheckWorldExtent("fuzz.xml", start, obstacles, kMaxExtentM);
  } catch (const std::runtime_error&) {
    return;  // refused, with a message
  }
  std::vector<Box2> boxes;
  for (const sim::ObstacleFootprint& o : obstacles) {
    Box2 box;
    box.lo = box.hi = o.X_WO.translation();
    if (o.shape == sim::ObstacleFootprint::Shape::kRectangle) {
      for (const Eigen::Vector2d& corner : sim::RectangleCorners(o)) {
        box.lo = box.lo.cwiseMin(corner);
        box.hi = box.hi.cwiseMax(corner);
      }
    } else {
      box.lo.array() -= o.radius_m;
      box.hi.array() += o.radius_m;
    }
    Expect(box.lo.allFinite() && box.hi.allFinite(), "an accepted footprint not finite");
    boxes.push_back(box);
  }
  const BoxGrid grid(boxes, 1.0);
  const double side = kMaxExtentM + 4.0;
  Expect(static_cast<double>(grid.limits().num_cells()) <= side * side, "a grid beyond the extent");
  for (int id = 0; id < grid.num_boxes(); ++id) {
    const Eigen::Vector2i cell = grid.limits().CellOf(0.5 * (grid.box(id).lo + grid.box(id).hi));
    Expect(grid.limits().Contains(cell), "a box outside its grid");
  }
}

}  // namespace

const std::vector<Target>& Targets() {
  static const std::vector<Target> kTargets = {{"config", ReadConfig},
                                               {"trajectory", ReadTrajectory},
                                               {"scans", ReadScans},
                                               {"map", ReadMap},
                                               {"explorer", ReadExplorer},
                                               {"import", ReadImport},
                                               {"campaign", ReadCampaign},
                                               {"world", ReadWorld}};
  return kTargets;
}

const Target& FindTarget(const std::string& name) {
  for (const Target& target : Targets()) {
    if (name == target.name) return target;
  }
  throw std::invalid_argument("no fuzz target named '" + name + "'");
}

}  // namespace mjslam::fuzz
