#pragma once

namespace mjslam {

/// P(X <= x) for X chi-square with `dof` degrees of freedom (dof > 0, x >= 0;
/// 0 for x <= 0). The regularised lower incomplete gamma function P(dof/2,
/// x/2) by its series or continued fraction (Numerical Recipes, 3rd ed.,
/// Sec. 6.2), relative accuracy ~1e-12.
double ChiSquareCdf(double x, double dof);

/// The x with ChiSquareCdf(x, dof) = p, for p in (0, 1) (checked), by
/// bisection to 1e-12 relative.
double ChiSquareQuantile(double p, double dof);

/// A two-sided interval, e.g. for an averaged NEES.
struct Interval {
  double lower = 0.0;
  double upper = 0.0;
  bool Contains(double value) const { return value >= lower && value <= upper; }
};

/// The two-sided `probability` bounds of the average over `num_runs` runs of
/// a NEES with `dof` degrees of freedom, for a consistent filter: N times the
/// average is chi-square with N dof degrees of freedom (Bar-Shalom, Li and
/// Kirubarajan, Estimation with Applications to Tracking and Navigation,
/// 2001, Sec. 5.4.2), so the bounds are chi2_{N dof}((1 -+ probability) / 2)
/// / N. For 3 dof and 95 %: N = 25 [2.118, 4.034], N = 50 [2.360, 3.716],
/// N = 100 [2.539, 3.499]. num_runs >= 1, dof >= 1, probability in (0, 1)
/// (checked).
Interval AverageNeesBounds(int num_runs, int dof, double probability = 0.95);

}  // namespace mjslam
