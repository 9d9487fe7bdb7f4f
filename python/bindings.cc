// mjslam._mjslam: the closed loop and the filter registry from Python
// (python/README.md). The package mjslam (python/mjslam/__init__.py)
// re-exports what is here; users import mjslam, not this module.
//
// Three things cross the border:
// - Loop: app::ClosedLoop, stepped from Python or run to its end in C++, its
//   filters' poses, covariances and maps as numpy arrays;
// - run(): `mjslam run`'s job (app::RunSimulation, then the evaluation) into
//   a run directory;
// - register_filter(): a filter written in Python as a kind of
//   slam::FilterRegistry, so that `slam.filters` can name it and the closed
//   loop runs it beside the C++ filters (PythonFilter below).
#include <pybind11/eigen.h>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <cmath>
#include <map>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "app/engine/closed_loop.h"
#include "app/engine/run_config.h"
#include "app/jobs/evaluate.h"
#include "app/jobs/run.h"
#include "config/config.h"
#include "config/config_node.h"
#include "rundir/layout.h"
#include "sim/mujoco_errors.h"
#include "rundir/map_csv.h"
#include "slam/filter.h"

namespace py = pybind11;

namespace mjslam::python {
namespace {

using Vector3 = Eigen::Vector3d;

Vector3 AsVector(const Pose2& pose) { return {pose.x, pose.y, pose.theta}; }

// "(3, 2)": the shape of an array, for messages.
std::string ShapeText(const py::array& a) {
  std::string text = "(";
  for (py::ssize_t i = 0; i < a.ndim(); ++i) {
    text += (i > 0 ? ", " : "") + std::to_string(a.shape(i));
  }
  return text + (a.ndim() == 1 ? ",)" : ")");
}

// The resolved YAML of `params` (config.yaml's form) as Python data.
template <typename T>
py::object AsPython(const T& params) {
  return py::module_::import("yaml").attr("safe_load")(config::ToYaml(params));
}

// ---------------------------------------------------------------------------
// What a Python filter is given: a record and a scan's features, as objects
// whose attributes are numbers and numpy arrays (copies: a filter may keep
// them).

struct Record {
  SensorRecord record;
};

struct Features {
  slam::ScanFeatures features;
};

// An (n, 2) array of f(item) for each item.
template <typename Item, typename F>
py::array_t<double> Rows2(const std::vector<Item>& items, F f) {
  py::array_t<double> out({static_cast<py::ssize_t>(items.size()), py::ssize_t{2}});
  auto a = out.template mutable_unchecked<2>();
  for (std::size_t i = 0; i < items.size(); ++i) {
    const Eigen::Vector2d v = f(items[i]);
    a(i, 0) = v(0);
    a(i, 1) = v(1);
  }
  return out;
}

// An (n, 2, 2) array of f(item) for each item.
template <typename Item, typename F>
py::array_t<double> Matrices2(const std::vector<Item>& items, F f) {
  py::array_t<double> out(
      {static_cast<py::ssize_t>(items.size()), py::ssize_t{2}, py::ssize_t{2}});
  auto a = out.template mutable_unchecked<3>();
  for (std::size_t i = 0; i < items.size(); ++i) {
    const Eigen::Matrix2d m = f(items[i]);
    for (int r = 0; r < 2; ++r) {
      for (int c = 0; c < 2; ++c) a(i, r, c) = m(r, c);
    }
  }
  return out;
}

// ---------------------------------------------------------------------------
// A filter written in Python, run by the closed loop as any slam::Filter.
// The Python object implements the protocol of python/README.md ("A filter in
// Python"): step(record, features) -> dict or None, pose(), covariance(),
// num_features() and map().

class PythonFilter : public slam::Filter {
 public:
  PythonFilter(std::string name, std::string kind, py::object filter)
      : where_("filter '" + name + "' (kind " + kind + ")"), filter_(std::move(filter)) {}
  ~PythonFilter() override {
    py::gil_scoped_acquire gil;
    filter_ = py::object();
  }

