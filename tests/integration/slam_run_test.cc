// Both filters on a short seeded run of the default world: consistency bands,
// covariance sanity and the selective filter's bound on updates.
#include <cmath>

#include <Eigen/Eigenvalues>
#include <gtest/gtest.h>

#include "common/angles.h"
#include "tests/integration/run_helpers.h"
#include "rundir/layout.h"

namespace mjslam::testing {
namespace {

class SlamRunTest : public ::testing::Test {
 protected:
  // Seeds 1, 2 and 3, 60 s each of the default world (the corridor loop)
  // with the default config, driven along the world's tour (the same path
  // whatever the explorer does): MAX = 2 updates per step for the selective
  // filter. Rows of the three runs are pooled.
  static void SetUpTestSuite() {
    for (const int seed : {1, 2, 3}) {
      const std::string dir = FreshDir("slam_run_" + std::to_string(seed));
      ASSERT_EQ(Shell(Program() + " run --quiet --no-render --config " + DefaultConfig() +
                      " --set control.driver=tour --duration 60 --seed " + std::to_string(seed) +
                      " --out " + dir + " 2> " +
                      dir + ".log"),
                0)
          << ReadText(dir + ".log");
      if (dir_ == nullptr) dir_ = new std::string(dir);  // maps of the first run
      const rundir::CsvTable run = rundir::ReadCsv(rundir::PathIn(dir, rundir::kTrajectoryFile));
      if (table_ == nullptr) table_ = new rundir::CsvTable(run);
      else table_->rows.insert(table_->rows.end(), run.rows.begin(), run.rows.end());
    }
  }
  static void TearDownTestSuite() {
    delete table_;
    delete dir_;
    table_ = nullptr;
    dir_ = nullptr;
  }
  double Value(std::size_t row, const std::string& column) const {
    return table_->rows[row][table_->ColumnIndex(column)];
  }
  static std::string* dir_;
  static rundir::CsvTable* table_;
};
std::string* SlamRunTest::dir_ = nullptr;
rundir::CsvTable* SlamRunTest::table_ = nullptr;

TEST_F(SlamRunTest, PoseErrorsStayNearTwoSigma) {
  // Issue target: both filters keep each component inside 2 sigma for
  // >= 90 % of the steps (seeds 1-3 pooled, 1803 steps). Measured on the default of
  // 2026-11-23 (`git show 561044d:docs/results.md`, "Tours, 3 seeds per world"): classical 0.99, 0.98, 0.94; selective 0.98, 1.00,
  // 0.96. Known faulty variants fail it: no lateral slip in the prediction
  // (classical heading 0.65, selective 0.73), corners that correct on top of
  // their lines (classical heading 0.898), forward-Euler prediction (x 0.46,
  // heading 0.40).
  const double min_fraction[3] = {0.90, 0.90, 0.90};
  for (const std::string f : {"classical", "selective"}) {
    int inside[3] = {0, 0, 0};
    const std::size_t n = table_->rows.size();
    for (std::size_t r = 0; r < n; ++r) {
      const double error[3] = {Value(r, f + "_x") - Value(r, "true_x"),
                               Value(r, f + "_y") - Value(r, "true_y"),
                               WrapAngle(Value(r, f + "_th") - Value(r, "true_th"))};
      const double variance[3] = {Value(r, f + "_pxx"), Value(r, f + "_pyy"),
                                  Value(r, f + "_pthth")};
      for (int k = 0; k < 3; ++k) {
        // The known start has zero covariance and zero error: count it inside.
        if (std::abs(error[k]) <= 2.0 * std::sqrt(variance[k]) + 1e-12) ++inside[k];
      }
    }
    for (int k = 0; k < 3; ++k) {
      const double fraction = static_cast<double>(inside[k]) / n;
      std::printf("%s component %d: %.3f of %zu steps inside 2 sigma\n", f.c_str(), k, fraction, n);
      EXPECT_GE(fraction, min_fraction[k]) << f << " component " << k;
    }
  }
}

TEST_F(SlamRunTest, PoseCovarianceIsSymmetricPositiveSemiDefinite) {
  for (const std::string f : {"classical", "selective"}) {
    for (std::size_t r = 0; r < table_->rows.size(); ++r) {
      Eigen::Matrix3d P;
      P << Value(r, f + "_pxx"), Value(r, f + "_pxy"), Value(r, f + "_pxth"),
          Value(r, f + "_pxy"), Value(r, f + "_pyy"), Value(r, f + "_pyth"),
          Value(r, f + "_pxth"), Value(r, f + "_pyth"), Value(r, f + "_pthth");
      const double smallest = Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(P).eigenvalues()(0);
      ASSERT_GE(smallest, -1e-12 * std::max(1.0, P.norm())) << f << " row " << r + 1;
    }
  }
}

TEST_F(SlamRunTest, SelectiveUsesAtMostMaxObservationsClassicalUsesAll) {
  // Matched corners whose two lines matched too correct neither filter
  // (slam.ekf.correct_corners_of_matched_lines), so nupdated <= nmatched.
  int selective_limited = 0;
  int classical_updates = 0;
  int selective_updates = 0;
  for (std::size_t r = 0; r < table_->rows.size(); ++r) {
    const double matched = Value(r, "selective_nmatched");
    const double updated = Value(r, "selective_nupdated");
    ASSERT_LE(updated, std::min(matched, 2.0)) << "row " << r + 1;
    if (updated == 2.0 && matched > 2.0) ++selective_limited;
    ASSERT_LE(Value(r, "classical_nupdated"), Value(r, "classical_nmatched")) << "row " << r + 1;
    classical_updates += static_cast<int>(Value(r, "classical_nupdated"));
    selective_updates += static_cast<int>(updated);
  }
  // The run must exercise the selection, or the test above proves nothing.
  EXPECT_GT(selective_limited, 50);
  EXPECT_GT(classical_updates, 500);
  EXPECT_GT(classical_updates, 2 * selective_updates);
  EXPECT_GT(Value(table_->rows.size() - 1, "classical_nfeat"), 10.0);
}

TEST_F(SlamRunTest, MapCovariancesArePositiveDefinite) {
  for (const std::string f : {"classical", "selective"}) {
    const rundir::CsvTable map = rundir::ReadCsv(*dir_ + "/map_" + f + ".csv", {"type"});
    ASSERT_GT(map.rows.size(), 10u);
    for (const std::vector<double>& row : map.rows) {
      const double c00 = row[map.ColumnIndex("c00")];
      const double c01 = row[map.ColumnIndex("c01")];
      const double c11 = row[map.ColumnIndex("c11")];
      EXPECT_GT(c00, 0.0);
      EXPECT_GT(c11, 0.0);
      EXPECT_GT(c00 * c11 - c01 * c01, 0.0);
    }
  }
}

}  // namespace
}  // namespace mjslam::testing
