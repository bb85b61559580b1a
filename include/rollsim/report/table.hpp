// Small output helpers shared by commands: an aligned plain-text table and a one-line JSON object writer.
#pragma once

#include <string>
#include <vector>

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

/// Fixed-point text of `value` with `decimals` digits after the point ("NaN"/"inf" for non-finite values).
std::string fixed(double value, int decimals);

/// Builds one JSON object on one line, keys in insertion order. Non-finite numbers are written as null
/// (JSON has no NaN), strings are escaped.
class JsonObject {
 public:
  JsonObject& add(const std::string& key, double value);
  JsonObject& add(const std::string& key, int value);
  JsonObject& add(const std::string& key, bool value);
  JsonObject& add(const std::string& key, const std::string& value);
  JsonObject& add(const std::string& key, const char* value) { return add(key, std::string(value)); }
  JsonObject& add_null(const std::string& key);
  /// A nested object as the value of `key`.
  JsonObject& add(const std::string& key, const JsonObject& value);
  /// "{...}" without a trailing newline.
  std::string str() const;

 private:
  void add_raw(const std::string& key, const std::string& json_value);
  std::string body_;
};

/// `text` as a quoted, escaped JSON string.
std::string json_string(const std::string& text);

}  // namespace rollsim::report
