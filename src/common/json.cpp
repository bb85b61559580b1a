#include "rollsim/common/json.hpp"

#include <cmath>
#include <cstdio>

#include "rollsim/common/format.hpp"
#include "rollsim/common/text.hpp"

namespace rollsim {

std::string yaml_double_quoted(const std::string& text) {
  std::string quoted = json_string(text);
  for (auto at = quoted.find('\x7f'); at != std::string::npos; at = quoted.find('\x7f', at)) quoted.replace(at, 1, "\\x7f");
  return quoted;
}

std::string json_string(const std::string& text) {
  std::string out = "\"";
  for (const char ch : valid_utf8(text)) {  // JSON is UTF-8: a Latin-1 name made the whole line unreadable
    switch (ch) {
      case '"': out += "\\\""; break;
      case '\\': out += "\\\\"; break;
      case '\n': out += "\\n"; break;
      case '\t': out += "\\t"; break;
      case '\r': out += "\\r"; break;
      default:
        if (static_cast<unsigned char>(ch) < 0x20) {
          char buf[8];
          std::snprintf(buf, sizeof buf, "\\u%04x", static_cast<unsigned>(static_cast<unsigned char>(ch)));
          out += buf;
        } else {
          out += ch;
        }
    }
  }
  return out + "\"";
}

void JsonObject::add_raw(const std::string& key, const std::string& json_value) {
  if (!body_.empty()) body_ += ", ";
  body_ += json_string(key) + ": " + json_value;
}

JsonObject& JsonObject::add(const std::string& key, double value) {
  if (!std::isfinite(value)) return add_null(key);
  add_raw(key, format_value(value));  // shortest round-trip form
  return *this;
}

JsonObject& JsonObject::add(const std::string& key, int value) {
  add_raw(key, std::to_string(value));
  return *this;
}

JsonObject& JsonObject::add(const std::string& key, bool value) {
  add_raw(key, value ? "true" : "false");
  return *this;
}

JsonObject& JsonObject::add(const std::string& key, const std::string& value) {
  add_raw(key, json_string(value));
  return *this;
}

JsonObject& JsonObject::add_null(const std::string& key) {
  add_raw(key, "null");
  return *this;
}

JsonObject& JsonObject::add(const std::string& key, const std::vector<std::string>& values) {
  std::string list = "[";
  for (std::size_t i = 0; i < values.size(); ++i) list += (i ? ", " : "") + json_string(values[i]);
  add_raw(key, list + "]");
  return *this;
}

std::string JsonObject::str() const { return "{" + body_ + "}"; }

JsonObject& JsonObject::add(const std::string& key, const JsonObject& value) {
  add_raw(key, value.str());
  return *this;
}

JsonObject& JsonObject::add(const std::string& key, const std::vector<JsonObject>& values) {
  std::string list = "[";
  for (std::size_t i = 0; i < values.size(); ++i) list += (i ? ", " : "") + values[i].str();
  add_raw(key, list + "]");
  return *this;
}

}  // namespace rollsim