  slam::StepReport Step(const SensorRecord& record, const slam::ScanFeatures* features) override {
    py::gil_scoped_acquire gil;
    py::object features_object = py::none();
    if (features != nullptr) features_object = py::cast(Features{*features});
    const py::object result = filter_.attr("step")(Record{record}, features_object);
    slam::StepReport report;
    if (!result.is_none()) {
      if (!py::isinstance<py::dict>(result)) {
        throw std::runtime_error(where_ + ": step() returned " +
                                 py::repr(result).cast<std::string>() +
                                 ", expected a dict of StepReport fields or None");
      }
      const py::dict fields = result.cast<py::dict>();
      report.num_features = -1;
      for (const auto& [key_object, value] : fields) {
        const std::string key = py::str(key_object);
        if (key == "nis_sum") {
          report.nis_sum = value.cast<double>();
        } else if (key == "nearest_nis") {
          report.nearest_nis = value.cast<std::vector<double>>();
        } else if (key == "association") {
          ReadAssociation(value, &report.association);
        } else if (int* field = IntField(&report, key)) {
          *field = value.cast<int>();
        } else {
          throw std::runtime_error(where_ + ": step() returned the unknown field '" + key +
                                   "' (known: num_features, num_observed, num_matched, "
                                   "num_redundant_corners, num_updated, num_new, "
                                   "num_corners_from_lines, num_ambiguous, num_unanchored, "
                                   "nis_sum, nearest_nis, association)");
        }
      }
      CheckPerObservation(report);
      if (report.num_features >= 0) return report;
    }
    report.num_features = num_features();
    return report;
  }

  Pose2 X_WR() const override {
    py::gil_scoped_acquire gil;
    const Vector3 pose = Array<3>("pose");
    return Pose2(pose(0), pose(1), pose(2));
  }

  Eigen::Matrix3d pose_covariance() const override {
    py::gil_scoped_acquire gil;
    const py::array_t<double, py::array::c_style | py::array::forcecast> a =
        filter_.attr("covariance")();
    if (a.ndim() != 2 || a.shape(0) != 3 || a.shape(1) != 3) {
      throw std::runtime_error(where_ + ": covariance() must give a 3x3 array, not shape " +
                               ShapeText(a));
    }
    Eigen::Matrix3d P;
    for (int r = 0; r < 3; ++r) {
      for (int c = 0; c < 3; ++c) P(r, c) = a.at(r, c);
    }
    return P;
  }

  std::vector<MapFeature> Map() const override {
    py::gil_scoped_acquire gil;
    std::vector<MapFeature> map;
    const py::object features = filter_.attr("map")();
    int index = 0;
    for (const py::handle item : features) {
      if (!py::isinstance<py::dict>(item) || !item.cast<py::dict>().contains("type") ||
          !item.cast<py::dict>().contains("params") ||
          !item.cast<py::dict>().contains("covariance")) {
        throw std::runtime_error(where_ + ": map() feature " + std::to_string(index) + " is " +
                                 py::repr(item).cast<std::string>() +
                                 ", expected a dict with type, params and covariance");
      }
      const py::dict d = item.cast<py::dict>();
      MapFeature f;
      f.id = d.contains("id") ? d["id"].cast<int>() : index;
      const std::string type = d["type"].cast<std::string>();
      if (type != "line" && type != "corner") {
        throw std::runtime_error(where_ + ": map() feature " + std::to_string(index) +
                                 " has type '" + type + "', expected 'line' or 'corner'");
      }
      f.type = type == "line" ? FeatureType::kLine : FeatureType::kCorner;
      f.params = d["params"].cast<Eigen::Vector2d>();
      f.covariance = d["covariance"].cast<Eigen::Matrix2d>();
      if (d.contains("segment") && !d["segment"].is_none()) {
        const auto segment = d["segment"].cast<std::pair<Eigen::Vector2d, Eigen::Vector2d>>();
        f.has_segment = true;
        f.p_WA = segment.first;
        f.p_WB = segment.second;
      }
      map.push_back(f);
      ++index;
    }
    return map;
  }

  int num_features() const override {
    py::gil_scoped_acquire gil;
    return filter_.attr("num_features")().cast<int>();
  }

