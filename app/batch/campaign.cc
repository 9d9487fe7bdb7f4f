#include "app/batch/campaign.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <map>
#include <set>
#include <stdexcept>

#include "config/config.h"
#include "rundir/csv_writer.h"
#include "rundir/layout.h"

namespace mjslam::app {
namespace {

namespace fs = std::filesystem;

// `text` with every character a folder name should not hold replaced by '_'.
std::string FolderSafe(const std::string& text) {
  std::string safe = text;
  for (char& c : safe) {
    const bool ok = (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') ||
                    c == '.' || c == '_' || c == '-' || c == '=' || c == '+';
    if (!ok) c = '_';
  }
  // No ".", ".." or hidden folder: a name of dots would be the folder above.
  if (!safe.empty() && safe[0] == '.') safe[0] = '_';
  return safe;
}

// The number at `pointer` of `summary`, or NaN.
double NumberAt(const nlohmann::json& summary, const std::string& pointer) {
  const nlohmann::json::json_pointer p(pointer);
  if (!summary.contains(p) || !summary.at(p).is_number()) return std::nan("");
  return summary.at(p).get<double>();
}

std::string TextAt(const nlohmann::json& summary, const std::string& pointer) {
  const nlohmann::json::json_pointer p(pointer);
  if (!summary.contains(p) || !summary.at(p).is_string()) return "";
  return summary.at(p).get<std::string>();
}

// The per-filter columns of the table: name suffix and JSON pointer below
// /filters/<f>.
struct FilterColumn {
  const char* name;
  const char* pointer;
};
constexpr FilterColumn kFilterColumns[] = {
    {"fraction_inside", "/fraction_inside"},
    {"mean_anees", "/mean_anees"},
    {"rmse_x", "/runs_mean/rmse/x"},
    {"rmse_y", "/runs_mean/rmse/y"},
    {"rmse_th", "/runs_mean/rmse/th"},
    {"matched_fraction", "/runs_mean/map/matched_fraction"},
    {"matched_seen_fraction", "/runs_mean/map/matched_seen_fraction"},
    {"processing_s", "/processing_s"}};

}  // namespace

std::vector<ParamProblem> CampaignAxis::Validate() const {
  ParamChecker check;
  check.Require(!key.empty(), "key", key, "a config key, e.g. slam.ekf.max_updates");
  check.Require(!values.empty(), "values", values.size(), "at least one value");
  return check.problems();
}

std::vector<ParamProblem> CampaignCondition::Validate() const {
  ParamChecker check;
  check.Require(!name.empty() && name == FolderSafe(name), "name", name,
                "letters, digits, '_', '-', '+' or '.', not starting with '.'");
  for (std::size_t i = 0; i < set.size(); ++i) {
    const std::size_t equals = set[i].find('=');
    check.Require(equals != std::string::npos && equals > 0,
                  "set[" + std::to_string(i) + "]", set[i], "KEY=VALUE");
  }
  return check.problems();
}

std::vector<ParamProblem> CampaignParams::Validate() const {
  ParamChecker check;
  check.NonNegative("runs", runs);
  for (std::size_t i = 0; i < axes.size(); ++i) {
    check.Merge("axes[" + std::to_string(i) + "]", axes[i].Validate());
  }
  for (std::size_t i = 0; i < conditions.size(); ++i) {
    check.Merge("conditions[" + std::to_string(i) + "]", conditions[i].Validate());
  }
  return check.problems();
}

CampaignParams LoadCampaign(const std::string& path) {
  CampaignParams campaign = config::LoadConfigFile<CampaignParams>(path);
  const fs::path folder = fs::absolute(path).parent_path();
  for (std::string& world : campaign.worlds) {
    world = (folder / world).lexically_normal().string();
  }
  // A condition's world or robot, like `worlds`, relative to the file.
  for (CampaignCondition& condition : campaign.conditions) {
    for (std::string& override : condition.set) {
      for (const std::string key : {"run.world=", "run.robot_model="}) {
        if (override.rfind(key, 0) == 0) {
          override = key + (folder / override.substr(key.size())).lexically_normal().string();
        }
      }
    }
  }
  return campaign;
}

CampaignParams CampaignFromOptions(const std::vector<std::string>& worlds,
                                   const std::vector<std::string>& vary) {
  CampaignParams campaign;
  for (const std::string& world : worlds) {
    campaign.worlds.push_back(fs::absolute(world).lexically_normal().string());
  }
  for (const std::string& option : vary) {
    const std::size_t equals = option.find('=');
    if (equals == std::string::npos || equals == 0 || equals + 1 == option.size()) {
      throw std::runtime_error("--vary '" + option + "': expected KEY=V1,V2,... (e.g. "
                               "slam.ekf.max_updates=1,2,3)");
    }
    CampaignAxis axis{option.substr(0, equals), {}};
    std::string rest = option.substr(equals + 1);
    for (std::size_t start = 0;;) {
      const std::size_t comma = rest.find(',', start);
      const std::string value = rest.substr(start, comma - start);
      if (value.empty()) throw std::runtime_error("--vary '" + option + "': an empty value");
      axis.values.push_back(value);
      if (comma == std::string::npos) break;
      start = comma + 1;
    }
    campaign.axes.push_back(axis);
  }
  return campaign;
}

std::size_t CampaignCellCount(const CampaignParams& campaign, std::size_t limit) {
  std::size_t count = std::max<std::size_t>(campaign.worlds.size(), 1);
  for (const CampaignAxis& axis : campaign.axes) {
    if (count > limit) break;
    count *= axis.values.size();  // at most limit x 2^32: no overflow in 64 bits
  }
  if (count <= limit && !campaign.conditions.empty()) count *= campaign.conditions.size();
  return std::min(count, limit + 1);
}

void CheckDistinctValues(const CampaignParams& campaign) {
  for (const CampaignAxis& axis : campaign.axes) {
    // A value's meaning: the number it spells, or its text.
    std::map<std::string, std::string> seen;
    for (const std::string& value : axis.values) {
      char* end = nullptr;
      const double number = std::strtod(value.c_str(), &end);
      const bool numeric = end != value.c_str() && *end == '\0';
      const std::string meaning = numeric ? "number " + ValueText(number) : "text " + value;
      const auto [it, fresh] = seen.emplace(meaning, value);
      if (!fresh) {
        throw std::runtime_error("campaign axis " + axis.key + ": the values '" + it->second +
                                 "' and '" + value + "' are the same value (two identical cells)");
      }
    }
  }
}

std::vector<CampaignCell> CampaignCells(const CampaignParams& campaign) {
  CheckDistinctValues(campaign);
  // Start with one cell per world (or one without a world), then multiply by
  // each axis in turn.
  std::vector<CampaignCell> cells;
  if (campaign.worlds.empty()) cells.push_back({});
  for (const std::string& world : campaign.worlds) {
    const std::string stem = fs::path(world).stem().string();
    cells.push_back({FolderSafe(stem), {"run.world=" + world}, {{"world", stem}}});
  }
  for (const CampaignAxis& axis : campaign.axes) {
    std::vector<CampaignCell> product;
    for (const CampaignCell& cell : cells) {
      for (const std::string& value : axis.values) {
        CampaignCell next = cell;
        const std::string part = FolderSafe(axis.key + "=" + value);
        next.name = next.name.empty() ? part : next.name + "__" + part;
        next.overrides.push_back(axis.key + "=" + value);
        next.labels.emplace_back(axis.key, value);
        product.push_back(next);
      }
    }
    cells = product;
  }
  if (!campaign.conditions.empty()) {
    std::vector<CampaignCell> product;
    for (const CampaignCell& cell : cells) {
      for (const CampaignCondition& condition : campaign.conditions) {
        CampaignCell next = cell;
        const std::string part = FolderSafe(condition.name);
        next.name = next.name.empty() ? part : next.name + "__" + part;
        next.overrides.insert(next.overrides.end(), condition.set.begin(), condition.set.end());
        next.labels.emplace_back("condition", condition.name);
        product.push_back(next);
      }
    }
    cells = product;
  }
  // Two cells in one folder would mix their runs.
  std::set<std::string> names;
  for (CampaignCell& cell : cells) {
    if (cell.name.empty()) cell.name = "all";
    if (!names.insert(cell.name).second) {
      throw std::runtime_error("campaign: two cells would share the folder '" + cell.name +
                               "' (a world, value or condition given twice?)");
    }
  }
  return cells;
}

namespace {

// The filters of the cells' sweeps: each name of a summary's `filters`, in
// the order first seen (the default filters' when there are none).
std::vector<std::string> CampaignFilterNames(const std::vector<nlohmann::json>& summaries) {
  std::vector<std::string> names;
  for (const nlohmann::json& s : summaries) {
    if (!s.is_object() || !s.contains("filters") || !s["filters"].is_object()) continue;
    for (const auto& [name, unused] : s["filters"].items()) {
      if (std::find(names.begin(), names.end(), name) == names.end()) names.push_back(name);
    }
  }
  return names.empty() ? rundir::DefaultFilterNames() : names;
}

}  // namespace

std::string CampaignTableCsv(const std::vector<CampaignCell>& cells,
                             const std::vector<nlohmann::json>& summaries) {
  const std::vector<std::string> names = CampaignFilterNames(summaries);
  std::string csv = "cell";
  if (!cells.empty()) {
    for (const auto& [label, value] : cells.front().labels) csv += "," + rundir::CsvField(label);
  }
  csv += ",runs";
  for (const std::string& f : names) {
    for (const FilterColumn& column : kFilterColumns) csv += "," + f + "_" + column.name;
    csv += "," + f + "_verdict";
  }
  csv += "\n";
  for (std::size_t c = 0; c < cells.size(); ++c) {
    const nlohmann::json& s = summaries[c];
    csv += rundir::CsvField(cells[c].name);
    for (const auto& [label, value] : cells[c].labels) csv += "," + rundir::CsvField(value);
    csv += "," + std::to_string(s["sweep"].value("completed_runs", 0));
    for (const std::string& f : names) {
      for (const FilterColumn& column : kFilterColumns) {
        csv += "," + rundir::FormatDouble(NumberAt(s, "/filters/" + f + column.pointer));
      }
      csv += "," + TextAt(s, "/filters/" + f + "/verdict");
    }
    csv += "\n";
  }
  return csv;
}

std::string CampaignTableText(const std::vector<CampaignCell>& cells,
                              const std::vector<nlohmann::json>& summaries) {
  const std::vector<std::string> names = CampaignFilterNames(summaries);
  // Column widths: the longest cell name.
  std::size_t width = 4;
  for (const CampaignCell& cell : cells) width = std::max(width, cell.name.size());
  const int w = static_cast<int>(width);
  char line[512];
  std::string text;
  std::snprintf(line, sizeof(line), "%-*s %5s", w, "cell", "runs");
  text += line;
  for (const std::string& f : names) {
    std::snprintf(line, sizeof(line), "  %10.10s in   ANEES verdict       ", f.c_str());
    text += line;
  }
  text += "\n";
  for (std::size_t c = 0; c < cells.size(); ++c) {
    const nlohmann::json& s = summaries[c];
    std::snprintf(line, sizeof(line), "%-*s %5d", w, cells[c].name.c_str(),
                  s["sweep"].value("completed_runs", 0));
    text += line;
    for (const std::string& f : names) {
      std::snprintf(line, sizeof(line), "  %13.3f %7.3f %-14s",
                    NumberAt(s, "/filters/" + f + "/fraction_inside"),
                    NumberAt(s, "/filters/" + f + "/mean_anees"),
                    TextAt(s, "/filters/" + f + "/verdict").c_str());
      text += line;
    }
    text += "\n";
  }
  return text;
}

}  // namespace mjslam::app
