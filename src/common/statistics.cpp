#include "rollsim/common/statistics.hpp"

#include <algorithm>
#include <cmath>
#include <cstddef>

namespace rollsim {

double median(std::vector<double> values) {
  if (values.empty()) return std::nan("");
  const std::size_t n = values.size() / 2;
  std::nth_element(values.begin(), values.begin() + static_cast<std::ptrdiff_t>(n), values.end());
  const double upper = values[n];
  if (values.size() % 2) return upper;
  return 0.5 * (upper + *std::max_element(values.begin(), values.begin() + static_cast<std::ptrdiff_t>(n)));
}

}  // namespace rollsim