 private:
  static int* IntField(slam::StepReport* r, const std::string& key) {
    if (key == "num_features") return &r->num_features;
    if (key == "num_observed") return &r->num_observed;
    if (key == "num_matched") return &r->num_matched;
    if (key == "num_redundant_corners") return &r->num_redundant_corners;
    if (key == "num_updated") return &r->num_updated;
    if (key == "num_new") return &r->num_new;
    if (key == "num_corners_from_lines") return &r->num_corners_from_lines;
    if (key == "num_ambiguous") return &r->num_ambiguous;
    if (key == "num_unanchored") return &r->num_unanchored;
    return nullptr;
  }

  // {"feature": [int, ...], "outcome": ["matched" | "new" | "ambiguous" |
  // "unanchored", ...]}, one entry per observation.
  void ReadAssociation(const py::handle value, slam::Association* association) const {
    const py::dict d = py::reinterpret_borrow<py::dict>(value);
    if (!py::isinstance<py::dict>(value) || !d.contains("feature") || !d.contains("outcome")) {
      throw std::runtime_error(where_ + ": step()'s association must be a dict with the lists "
                               "'feature' and 'outcome'");
    }
    association->feature = d["feature"].cast<std::vector<int>>();
    association->outcome.clear();
    for (const py::handle o : d["outcome"]) {
      const std::string text = py::str(o);
      if (text == "matched") {
        association->outcome.push_back(slam::AssociationOutcome::kMatched);
      } else if (text == "new") {
        association->outcome.push_back(slam::AssociationOutcome::kNew);
      } else if (text == "ambiguous") {
        association->outcome.push_back(slam::AssociationOutcome::kAmbiguous);
      } else if (text == "unanchored") {
        association->outcome.push_back(slam::AssociationOutcome::kUnanchored);
      } else {
        throw std::runtime_error(where_ + ": step()'s association has the outcome '" + text +
                                 "' (known: matched, new, ambiguous, unanchored)");
      }
    }
  }

  // What the innovation check reads per observation: nearest_nis and both
  // lists of association, each with one entry per observation, or none of
  // them.
  void CheckPerObservation(const slam::StepReport& r) const {
    const bool any = !r.nearest_nis.empty() || !r.association.feature.empty() ||
                     !r.association.outcome.empty();
    const auto check = [&](std::size_t size, const char* what) {
      if (any && size != static_cast<std::size_t>(r.num_observed)) {
        throw std::runtime_error(where_ + ": step()'s " + what + " has " + std::to_string(size) +
                                 " entries for num_observed " + std::to_string(r.num_observed));
      }
    };
    check(r.nearest_nis.size(), "nearest_nis");
    check(r.association.feature.size(), "association['feature']");
    check(r.association.outcome.size(), "association['outcome']");
  }

  template <int N>
  Eigen::Matrix<double, N, 1> Array(const char* method) const {
    const py::array_t<double, py::array::c_style | py::array::forcecast> a =
        filter_.attr(method)();
    if (a.ndim() != 1 || a.shape(0) != N) {
      throw std::runtime_error(where_ + ": " + method + "() must give " + std::to_string(N) +
                               " numbers, not shape " +
                               ShapeText(a));
    }
    Eigen::Matrix<double, N, 1> v;
    for (int i = 0; i < N; ++i) v(i) = a.at(i);
    return v;
  }

