#pragma once

// A campaign: a grid of sweeps, every world x every combination of the
// values of a few config keys, each cell a sweep of the same seeds. Declared
// in a small YAML file (`mjslam sweep --campaign FILE`) or with repeated
// options (`--world W`, `--vary KEY=V1,V2`); docs/commands.md, "Campaigns".

#include <cstddef>
#include <string>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include "common/params.h"

namespace mjslam::app {

/// One axis of the grid: a config key (as for --set) and its values (YAML
/// scalars, as text).
struct CampaignAxis {
  std::string key;
  std::vector<std::string> values;

  template <typename Archive>
  void Serialize(Archive* a) {
    a->Visit(MJSLAM_NVP(key));
    a->Visit(MJSLAM_NVP(values));
  }
  std::vector<ParamProblem> Validate() const;
};

/// A named condition: overrides (as --set) that together make one case, e.g.
/// {name: bias_plus_15mm, set: [laser.range_bias_m=0.015, laser.range_bias_std_m=0]}.
struct CampaignCondition {
  /// The cell's label and part of its folder name: letters, digits, '_',
  /// '-', '+', '.'.
  std::string name;
  /// KEY=VALUE overrides; none: the config as it is.
  std::vector<std::string> set;

  template <typename Archive>
  void Serialize(Archive* a) {
    a->Visit(MJSLAM_NVP(name));
    a->Visit(MJSLAM_NVP(set));
  }
  std::vector<ParamProblem> Validate() const;
};

/// A campaign file:
///
///     runs: 40                  # seeds run.seed + 0 .. runs - 1 in every cell
///     worlds: [../worlds/room.xml, ../worlds/office.xml]
///     axes:
///       - key: slam.ekf.max_updates
///         values: [1, 2, 3]
///     conditions:               # one at a time, not a product of keys
///       - {name: nominal}
///       - {name: bias, set: [laser.range_bias_m=0.015]}
///
/// World paths (in `worlds`, and run.world / run.robot_model in a
/// condition's `set`) are relative to the file's folder.
struct CampaignParams {
  /// Runs per cell; 0: --runs decides.
  int runs = 0;
  /// Worlds (MJCF files); empty: the config's run.world only.
  std::vector<std::string> worlds;
  /// Config keys and their values; the grid is their product with worlds.
  std::vector<CampaignAxis> axes;
  /// Named conditions, an axis of its own after `axes`; empty: none.
  std::vector<CampaignCondition> conditions;

  template <typename Archive>
  void Serialize(Archive* a) {
    a->Visit(MJSLAM_NVP(runs));
    a->Visit(MJSLAM_NVP(worlds));
    a->Visit(MJSLAM_NVP(axes));
    a->Visit(MJSLAM_NVP(conditions));
  }
  std::vector<ParamProblem> Validate() const;
};

/// One cell of the grid.
struct CampaignCell {
  /// Its folder name under the campaign's `cells/`: the world's file stem and
  /// each axis as `key=value`, joined by "__" (e.g.
  /// `office__slam.ekf.max_updates=2`).
  std::string name;
  /// The `--set` overrides that make the cell: `run.world=...` (when the
  /// campaign has worlds) and one `key=value` per axis, in axis order.
  std::vector<std::string> overrides;
  /// What the table shows of the cell: ("world", stem) and (key, value) per
  /// axis.
  std::vector<std::pair<std::string, std::string>> labels;
};

/// Reads a campaign file (config/ reader: unknown keys, wrong types, empty
/// axes are a ConfigError naming file:line:col and key) and makes its world
/// paths absolute, relative to the file's folder.
CampaignParams LoadCampaign(const std::string& path);

/// A campaign from repeated options: `worlds` (relative to the working
/// directory) and `vary`, each "KEY=V1,V2,..." (values split at commas).
/// Throws std::runtime_error naming a malformed --vary option.
CampaignParams CampaignFromOptions(const std::vector<std::string>& worlds,
                                   const std::vector<std::string>& vary);

/// The number of cells of the grid (worlds x the values of each axis x the
/// conditions),
/// counted without making them; `limit` + 1 when there are more than
/// `limit`.
std::size_t CampaignCellCount(const CampaignParams& campaign, std::size_t limit);

/// Throws std::runtime_error naming the axis when two of its values mean the
/// same (the same text, or the same number: 10, 10.0, 1e1).
void CheckDistinctValues(const CampaignParams& campaign);

/// The cells of the grid, worlds outermost, then the axes in order, then the
/// conditions (the last varies fastest). Throws std::runtime_error when two cells get one name or
/// an axis repeats a value (CheckDistinctValues).
std::vector<CampaignCell> CampaignCells(const CampaignParams& campaign);

/// The table across cells from each cell's sweep summary.json (`summaries`,
/// in the order of `cells`): one row per cell, its labels, the runs, and per
/// filter f: f_fraction_inside, f_mean_anees, f_verdict, f_rmse_x, f_rmse_y,
/// f_rmse_th, f_matched_fraction, f_processing_s. Returns the CSV text (a
/// header line, then one line per cell).
std::string CampaignTableCsv(const std::vector<CampaignCell>& cells,
                             const std::vector<nlohmann::json>& summaries);

/// The same table for a terminal: aligned columns, fewer of them (labels,
/// runs, and per filter the fraction inside, mean ANEES and verdict).
std::string CampaignTableText(const std::vector<CampaignCell>& cells,
                              const std::vector<nlohmann::json>& summaries);

}  // namespace mjslam::app
