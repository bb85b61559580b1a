#include "rollsim/common/statistics.hpp"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <numbers>
#include <stdexcept>
#include <utility>

namespace rollsim {

double median(std::vector<double> values) {
  if (values.empty()) return std::nan("");
  const std::size_t n = values.size() / 2;
  std::nth_element(values.begin(), values.begin() + static_cast<std::ptrdiff_t>(n), values.end());
  const double upper = values[n];
  if (values.size() % 2) return upper;
  return 0.5 * (upper + *std::max_element(values.begin(), values.begin() + static_cast<std::ptrdiff_t>(n)));
}

double median_step(const std::vector<double>& values) {
  std::vector<double> steps;
  for (std::size_t i = 1; i < values.size(); ++i) steps.push_back(values[i] - values[i - 1]);
  return median(std::move(steps));
}

namespace {

// P(|T| <= t) for Student's t with nu degrees of freedom (Abramowitz and Stegun 26.7.3 and 26.7.4).
double t_central_probability(double t, int nu) {
  const double theta = std::atan(t / std::sqrt(static_cast<double>(nu)));
  const double c2 = std::cos(theta) * std::cos(theta), s = std::sin(theta);
  if (nu % 2 == 1) {
    double term = std::cos(theta), sum = nu > 1 ? term : 0.0;
    for (int k = 3; k <= nu - 2; k += 2) {
      term *= c2 * static_cast<double>(k - 1) / static_cast<double>(k);
      sum += term;
    }
    return 2.0 / std::numbers::pi * (theta + s * sum);
  }
  double term = 1.0, sum = 1.0;
  for (int k = 2; k <= nu - 2; k += 2) {
    term *= c2 * static_cast<double>(k - 1) / static_cast<double>(k);
    sum += term;
  }
  return s * sum;
}

}  // namespace

double student_t_95(int dof) {
  if (dof < 1) throw std::invalid_argument("student_t_95: dof must be at least 1");
  double lo = 1.9, hi = 13.0;  // the quantile lies between the normal's 1.96 and dof 1's 12.71
  for (int i = 0; i < 100; ++i) {
    const double mid = 0.5 * (lo + hi);
    (t_central_probability(mid, dof) < 0.95 ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}

}  // namespace rollsim