  std::string where_;
  py::object filter_;
};

// The Python classes registered as filter kinds, by kind. Never freed: the
// registry (a static of the program) may outlive the interpreter.
std::map<std::string, py::object>& PythonKinds() {
  static auto* kinds = new std::map<std::string, py::object>();
  return *kinds;
}

void RegisterFilter(const std::string& kind, py::object filter_class) {
  if (!PyCallable_Check(filter_class.ptr())) {
    throw py::type_error("register_filter('" + kind +
                         "', ...): expected a class or callable, got " +
                         py::repr(filter_class).cast<std::string>());
  }
  slam::FilterRegistry& registry = slam::FilterRegistry::Global();
  std::map<std::string, py::object>& kinds = PythonKinds();
  if (registry.Has(kind) && kinds.count(kind) == 0) {
    throw py::value_error("register_filter: kind '" + kind +
                          "' is a C++ filter kind of the program; choose another name");
  }
  // A kind registered from Python again (a notebook cell run twice) takes
  // the new class.
  const bool known = kinds.count(kind) > 0;
  kinds[kind] = std::move(filter_class);
  if (known) return;
  registry.Register(kind, [kind](const slam::FilterSettings& settings, const Pose2& X_WR0,
                                 const Pose2& X_RS, Rng rng) -> std::unique_ptr<slam::Filter> {
    py::gil_scoped_acquire gil;
    py::dict python_settings;
    python_settings["filter"] = AsPython(settings.filter);
    python_settings["slam"] = AsPython(settings.slam);
    python_settings["seed"] = rng.seed();
    py::object filter =
        PythonKinds().at(kind)(python_settings, AsVector(X_WR0), AsVector(X_RS));
    return std::make_unique<PythonFilter>(settings.filter.name, kind, std::move(filter));
  });
}

// ---------------------------------------------------------------------------
// Loop: the closed loop of a config, stepped from Python.

// One step as Python sees it: a copy of app::LoopStep (valid after the next
// step), its arrays made when asked for.
struct Step {
  app::LoopStep step;
  std::shared_ptr<const std::vector<std::string>> filter_names;
};

py::dict RowDict(const Step& s) {
  const rundir::TrajectoryRow& row = s.step.row;
  py::dict d;
  d["t"] = row.t_s;
  d["true_x"] = row.X_WR_true.x;
  d["true_y"] = row.X_WR_true.y;
  d["true_th"] = row.X_WR_true.theta;
  d["odom_x"] = row.X_WR_odometry.x;
  d["odom_y"] = row.X_WR_odometry.y;
  d["odom_th"] = row.X_WR_odometry.theta;
  d["cmd_v"] = row.command.v_mps;
  d["cmd_w"] = row.command.w_radps;
  d["explored"] = row.explored;
  for (std::size_t i = 0; i < row.filters.size(); ++i) {
    const rundir::FilterRow& f = row.filters[i];
    const std::string& p = (*s.filter_names)[i];
    d[py::str(p + "_x")] = f.X_WR.x;
    d[py::str(p + "_y")] = f.X_WR.y;
    d[py::str(p + "_th")] = f.X_WR.theta;
    d[py::str(p + "_pxx")] = f.P(0, 0);
    d[py::str(p + "_pxy")] = f.P(0, 1);
    d[py::str(p + "_pxth")] = f.P(0, 2);
    d[py::str(p + "_pyy")] = f.P(1, 1);
    d[py::str(p + "_pyth")] = f.P(1, 2);
    d[py::str(p + "_pthth")] = f.P(2, 2);
    d[py::str(p + "_nfeat")] = f.num_features;
    d[py::str(p + "_nmatched")] = f.num_matched;
    d[py::str(p + "_nupdated")] = f.num_updated;
    d[py::str(p + "_us")] = f.processing_us;
    d[py::str(p + "_period")] = f.period_s;
    d[py::str(p + "_open_loop")] = f.open_loop_s;
    d[py::str(p + "_nees")] = f.nees;
    d[py::str(p + "_processed")] = f.processed ? 1 : 0;
  }
  return d;
}

class Loop {
 public:
  Loop(const std::string& config_path, const std::vector<std::string>& overrides)
      : config_(app::LoadRunConfig(config_path, overrides)) {
    config_.ValidateOrThrow();
    loop_ = std::make_unique<app::ClosedLoop>(config_);
    names_ = std::make_shared<const std::vector<std::string>>(loop_->filters().names());
  }

  bool done() const { return loop_->Done(); }

  Step DoStep() {
    if (loop_->Done()) throw py::stop_iteration("the loop is done");
    Step s{loop_->Step(), names_};
    ++steps_;
    return s;
  }

  int Run() {
    const int before = steps_;
    while (!loop_->Done()) {
      loop_->Step();
      ++steps_;
    }
    return steps_ - before;
  }

  int Index(const std::string& name) const {
    const int i = loop_->filters().IndexOf(name);
    if (i < 0) {
      std::string names;
      for (const std::string& n : loop_->filters().names()) {
        names += (names.empty() ? "" : ", ") + n;
      }
      throw py::key_error("no filter '" + name + "' in this loop (its filters: " + names + ")");
    }
    return i;
  }

