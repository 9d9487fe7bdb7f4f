#include "common/chi_square.h"

#include <cmath>

#include "common/check.h"

namespace mjslam {
namespace {

// Regularised lower incomplete gamma P(a, x), a > 0, x >= 0.
double GammaP(double a, double x) {
  if (x <= 0.0) return 0.0;
  const double log_prefix = a * std::log(x) - x - std::lgamma(a);
  if (x < a + 1.0) {
    // Series: P = e^-x x^a / Gamma(a+1) * sum x^n / ((a+1)...(a+n)).
    double term = 1.0 / a;
    double sum = term;
    for (int n = 1; n < 10000; ++n) {
      term *= x / (a + n);
      sum += term;
      if (std::abs(term) < std::abs(sum) * 1e-16) break;
    }
    return sum * std::exp(log_prefix);
  }
  // Continued fraction for Q = 1 - P (modified Lentz).
  const double tiny = 1e-300;
  double b = x + 1.0 - a;
  double c = 1.0 / tiny;
  double d = 1.0 / b;
  double h = d;
  for (int i = 1; i < 10000; ++i) {
    const double an = -i * (i - a);
    b += 2.0;
    d = an * d + b;
    if (std::abs(d) < tiny) d = tiny;
    c = b + an / c;
    if (std::abs(c) < tiny) c = tiny;
    d = 1.0 / d;
    const double delta = d * c;
    h *= delta;
    if (std::abs(delta - 1.0) < 1e-16) break;
  }
  return 1.0 - std::exp(log_prefix) * h;
}

}  // namespace

double ChiSquareCdf(double x, double dof) {
  MJSLAM_CHECK(dof > 0.0);
  return GammaP(0.5 * dof, 0.5 * x);
}

double ChiSquareQuantile(double p, double dof) {
  MJSLAM_CHECK(p > 0.0 && p < 1.0 && dof > 0.0);
  // Bracket, then bisect.
  double lo = 0.0;
  double hi = dof + 10.0 * std::sqrt(2.0 * dof) + 10.0;
  while (ChiSquareCdf(hi, dof) < p) hi *= 2.0;
  for (int i = 0; i < 200 && hi - lo > 1e-12 * hi; ++i) {
    const double mid = 0.5 * (lo + hi);
    if (ChiSquareCdf(mid, dof) < p) lo = mid;
    else hi = mid;
  }
  return 0.5 * (lo + hi);
}

Interval AverageNeesBounds(int num_runs, int dof, double probability) {
  MJSLAM_CHECK(num_runs >= 1 && dof >= 1 && probability > 0.0 && probability < 1.0);
  const double total_dof = static_cast<double>(num_runs) * dof;
  const double tail = 0.5 * (1.0 - probability);
  return {ChiSquareQuantile(tail, total_dof) / num_runs,
          ChiSquareQuantile(1.0 - tail, total_dof) / num_runs};
}

}  // namespace mjslam
