// Input errors: one exception type that names where bad input came from and what is allowed.
#pragma once

#include <stdexcept>
#include <string>

namespace rollsim {

/// Thrown for any bad user input (file, key, option, value). The CLI prints what() and exits non-zero.
/// `where` names the file and key or line, or the command-line option; `problem` says the value and what
/// is allowed, e.g. where = "tyres/a.yaml: key 'pressure_bar'", problem = "-1 is not allowed: must be > 0".
class InputError : public std::runtime_error {
 public:
  InputError(const std::string& where, const std::string& problem)
      : std::runtime_error(where + ": " + problem), where_(where), problem_(problem) {}
  const std::string& where() const noexcept { return where_; }
  const std::string& problem() const noexcept { return problem_; }

 private:
  std::string where_;
  std::string problem_;
};

/// Thrown when a model is asked for a state it has no solution for (e.g. a deflection reaching the rim).
/// Callers that know the input's origin re-throw it as an InputError naming the file or option.
class ModelDomainError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// Formats a double the way reports and error messages quote input values (shortest round-trip form).
std::string format_value(double value);

}  // namespace rollsim