  const app::ClosedLoop& loop() const { return *loop_; }
  const app::RunConfig& config() const { return config_; }
  int steps() const { return steps_; }

 private:
  app::RunConfig config_;
  std::unique_ptr<app::ClosedLoop> loop_;
  // The filters' names, shared by every Step.
  std::shared_ptr<const std::vector<std::string>> names_;
  int steps_ = 0;
};

py::dict MapColumns(const std::vector<MapFeature>& map) {
  const auto n = static_cast<py::ssize_t>(map.size());
  py::array_t<int> id(n);
  py::list type;
  py::array_t<double> params({n, py::ssize_t{2}});
  py::array_t<double> covariance({n, py::ssize_t{2}, py::ssize_t{2}});
  py::array_t<double> segment({n, py::ssize_t{2}, py::ssize_t{2}});
  auto ids = id.mutable_unchecked<1>();
  auto p = params.mutable_unchecked<2>();
  auto c = covariance.mutable_unchecked<3>();
  auto s = segment.mutable_unchecked<3>();
  for (py::ssize_t i = 0; i < n; ++i) {
    const MapFeature& f = map[i];
    ids(i) = f.id;
    type.append(f.type == FeatureType::kLine ? "line" : "corner");
    for (int r = 0; r < 2; ++r) {
      p(i, r) = f.params(r);
      for (int k = 0; k < 2; ++k) c(i, r, k) = f.covariance(r, k);
      s(i, 0, r) = f.has_segment ? f.p_WA(r) : std::nan("");
      s(i, 1, r) = f.has_segment ? f.p_WB(r) : std::nan("");
    }
  }
  py::dict d;
  d["id"] = id;
  d["type"] = type;
  d["params"] = params;
  d["covariance"] = covariance;
  d["segment"] = segment;
  return d;
}

// mjslam run's job from Python: the run directory, then its evaluation.
py::dict Run(const std::string& config_path, const std::vector<std::string>& overrides,
             const std::string& out_dir, bool evaluate) {
  const app::RunConfig config = app::LoadRunConfig(config_path, overrides);
  app::RunOptions options;
  options.out_dir = out_dir;
  options.config_path = config_path;
  options.command_line = "mjslam.run(" + config_path + ")";
  options.show_progress = false;
  const app::RunResult result = app::RunSimulation(config, options);
  if (evaluate && result.status == "completed") app::EvaluateRunDirectory(out_dir);
  py::dict d;
  d["status"] = result.status;
  d["steps"] = result.steps;
  d["sim_time_s"] = result.sim_time_s;
  d["warnings"] = result.warnings;
  return d;
}

}  // namespace
}  // namespace mjslam::python

