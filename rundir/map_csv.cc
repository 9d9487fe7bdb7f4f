#include "rundir/map_csv.h"

#include <cmath>
#include <stdexcept>

#include "rundir/csv_reader.h"
#include "rundir/csv_writer.h"
#include "rundir/layout.h"
#include "rundir/run_files.h"

namespace mjslam::rundir {

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
    if (!f.params.allFinite() || !f.covariance.allFinite()) {
      throw std::runtime_error(where + "p0, p1, c00, c01, c11: expected numbers");
    }
    f.has_segment = f.type == MapFeature::Type::kLine && std::isfinite(row[ax]) &&
                    std::isfinite(row[ax + 1]) && std::isfinite(row[ax + 2]) &&
                    std::isfinite(row[ax + 3]);
    if (f.has_segment) {
      f.p_WA = {row[ax], row[ax + 1]};
      f.p_WB = {row[ax + 2], row[ax + 3]};
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
