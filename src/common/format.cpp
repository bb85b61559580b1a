#include "rollsim/common/format.hpp"

#include <charconv>
#include <cmath>
#include <cstdio>

namespace rollsim {

std::string format_value(double value) {
  if (std::isnan(value)) return "NaN";
  if (std::isinf(value)) return value > 0 ? "inf" : "-inf";
  char buf[64];
  auto res = std::to_chars(buf, buf + sizeof buf, value);
  return std::string(buf, res.ptr);
}

namespace {
std::string printf_finite(double value, const char* format, int precision) {
  if (std::isnan(value)) return "NaN";
  if (std::isinf(value)) return value > 0 ? "inf" : "-inf";
  char buf[64];
  std::snprintf(buf, sizeof buf, format, precision, value);
  return buf;
}
}  // namespace

std::string fixed(double value, int decimals) { return printf_finite(value, "%.*f", decimals); }

int decimals_apart(double a, double b, int least, int most) {
  int d = least;
  while (d < most && fixed(a, d) == fixed(b, d)) ++d;
  return d;
}

std::string significant(double value, int digits) { return printf_finite(value, "%.*g", digits); }

}  // namespace rollsim
