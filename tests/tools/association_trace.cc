// Diagnostic: prints what tests/tools/association_audit.h finds for one
// filter of a run directory: each wrong line match (an observation matched
// to a feature made from another true line) and each new line feature for a
// true line that already has one, between T_FROM and T_TO, then counts per
// 50 s.
//
//   association_trace RUN_DIR [classical|selective] [T_FROM T_TO [KEY=VALUE ...]]
//
// KEY=VALUE: config overrides for the filter, e.g. slam.ekf.gate_line_side=false.
// Not part of the test suite: built on request (target association_trace).
#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "tests/tools/association_audit.h"

int main(int argc, char** argv) {
  if (argc < 2) {
    std::fprintf(stderr,
                 "usage: association_trace RUN_DIR [classical|selective] [T_FROM T_TO [KEY=VALUE ...]]\n");
    return 2;
  }
  const std::string name = argc > 2 ? argv[2] : "classical";
  const double t_from = argc > 4 ? std::atof(argv[3]) : 0.0;
  const double t_to = argc > 4 ? std::atof(argv[4]) : -1.0;
  std::vector<std::string> overrides;
  for (int a = 5; a < argc; ++a) overrides.push_back(argv[a]);
  try {
    mjslam::testing::AssociationAudit audit =
        mjslam::testing::AuditAssociations(argv[1], name, overrides, t_from, t_to);
    for (const std::string& event : audit.events) std::printf("%s\n", event.c_str());
    for (const std::string& scan : audit.scan_lines) std::printf("%s\n", scan.c_str());
    std::printf("replay: largest |x - recorded %s_x| %.3g m\n", name.c_str(),
                audit.max_replay_difference);
    std::printf("per 50 s: wrong line matches, new line features for lines already mapped; all "
                "observations matched (mean nearest NIS), new, ambiguous; largest position "
                "error (m)\n");
    for (int bin = 0; bin * 50.0 <= audit.end_t_s; ++bin) {
      std::printf("  %4d-%4d s: %4d %4d; %5d (%.2f) %4d %4d; %.3f\n", bin * 50, bin * 50 + 50,
                  audit.wrong_matches[bin], audit.duplicates[bin], audit.matched[bin],
                  audit.matched_nis[bin] / std::max(audit.matched[bin], 1), audit.added[bin],
                  audit.ambiguous[bin], audit.max_error_m[bin]);
    }
    std::printf("total: %d wrong line matches, %d duplicate line features\n",
                audit.total_wrong_matches(), audit.total_duplicates());
    const mjslam::slam::InnovationCheckResult& check = audit.innovation;
    std::printf("innovation check: %s since %.1f s; NIS test %d of %d windows failed (mean NIS "
                "%.2f); near-miss test %d of %d windows failed (since %.1f s), %.2f %% of the "
                "observations near misses; copy test %d scans failed (first at %.1f s), %ld "
                "copies\n",
                check.inconsistent() ? "INCONSISTENT" : "consistent",
                check.inconsistent() ? *check.inconsistent_since_s : -1.0, check.failed_windows,
                check.windows, check.mean_nis, check.near_miss_failed_windows,
                check.near_miss_windows,
                check.near_miss_since_s ? *check.near_miss_since_s : -1.0,
                100.0 * check.near_miss_fraction, check.copied_scans,
                check.map_copied_at_s ? *check.map_copied_at_s : -1.0, check.copies);
  } catch (const std::exception& error) {
    std::fprintf(stderr, "association_trace: %s\n", error.what());
    return 1;
  }
  return 0;
}
