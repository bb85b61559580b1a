// Small output helpers shared by commands: an aligned plain-text table and a one-line JSON object writer.
#pragma once

#include <string>
#include <vector>

#include "rollsim/common/format.hpp"  // fixed, format_value: the numbers in every table
#include "rollsim/common/json.hpp"

namespace rollsim::report {

/// A plain-text table whose columns are padded to their widest cell. Numbers are right-aligned, text left.
class TextTable {
 public:
  explicit TextTable(std::vector<std::string> headers);
  /// Marks column `col` as text (left-aligned); columns are right-aligned numbers by default.
  void set_left_aligned(std::size_t col);
  /// Adds a row; it must have as many cells as there are headers.
  void add_row(std::vector<std::string> cells);
  /// The table with a header line, a dashed rule and one line per row, each ending in '\n'.
  std::string render() const;

 private:
  std::vector<std::string> headers_;
  std::vector<bool> left_;
  std::vector<std::vector<std::string>> rows_;
};

// The common/ formatters and JSON writer under the names callers in report's namespace have used.
using rollsim::fixed;
using rollsim::json_string;
using rollsim::JsonObject;

}  // namespace rollsim::report
