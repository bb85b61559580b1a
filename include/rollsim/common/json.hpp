// JSON output: one string escaper (RFC 8259: quote, backslash and every control character) and one-line objects.
#pragma once

#include <string>
#include <vector>

namespace rollsim {

/// `text` as a quoted JSON string: quote and backslash escaped, control characters as \n, \t, \r or \u00XX.
std::string json_string(const std::string& text);
/// The same as a YAML double-quoted scalar, which reads back as `text` (JSON's escapes are YAML's, and DEL, which
/// YAML does not print, is escaped too): names written into YAML files.
std::string yaml_double_quoted(const std::string& text);

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
  /// An array of objects as the value of `key` (a key may appear only once in an object: RFC 8259 leaves a repeat
  /// to the parser, and most keep the last).
  JsonObject& add(const std::string& key, const std::vector<JsonObject>& values);
  /// An array of strings as the value of `key`.
  JsonObject& add(const std::string& key, const std::vector<std::string>& values);
  /// "{...}" without a trailing newline.
  std::string str() const;

 private:
  void add_raw(const std::string& key, const std::string& json_value);
  std::string body_;
};

}  // namespace rollsim
