#pragma once

// Toy Params structs for the config tests: nested, with every supported field
// type, validated with ParamChecker like the real modules' structs.

#include <array>
#include <cstdint>
#include <string>
#include <variant>
#include <vector>

#include "common/params.h"

namespace mjslam::config::testing {

struct InnerToyParams {
  /// Unitless gain in [0, 1].
  double gain = 0.5;
  /// Fixed-size offset (m).
  std::array<double, 3> offset_m{0.0, 0.0, 0.0};

  template <typename Archive>
  void Serialize(Archive* a) {
    a->Visit(MJSLAM_NVP(gain));
    a->Visit(MJSLAM_NVP(offset_m));
  }

  std::vector<ParamProblem> Validate() const {
    ParamChecker checker;
    checker.InRange("gain", gain, 0.0, 1.0);
    return checker.problems();
  }
};

struct LaserToyParams {
  /// Range noise standard deviation (m), >= 0.
  double range_noise_std_m = 0.01;
  /// Number of beams, > 0.
  int beam_count = 181;
  bool enabled = true;
  std::uint64_t seed = 42;
  /// "exact" or "noisy".
  std::string mode = "exact";
  /// Each > 0.
  std::vector<double> gains{1.0, 2.0};
  /// (x, y) points (m).
  std::vector<std::array<double, 2>> waypoints{};
  InnerToyParams inner;

  template <typename Archive>
  void Serialize(Archive* a) {
    a->Visit(MJSLAM_NVP(range_noise_std_m));
    a->Visit(MJSLAM_NVP(beam_count));
    a->Visit(MJSLAM_NVP(enabled));
    a->Visit(MJSLAM_NVP(seed));
    a->Visit(MJSLAM_NVP(mode));
    a->Visit(MJSLAM_NVP(gains));
    a->Visit(MJSLAM_NVP(waypoints));
    a->Visit(MJSLAM_NVP(inner));
  }

  std::vector<ParamProblem> Validate() const {
    ParamChecker checker;
    checker.NonNegative("range_noise_std_m", range_noise_std_m);
    checker.Positive("beam_count", beam_count);
    checker.OneOf("mode", mode, {"exact", "noisy"});
    for (std::size_t i = 0; i < gains.size(); ++i) {
      checker.Positive("gains[" + std::to_string(i) + "]", gains[i]);
    }
    checker.Merge("inner", inner.Validate());
    return checker.problems();
  }
};

struct ToyParams {
  /// Loop rate (Hz), > 0.
  double rate_hz = 10.0;
  /// Minimum range (m), < max_range_m.
  double min_range_m = 0.1;
  /// Maximum range (m).
  double max_range_m = 30.0;
  LaserToyParams laser;

  template <typename Archive>
  void Serialize(Archive* a) {
    a->Visit(MJSLAM_NVP(rate_hz));
    a->Visit(MJSLAM_NVP(min_range_m));
    a->Visit(MJSLAM_NVP(max_range_m));
    a->Visit(MJSLAM_NVP(laser));
  }

  std::vector<ParamProblem> Validate() const {
    ParamChecker checker;
    checker.Positive("rate_hz", rate_hz);
    checker.Require(min_range_m < max_range_m, "min_range_m", min_range_m,
                    "a value < max_range_m");
    checker.Merge("laser", laser.Validate());
    return checker.problems();
  }
};

/// One alternative of a tagged choice (`kind: line`).
struct LineToyModel {
  static constexpr const char* kKind = "line";
  /// Keys this struct no longer reads.
  static constexpr RetiredKey kRetiredKeys[] = {{"gradient", "slope", ""}};
  /// Slope, >= 0.
  double slope = 1.0;
  InnerToyParams inner;

  template <typename Archive>
  void Serialize(Archive* a) {
    a->Visit(MJSLAM_NVP(slope));
    a->Visit(MJSLAM_NVP(inner));
  }

  std::vector<ParamProblem> Validate() const {
    ParamChecker checker;
    checker.NonNegative("slope", slope);
    checker.Merge("inner", inner.Validate());
    return checker.problems();
  }
};

/// The other alternative (`kind: circle`), with a nested map of its own.
struct CircleToyModel {
  static constexpr const char* kKind = "circle";
  /// Radius (m), > 0.
  double radius_m = 2.0;
  InnerToyParams inner;
  struct Centre {
    double x_m = 0.0;
    double y_m = 0.0;
    template <typename Archive>
    void Serialize(Archive* a) {
      a->Visit(MJSLAM_NVP(x_m));
      a->Visit(MJSLAM_NVP(y_m));
    }
  } centre;

  template <typename Archive>
  void Serialize(Archive* a) {
    a->Visit(MJSLAM_NVP(radius_m));
    a->Visit(MJSLAM_NVP(inner));
    a->Visit(MJSLAM_NVP(centre));
  }

  std::vector<ParamProblem> Validate() const {
    ParamChecker checker;
    checker.Positive("radius_m", radius_m);
    checker.Merge("inner", inner.Validate());
    return checker.problems();
  }
};

/// A struct with a tagged choice (`model: {kind: line | circle, ...}`).
struct ChoiceToyParams {
  double rate_hz = 10.0;
  /// Keys this struct no longer reads.
  static constexpr RetiredKey kRetiredKeys[] = {
      {"line_slope", "model.slope", "with model.kind: line"}};
  std::variant<LineToyModel, CircleToyModel> model;

  template <typename Archive>
  void Serialize(Archive* a) {
    a->Visit(MJSLAM_NVP(rate_hz));
    a->Visit(MJSLAM_NVP(model));
  }

  std::vector<ParamProblem> Validate() const {
    ParamChecker checker;
    checker.Positive("rate_hz", rate_hz);
    checker.Merge("model", std::visit([](const auto& m) { return m.Validate(); }, model));
    return checker.problems();
  }
};

}  // namespace mjslam::config::testing
