#include "rollsim/common/text.hpp"

#include <algorithm>

namespace rollsim {

std::string lower_ascii(std::string text) {
  // Not std::tolower: its answer depends on the process's locale, and a name must compare the same everywhere.
  std::transform(text.begin(), text.end(), text.begin(), [](char c) { return c >= 'A' && c <= 'Z' ? static_cast<char>(c - 'A' + 'a') : c; });
  return text;
}

}  // namespace rollsim
