#include "rundir/map_csv.h"

#include <cmath>
#include <stdexcept>

#include "rundir/csv_reader.h"
#include "rundir/csv_writer.h"
#include "rundir/layout.h"
#include "rundir/run_files.h"

namespace mjslam::rundir {
namespace {

// Coordinates beyond this are no building's (metres): a damaged file, not a map.
constexpr double kMaxCoordinateM = 1e6;

// The problem with row values of a feature, or "" when they are a map's.
std::string FeatureProblem(const MapFeature& f) {
  constexpr double kPi = 3.14159265358979323846;
  if (!f.params.allFinite() || !f.covariance.allFinite()) return "p0, p1, c00, c01, c11: expected numbers";
  if (f.type == MapFeature::Type::kLine) {
    if (!(f.params.x() >= 0.0 && f.params.x() <= kMaxCoordinateM)) {
      return "p0: expected a line distance rho in [0, 1e6] m";
    }
    if (!(std::abs(f.params.y()) <= kPi + 1e-9)) return "p1: expected a line angle alpha in [-pi, pi]";
  } else if (f.params.cwiseAbs().maxCoeff() > kMaxCoordinateM) {
    return "p0, p1: expected a corner within 1e6 m of the origin";
  }
  // A covariance: symmetric (one c01) and positive semidefinite (the ground
  // truth's is zero). The determinant may round a little below zero.
  const double c00 = f.covariance(0, 0), c01 = f.covariance(0, 1), c11 = f.covariance(1, 1);
  if (!(c00 >= 0.0 && c11 >= 0.0 && c00 * c11 - c01 * c01 >= -1e-9 * c00 * c11) ||
      c00 > kMaxCoordinateM * kMaxCoordinateM || c11 > kMaxCoordinateM * kMaxCoordinateM) {
    return "c00, c01, c11: expected a positive semidefinite covariance";
  }
  if (f.has_segment && (f.p_WA.cwiseAbs().maxCoeff() > kMaxCoordinateM ||
                        f.p_WB.cwiseAbs().maxCoeff() > kMaxCoordinateM)) {
    return "ax, ay, bx, by: expected a segment within 1e6 m of the origin";
  }
  return "";
}

// The row's values as text, for an error message.
std::string RowValues(const std::vector<double>& row, int first, int count) {
  std::string text;
  for (int i = first; i < first + count; ++i) text += (i > first ? ", " : "") + FormatDouble(row[i]);
  return text;
}

}  // namespace

FeatureMap ReadMapCsv(const std::string& path) {
  const CsvTable table = ReadCsv(path, {"type"});
  const int id = table.ColumnIndex("id");
  table.ColumnIndex("type");  // throws when missing
  const int p0 = table.ColumnIndex("p0");
  const int c00 = table.ColumnIndex("c00");
  const int ax = table.ColumnIndex("ax");
  FeatureMap map;
  for (std::size_t r = 0; r < table.rows.size(); ++r) {
    const std::vector<double>& row = table.rows[r];
    const std::string& kind = table.text[r][0];  // the only text column
    const std::string where = path + ":" + std::to_string(r + 2) + ": ";
    MapFeature f;
    // A whole number that fits an int (a cast of NaN or 1e308 is undefined).
    if (!(row[id] >= 0.0 && row[id] <= 1e9 && std::floor(row[id]) == row[id])) {
      throw std::runtime_error(where + "id: expected a whole number in [0, 1e9] (got " +
                               FormatDouble(row[id]) + ")");
    }
    f.id = static_cast<int>(row[id]);
    if (kind == "line") {
      f.type = MapFeature::Type::kLine;
    } else if (kind == "corner") {
      f.type = MapFeature::Type::kCorner;
    } else {
      throw std::runtime_error(where + "type: expected line or corner (got '" + kind + "')");
    }
    f.params = {row[p0], row[p0 + 1]};
    f.covariance << row[c00], row[c00 + 1], row[c00 + 1], row[c00 + 2];
    f.has_segment = f.type == MapFeature::Type::kLine && std::isfinite(row[ax]) &&
                    std::isfinite(row[ax + 1]) && std::isfinite(row[ax + 2]) &&
                    std::isfinite(row[ax + 3]);
    if (f.has_segment) {
      f.p_WA = {row[ax], row[ax + 1]};
      f.p_WB = {row[ax + 2], row[ax + 3]};
    }
    if (const std::string problem = FeatureProblem(f); !problem.empty()) {
      throw std::runtime_error(where + problem + " (got p0..c11 = " + RowValues(row, p0, 5) + ")");
    }
    map.push_back(f);
  }
  return map;
}

void WriteMapCsv(const std::string& path, const FeatureMap& map) {
  std::string text = HeaderLine(MapColumns());
  for (const MapFeature& f : map) {
    const bool line = f.type == MapFeature::Type::kLine;
    text += std::to_string(f.id) + (line ? ",line," : ",corner,");
    for (const double v : {f.params.x(), f.params.y(), f.covariance(0, 0), f.covariance(0, 1),
                           f.covariance(1, 1)}) {
      text += FormatDouble(v) + ",";
    }
    if (line && f.has_segment) {
      text += FormatDouble(f.p_WA.x()) + "," + FormatDouble(f.p_WA.y()) + "," +
              FormatDouble(f.p_WB.x()) + "," + FormatDouble(f.p_WB.y());
    } else {
      text += ",,,";
    }
    text += "\n";
  }
  WriteFileAtomically(path, text);
}

}  // namespace mjslam::rundir