PYBIND11_MODULE(_mjslam, m) {
  using namespace mjslam;
  using namespace mjslam::python;
  m.doc() = "The closed loop and filter registry of mjslam (import mjslam; python/README.md).";

  // mjslam's errors with their messages (file, line, key, value).
  py::register_exception<config::ConfigError>(m, "ConfigError", PyExc_ValueError);
  py::register_exception<ParamError>(m, "ParamError", PyExc_ValueError);
  py::register_exception<sim::SimError>(m, "SimError", PyExc_RuntimeError);
  py::register_exception<slam::SlamInputError>(m, "SlamInputError", PyExc_ValueError);

  m.def("load_config",
        [](const std::string& path, const std::vector<std::string>& overrides) {
          const app::RunConfig config = app::LoadRunConfig(path, overrides);
          config.ValidateOrThrow();
          return AsPython(config);
        },
        py::arg("path"), py::arg("overrides") = std::vector<std::string>{},
        "The resolved config of `path` with `overrides` ('key=value', as --set) applied, as "
        "dicts and lists (what config.yaml of a run holds). Raises ConfigError.");

  m.def("run", &Run, py::arg("config"), py::arg("overrides") = std::vector<std::string>{},
        py::arg("out"), py::arg("evaluate") = true,
        "mjslam run without renders: writes the run directory `out` (docs/run_directory.md) "
        "and evaluates it. Python filters named in slam.filters run beside the C++ ones. "
        "Returns {status, steps, sim_time_s, warnings}.");

  m.def("register_filter", &RegisterFilter, py::arg("kind"), py::arg("filter_class"),
        "Makes `filter_class` the filter kind `kind` of slam.filters: the closed loop builds "
        "one per entry as filter_class(settings, X_WR0, X_RS) and runs it beside the C++ "
        "filters (python/README.md, 'A filter in Python').");
  m.def("filter_kinds", [] { return slam::FilterRegistry::Global().Kinds(); },
        "The registered filter kinds, sorted.");

  py::class_<Record>(m, "Record", "What a filter is given at each control step.")
      .def_property_readonly("t", [](const Record& r) { return r.record.t_s; })
      .def_property_readonly("dt", [](const Record& r) { return r.record.dt_s; })
      .def_property_readonly("command", [](const Record& r) {
        return Eigen::Vector2d(r.record.command.v_mps, r.record.command.w_radps);
      })
      .def_property_readonly("odometry", [](const Record& r) { return AsVector(r.record.X_OR); })
      .def_property_readonly("has_scan", [](const Record& r) { return r.record.has_scan; })
      .def_property_readonly("ranges", [](const Record& r) -> py::object {
        if (!r.record.has_scan) return py::none();
        return py::array_t<double>(static_cast<py::ssize_t>(r.record.scan.ranges_m.size()),
                                   r.record.scan.ranges_m.data());
      });

  using slam::CornerObservation;
  using slam::LineObservation;
  py::class_<Features>(m, "Features", "The lines and corners extracted from one scan, in S.")
      .def_property_readonly("line_params", [](const Features& f) {
        return Rows2(f.features.lines, [](const LineObservation& l) {
          return Eigen::Vector2d(l.rho_m, l.alpha_rad);
        });
      })
      .def_property_readonly("line_covariances", [](const Features& f) {
        return Matrices2(f.features.lines, [](const LineObservation& l) { return l.covariance; });
      })
      .def_property_readonly("line_range_bias_gradients", [](const Features& f) {
        return Rows2(f.features.lines,
                     [](const LineObservation& l) { return l.range_bias_gradient; });
      })
      .def_property_readonly("line_endpoints", [](const Features& f) {
        return Matrices2(f.features.lines, [](const LineObservation& l) {
          Eigen::Matrix2d m;
          m.row(0) = l.p_SA.transpose();
          m.row(1) = l.p_SB.transpose();
          return m;
        });
      })
      .def_property_readonly("line_beams", [](const Features& f) {
        py::array_t<int> out({static_cast<py::ssize_t>(f.features.lines.size()), py::ssize_t{2}});
        auto a = out.mutable_unchecked<2>();
        for (std::size_t i = 0; i < f.features.lines.size(); ++i) {
          a(i, 0) = f.features.lines[i].first_beam;
          a(i, 1) = f.features.lines[i].last_beam;
        }
        return out;
      })
      .def_property_readonly("corner_params", [](const Features& f) {
        return Rows2(f.features.corners, [](const CornerObservation& c) {
          return Eigen::Vector2d(c.range_m, c.bearing_rad);
        });
      })
      .def_property_readonly("corner_covariances", [](const Features& f) {
        return Matrices2(f.features.corners,
                         [](const CornerObservation& c) { return c.covariance; });
      })
      .def_property_readonly("corner_range_bias_gradients", [](const Features& f) {
        return Rows2(f.features.corners,
                     [](const CornerObservation& c) { return c.range_bias_gradient; });
      })
      .def_property_readonly("corner_points", [](const Features& f) {
        return Rows2(f.features.corners, [](const CornerObservation& c) { return c.p_SC; });
      })
      .def_property_readonly("corner_convex", [](const Features& f) {
        py::array_t<bool> out(static_cast<py::ssize_t>(f.features.corners.size()));
        auto a = out.mutable_unchecked<1>();
        for (std::size_t i = 0; i < f.features.corners.size(); ++i) {
          a(i) = f.features.corners[i].kind == slam::CornerKind::kConvex;
        }
        return out;
      })
      .def_property_readonly("corner_lines", [](const Features& f) {
        py::array_t<int> out(
            {static_cast<py::ssize_t>(f.features.corners.size()), py::ssize_t{2}});
        auto a = out.mutable_unchecked<2>();
        for (std::size_t i = 0; i < f.features.corners.size(); ++i) {
          a(i, 0) = f.features.corners[i].line_a;
          a(i, 1) = f.features.corners[i].line_b;
        }
        return out;
      });

  py::class_<Step>(m, "Step", "One control step of a Loop: the record and trajectory.csv's row.")
      .def_property_readonly("index", [](const Step& s) { return s.step.index; })
      .def_property_readonly("t", [](const Step& s) { return s.step.record.t_s; })
      .def_property_readonly("record", [](const Step& s) { return Record{s.step.record}; })
      .def_property_readonly("true_pose",
                             [](const Step& s) { return AsVector(s.step.row.X_WR_true); })
      .def_property_readonly("true_laser_pose",
                             [](const Step& s) { return AsVector(s.step.X_WS_true); })
      .def_property_readonly("odometry",
                             [](const Step& s) { return AsVector(s.step.row.X_WR_odometry); })
      .def_property_readonly("command", [](const Step& s) {
        return Eigen::Vector2d(s.step.row.command.v_mps, s.step.row.command.w_radps);
      })
      .def_property_readonly("explored", [](const Step& s) { return s.step.row.explored; })
      .def_property_readonly("finished", [](const Step& s) { return s.step.finished; })
      .def_property_readonly("row", &RowDict,
                             "trajectory.csv's row of the step: column name -> value.");

  py::class_<Loop>(m, "Loop",
                   "The closed loop of a config (mjslam run's, writing no files): "
                   "Loop(config, overrides).")
      .def(py::init<const std::string&, const std::vector<std::string>&>(), py::arg("config"),
           py::arg("overrides") = std::vector<std::string>{})
      .def_property_readonly("done", &Loop::done)
      .def("step", &Loop::DoStep, "Runs one control step; returns its Step.")
      .def("__iter__", [](py::object self) { return self; })
      .def("__next__", &Loop::DoStep)
      .def("run", &Loop::Run, "Runs the remaining steps in C++; returns how many.")
      .def_property_readonly("num_steps", [](const Loop& l) { return l.loop().num_steps(); },
                             "The most steps the loop runs (run.duration_s).")
      .def_property_readonly("steps", &Loop::steps, "Steps run so far.")
      .def_property_readonly("cpu", [](const Loop& l) {
        const app::PhaseCpu& c = l.loop().cpu();
        py::dict d;
        d["physics"] = c.physics_s;
        d["laser"] = c.laser_s;
        d["odometry"] = c.odometry_s;
        d["coverage"] = c.coverage_s;
        d["filters"] = c.filters_s;
        d["driver"] = c.explorer_s;
        return d;
      }, "CPU seconds spent so far inside the C++ steps, by phase (mjslam run --profile's).")
      .def_property_readonly("filter_names",
                             [](const Loop& l) { return l.loop().filters().names(); })
      .def_property_readonly("config", [](const Loop& l) { return AsPython(l.config()); })
      .def_property_readonly("laser_mount", [](const Loop& l) { return AsVector(l.loop().X_RS()); })
      .def("pose", [](const Loop& l, const std::string& name) {
        return AsVector(l.loop().filters().filter(l.Index(name)).X_WR());
      }, py::arg("filter"), "Filter `filter`'s estimate (x, y, th) of R in W.")
      .def("covariance", [](const Loop& l, const std::string& name) {
        return l.loop().filters().filter(l.Index(name)).pose_covariance();
      }, py::arg("filter"), "Its 3x3 pose covariance.")
      .def("num_features", [](const Loop& l, const std::string& name) {
        return l.loop().filters().filter(l.Index(name)).num_features();
      }, py::arg("filter"))
      .def("map", [](const Loop& l, const std::string& name) {
        return MapColumns(l.loop().filters().filter(l.Index(name)).Map());
      }, py::arg("filter"), "Its map: id, type, params, covariance, segment (NaN: none).")
      .def("summary", [](const Loop& l) {
        return py::module_::import("json").attr("loads")(
            mjslam::rundir::ToJson(l.loop().Summary(false)).dump());
      }, "summary.json's run and filters sections for the run so far.");
}
