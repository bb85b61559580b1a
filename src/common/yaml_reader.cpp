#include "rollsim/common/yaml_reader.hpp"

#include <yaml-cpp/eventhandler.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <limits>
#include <sstream>

#include "rollsim/common/error.hpp"
#include "rollsim/common/format.hpp"
#include "rollsim/common/input_file.hpp"

namespace rollsim {

bool Range::contains(double v) const {
  if (!std::isfinite(v)) return false;
  if (min_open ? !(v > min) : !(v >= min)) return false;
  if (max_open ? !(v < max) : !(v <= max)) return false;
  return true;
}

std::string Range::describe() const {
  const bool has_min = min > -1e299;
  const bool has_max = max < 1e299;
  if (has_min && has_max) {
    return std::string("must be in ") + (min_open ? "(" : "[") + format_value(min) + ", " +
           format_value(max) + (max_open ? ")" : "]");
  }
  if (has_min) return std::string("must be ") + (min_open ? "> " : ">= ") + format_value(min);
  if (has_max) return std::string("must be ") + (max_open ? "< " : "<= ") + format_value(max);
  return "must be a finite number";
}

namespace {

// No rollsim file nests more than a few levels; a tree deeper than this is not one of its inputs.
constexpr int kMaxYamlDepth = 64;

// yaml-cpp keeps every occurrence of a repeated key and answers lookups with the first, so a second
// `pressure_bar:` further down would be silently ignored; keys that are lists or mappings cannot be named.
// Both are rejected here, at the line of the offending key, for every mapping in the document.
// Aliases can make a small file a huge tree (a "billion laughs") or an endless one (an alias inside its own
// anchor): the walk stops at bounds no real input nears.
void check_keys(const YAML::Node& node, const std::string& path, std::size_t& visited, int depth = 0) {
  if (++visited > 1000000) throw InputError(path, "more than a million values (aliases repeated?); not an input file of rollsim");
  if (depth > kMaxYamlDepth) {
    throw InputError(path + ": line " + std::to_string(node.Mark().line + 1),
                     "nested more than " + std::to_string(kMaxYamlDepth) + " levels deep (an alias inside its own anchor?)");
  }
  if (node.IsSequence()) {
    for (const auto& item : node) check_keys(item, path, visited, depth + 1);
    return;
  }
  if (!node.IsMap()) return;
  std::vector<std::string> seen;
  for (const auto& kv : node) {
    const std::string at = path + ": line " + std::to_string(kv.first.Mark().line + 1);
    if (!kv.first.IsScalar()) throw InputError(at, "a key must be a plain word, not a list or mapping");
    const std::string& key = kv.first.Scalar();
    if (std::find(seen.begin(), seen.end(), key) != seen.end())
      throw InputError(at + ": key '" + key + "'", "appears a second time in the same mapping; give each key once");
    seen.push_back(key);
    check_keys(kv.second, path, visited, depth + 1);
  }
}

// The line (from 1) where '[' and '{' first nest deeper than `depth` outside quotes and comments, or 0. yaml-cpp
// gives up on a deep flow collection with "bad file", which does not say why.
int flow_nested_beyond(const std::string& text, int depth) {
  int level = 0, line = 1;
  char quote = 0;
  for (std::size_t i = 0; i < text.size(); ++i) {
    const char ch = text[i];
    if (ch == '\n') ++line;
    if (quote) {
      if (ch == quote) quote = 0;
      continue;
    }
    if (ch == '"' || ch == '\'') quote = ch;
    else if (ch == '#') i = std::min(text.find('\n', i), text.size()) - 1;
    else if ((ch == '[' || ch == '{') && ++level > depth) return line;
    else if ((ch == ']' || ch == '}') && level > 0) --level;
  }
  return 0;
}

// The first line up to `line` (from 1) whose indentation holds a tab, or 0. YAML forbids tabs in indentation, and
// yaml-cpp's own message for them ("illegal map value") does not say so.
int tab_indented_line(const std::string& text, int line) {
  std::size_t start = 0;
  for (int n = 1; n <= line && start <= text.size(); ++n) {
    const std::size_t end = std::min(text.find('\n', start), text.size());
    const std::size_t indent_end = text.find_first_not_of(" \t", start);
    const bool content = indent_end < end && text[indent_end] != '#';  // blank and comment lines are not indentation
    if (content && text.find('\t', start) < indent_end) return n;
    start = end + 1;
  }
  return 0;
}

// Where each document of `text` starts (its first node, or its start where it has none), up to `at_most` of them,
// read through yaml-cpp's event parser. Its LoadAll loops for ever on a document that opens with a token no node can
// start with (a ',' at the top level: each call returns an empty document without consuming it, so memory grows
// until the process is killed; the tyre file fuzzer found it in session 22). A document that starts where the one
// before it did is that loop, and is refused.
std::vector<YAML::Mark> document_starts(const std::string& text, std::size_t at_most, const std::string& path) {
  struct Starts : YAML::EventHandler {
    std::vector<YAML::Mark> marks;
    bool first_node = false;
    void node(const YAML::Mark& mark) {
      if (first_node) marks.back() = mark, first_node = false;
    }
    void OnDocumentStart(const YAML::Mark& mark) override { marks.push_back(mark), first_node = true; }
    void OnDocumentEnd() override {}
    void OnNull(const YAML::Mark& mark, YAML::anchor_t) override { node(mark); }
    void OnAlias(const YAML::Mark& mark, YAML::anchor_t) override { node(mark); }
    void OnScalar(const YAML::Mark& mark, const std::string&, YAML::anchor_t, const std::string&) override { node(mark); }
    void OnSequenceStart(const YAML::Mark& mark, const std::string&, YAML::anchor_t, YAML::EmitterStyle::value) override {
      node(mark);
    }
    void OnSequenceEnd() override {}
    void OnMapStart(const YAML::Mark& mark, const std::string&, YAML::anchor_t, YAML::EmitterStyle::value) override {
      node(mark);
    }
    void OnMapEnd() override {}
  } starts;
  std::istringstream in(text);
  YAML::Parser parser(in);
  while (starts.marks.size() < at_most && parser.HandleNextDocument(starts)) {
    const auto n = starts.marks.size();
    if (n >= 2 && starts.marks[n - 1].pos == starts.marks[n - 2].pos) {
      const int line = starts.marks.back().line + 1;
      const std::size_t begin = text.find_first_not_of(" \t\r\n", static_cast<std::size_t>(std::max(0, starts.marks.back().pos)));
      const std::string found = begin < text.size() ? "'" + text.substr(begin, 1) + "'" : "this";
      throw InputError(path + ": line " + std::to_string(line),
                       "malformed YAML: no key or value can start with " + found +
                           " here (a ',', ']' or '}' belongs inside a [list] or {mapping})");
    }
  }
  return starts.marks;
}

}  // namespace

std::string Range::describe_for(double v) const {
  // Beyond the default bound of +-1e300, "must be > 0" would read as if the value were too small.
  if (std::isfinite(v) && (v > max || v < min) && std::abs(v) > 1e299 && (max >= 1e299 || min <= -1e299))
    return describe() + (describe() == "must be a finite number" ? "" : ",") + " with a magnitude of at most 1e300";
  if (std::isinf(v)) return describe() + " (and finite)";
  return describe();
}

YamlMap YamlMap::load_file(const std::string& path) { return load_text(read_input_file(path, kMaxYamlFileBytes), path); }

YamlMap YamlMap::load_text(const std::string& given, const std::string& path) {
  // A NUL byte was reported as an "unknown escape character" on some line (session 21); yaml-cpp stops reading there.
  if (const auto nul = given.find('\0'); nul != std::string::npos) {
    const auto line = 1 + std::count(given.begin(), given.begin() + static_cast<std::ptrdiff_t>(nul), '\n');
    throw InputError(path + ": line " + std::to_string(line), "holds a NUL byte: rollsim reads UTF-8 text (is the file UTF-16, or binary?)");
  }
  // Old Mac line ends (CR alone), which the CSV readers take, read as one line: "expected a YAML mapping".
  std::string text = given;
  if (text.find('\n') == std::string::npos) std::replace(text.begin(), text.end(), '\r', '\n');
  YAML::Node root;
  try {
    root = YAML::Load(text);
    // A second document (after '---') is refused, not ignored in silence (session 21: a tyre file's appended
    // "---\npressure_bar: 3.0" ran at the first document's pressure).
    if (const auto starts = document_starts(text, 2, path); starts.size() > 1) {
      throw InputError(path + ": line " + std::to_string(starts[1].line + 1),
                       "a second YAML document (after '---'): a rollsim file is one document; merge its keys into the first");
    }
  } catch (const YAML::Exception& e) {
    if (const int deep = flow_nested_beyond(text, kMaxYamlDepth))
      throw InputError(path + ": line " + std::to_string(deep), "nested more than " + std::to_string(kMaxYamlDepth) + " levels deep");
    const int line = e.mark.line + 1;
    const int tab = tab_indented_line(text, line);
    throw InputError(path + ": line " + std::to_string(line),
                     "malformed YAML: " + e.msg +
                         (tab ? "; line " + std::to_string(tab) + " is indented with a tab, and YAML allows only spaces for indentation" : ""));
  }
  if (!root.IsMap()) throw InputError(path, "expected a YAML mapping of keys to values at the top level");
  std::size_t visited = 0;
  check_keys(root, path, visited);
  return YamlMap(root, path, "");
}

namespace {
// Two keys a typing slip apart: an edit distance (insert, delete, substitute, case ignored) of at most a quarter of
// the longer one's length, and at least 1.
bool spelt_alike(const std::string& a, const std::string& b) {
  std::vector<std::size_t> row(b.size() + 1);
  for (std::size_t j = 0; j <= b.size(); ++j) row[j] = j;
  for (std::size_t i = 1; i <= a.size(); ++i) {
    std::size_t diagonal = row[0];
    row[0] = i;
    for (std::size_t j = 1; j <= b.size(); ++j) {
      const std::size_t above = row[j];
      const bool same = std::tolower(static_cast<unsigned char>(a[i - 1])) == std::tolower(static_cast<unsigned char>(b[j - 1]));
      row[j] = std::min({row[j] + 1, row[j - 1] + 1, diagonal + (same ? 0 : 1)});
      diagonal = above;
    }
  }
  return row[b.size()] <= std::max<std::size_t>(1, std::max(a.size(), b.size()) / 4);
}
}  // namespace

YamlMap::YamlMap(YAML::Node node, std::string file, std::string prefix)
    : node_(std::move(node)), file_(std::move(file)), prefix_(std::move(prefix)) {}

std::string YamlMap::where(const std::string& key) const {
  return file_ + ": key '" + prefix_ + key + "'";
}

bool YamlMap::has(const std::string& key) const { return node_[key].IsDefined() && !node_[key].IsNull(); }

YAML::Node YamlMap::get(const std::string& key, bool required) {
  if (std::find(read_keys_.begin(), read_keys_.end(), key) == read_keys_.end()) read_keys_.push_back(key);
  YAML::Node n = node_[key];
  if (!n.IsDefined() || n.IsNull()) {
    if (required) {
      // A misspelt key shows up here first as a missing one: name the present keys that nobody asked for and that
      // are spelt like it. Every unread key was named before, so a case missing `expected` suggested its
      // `tolerance_pct`, which is read later (session 20).
      std::string unknown;
      if (node_.IsMap()) {
        for (const auto& kv : node_) {
          const std::string k = kv.first.as<std::string>();
          if (k != key && std::find(read_keys_.begin(), read_keys_.end(), k) == read_keys_.end() && spelt_alike(k, key))
            unknown += (unknown.empty() ? "" : ", ") + ("'" + k + "'");
        }
      }
      throw InputError(where(key), "required key is missing" + (unknown.empty() ? std::string() : " (misspelt as " + unknown + "?)"));
    }
    return YAML::Node();
  }
  return n;
}

namespace {
// A number as a person writes it in decimal: strtod also reads hexadecimal ("0x10" ran at 16 km/h) and skips leading
// blanks (" 2.1" was taken, "2.1 " refused; session 20).
bool plain_decimal(const std::string& text) {
  if (text.empty() || std::isspace(static_cast<unsigned char>(text.front()))) return false;
  return text.find_first_of("xX") == std::string::npos;
}
}  // namespace

double YamlMap::to_number(const YAML::Node& n, const std::string& key, Range range) const {
  if (!n.IsScalar()) throw InputError(where(key), "expected a number; " + range.describe());
  const std::string text = n.Scalar();
  double v = 0.0;
  try {
    std::size_t used = 0;
    if (!plain_decimal(text)) throw std::invalid_argument(text);
    v = std::stod(text, &used);
    if (used != text.size()) throw std::invalid_argument(text);
  } catch (const std::exception&) {
    // yaml-cpp spells NaN and infinity .nan and .inf: the range then says what is allowed. Anything else that is
    // not a number is a typo.
    if (text == ".nan" || text == ".NaN" || text == ".NAN") {
      v = std::nan("");
    } else if (text == ".inf" || text == ".Inf" || text == ".INF" || text == "+.inf" || text == "+.Inf" || text == "+.INF") {
      v = std::numeric_limits<double>::infinity();
    } else if (text == "-.inf" || text == "-.Inf" || text == "-.INF") {
      v = -std::numeric_limits<double>::infinity();
    } else {
      throw InputError(where(key), "'" + text + "' is not a number; " + range.describe());
    }
  }
  return checked_number(v, where(key), range);
}

double YamlMap::number(const std::string& key, Range range) { return to_number(get(key, true), key, range); }

double YamlMap::number_or(const std::string& key, double fallback, Range range) {
  auto v = optional_number(key, range);
  return v ? *v : fallback;
}

std::optional<double> YamlMap::optional_number(const std::string& key, Range range) {
  YAML::Node n = get(key, false);
  if (!has(key)) return std::nullopt;
  return to_number(n, key, range);
}

std::string YamlMap::string(const std::string& key) {
  YAML::Node n = get(key, true);
  if (!n.IsScalar()) throw InputError(where(key), "expected a text value");
  return n.Scalar();
}

std::string YamlMap::string_or(const std::string& key, const std::string& fallback) {
  auto v = optional_string(key);
  return v ? *v : fallback;
}

std::optional<std::string> YamlMap::optional_string(const std::string& key) {
  YAML::Node n = get(key, false);
  if (!has(key)) return std::nullopt;
  if (!n.IsScalar()) throw InputError(where(key), "expected a text value");
  return n.Scalar();
}

bool YamlMap::boolean_or(const std::string& key, bool fallback) {
  YAML::Node n = get(key, false);
  if (!has(key)) return fallback;
  const std::string s = n.IsScalar() ? n.Scalar() : "";
  // YAML's spellings: lower case, capitalised or upper case (True and TRUE were refused, though any YAML reader,
  // yaml-cpp's own included, takes them).
  const auto spelt = [&s](const std::string& word) {
    std::string capitalised = word, upper = word;
    capitalised[0] = static_cast<char>(std::toupper(static_cast<unsigned char>(word[0])));
    for (char& ch : upper) ch = static_cast<char>(std::toupper(static_cast<unsigned char>(ch)));
    return s == word || s == capitalised || s == upper;
  };
  if (spelt("true") || spelt("yes") || spelt("on")) return true;
  if (spelt("false") || spelt("no") || spelt("off")) return false;
  throw InputError(where(key), "'" + s + "' is not allowed: must be true or false");
}

std::vector<double> YamlMap::numbers(const std::string& key, Range range, std::size_t min_size) {
  YAML::Node n = get(key, true);
  if (!n.IsSequence()) throw InputError(where(key), "expected a list of numbers, e.g. [1, 2, 3]");
  if (n.size() < min_size) {
    throw InputError(where(key), "has " + std::to_string(n.size()) + " values; at least " +
                                     std::to_string(min_size) + " are needed");
  }
  std::vector<double> out;
  out.reserve(n.size());
  for (std::size_t i = 0; i < n.size(); ++i) out.push_back(to_number(n[i], key + "[" + std::to_string(i) + "]", range));
  return out;
}

std::optional<std::vector<double>> YamlMap::optional_numbers(const std::string& key, Range range,
                                                             std::size_t min_size) {
  if (!has(key)) {
    get(key, false);
    return std::nullopt;
  }
  return numbers(key, range, min_size);
}

YamlMap YamlMap::map(const std::string& key) {
  YAML::Node n = get(key, true);
  if (!n.IsMap()) throw InputError(where(key), "expected a mapping of keys to values");
  return YamlMap(n, file_, prefix_ + key + ".");
}

std::optional<YamlMap> YamlMap::optional_map(const std::string& key) {
  YAML::Node n = get(key, false);
  if (!has(key)) return std::nullopt;
  if (!n.IsMap()) throw InputError(where(key), "expected a mapping of keys to values");
  return YamlMap(n, file_, prefix_ + key + ".");
}

void YamlMap::accept(const std::string& key) { get(key, false); }

void YamlMap::finish() const {
  for (const auto& kv : node_) {
    const std::string key = kv.first.as<std::string>();
    if (std::find(read_keys_.begin(), read_keys_.end(), key) == read_keys_.end()) {
      std::ostringstream allowed;
      for (std::size_t i = 0; i < read_keys_.size(); ++i) allowed << (i ? ", " : "") << read_keys_[i];
      throw InputError(where(key), "unknown key (misspelt?); allowed here: " + allowed.str());
    }
  }
}

std::string data_root() {
  if (const char* env = std::getenv("ROLLSIM_DATA_DIR"); env && *env) return env;
  return ROLLSIM_SOURCE_DIR;
}

std::optional<std::string> shipped_data_file(const std::string& name, const std::string& shipped_dir, const std::string& extension) {
  namespace fs = std::filesystem;
  if (!fs::path(name).is_relative()) return std::nullopt;
  const fs::path shipped = fs::path(data_root()) / shipped_dir;
  std::vector<fs::path> candidates{shipped / name};
  if (!extension.empty()) candidates.push_back(shipped / (name + extension));
  for (const auto& c : candidates)
    if (is_regular_file_path(c)) return c.string();
  return std::nullopt;
}

namespace {
std::string resolve_data_file_in(const std::string& name, const std::string& shipped_dir, const std::string& extension,
                                 const std::string& option, const std::string& looked_beside);
}  // namespace

std::string resolve_data_file(const std::string& name, const std::string& shipped_dir,
                              const std::string& extension, const std::string& option) {
  return resolve_data_file_in(name, shipped_dir, extension, option, "");
}

std::string resolve_data_file_beside(const std::string& name, const std::string& referring_file,
                                     const std::string& shipped_dir, const std::string& extension, const std::string& option) {
  if (auto beside = file_beside(name, referring_file)) return *beside;
  const std::string folder = std::filesystem::path(referring_file).parent_path().string();
  return resolve_data_file_in(name, shipped_dir, extension, option, folder.empty() ? "." : folder);
}

namespace {
std::string resolve_data_file_in(const std::string& name, const std::string& shipped_dir, const std::string& extension,
                                 const std::string& option, const std::string& looked_beside) {
  namespace fs = std::filesystem;
  const fs::path given(name);
  // A bare name ("nedc", "155-70R19") names shipped data: a file of that name in the current folder must not
  // silently stand in for it. A name with a folder or an extension ("my.yaml", "./nedc.csv") is the user's file.
  const bool bare = !given.has_parent_path() && given.extension().empty();
  if (bare) {
    if (auto shipped = shipped_data_file(name, shipped_dir, extension)) return *shipped;
  }
  std::vector<fs::path> candidates{given};
  if (!extension.empty() && given.extension() != extension) candidates.emplace_back(name + extension);
  for (const auto& c : candidates) {
    if (is_regular_file_path(c)) return c.string();
  }
  if (!bare) {
    if (auto shipped = shipped_data_file(name, shipped_dir, extension)) return *shipped;
  }
  const fs::path shipped = fs::path(data_root()) / shipped_dir;
  // A folder given by name: say so rather than "not found".
  if (is_folder_path(given)) throw InputError(option + " '" + name + "'", "is a folder; a file is expected here");
  std::error_code ec;
  if (fs::exists(given, ec)) {
    throw InputError(option + " '" + name + "'", "is not a regular file (a device, pipe or socket?)");
  }
  // Every place looked in: a baseline's tyre beside it was found but the error did not say it looked there (session 20).
  throw InputError(option + " '" + name + "'", "file not found (looked in " +
                                                   (looked_beside.empty() ? "" : "the referring file's folder " + looked_beside + ", ") +
                                                   "the current folder and " + shipped.string() + ")");
}
}  // namespace

double parse_option_number(const std::string& text, const std::string& option, Range range) {
  char* end = nullptr;
  double v = std::strtod(text.c_str(), &end);
  if (!plain_decimal(text) || end != text.c_str() + text.size()) {
    throw InputError(option, "'" + text + "' is not a number; " + range.describe());
  }
  if (v == 0.0) v = 0.0;  // -0 printed "-0.0" speeds and powers
  // A number is said as typed (the shortest round-trip form printed --threads 100000 as "1e+05": session 22's
  // outside testing); NaN and infinity by their one name, whichever way they were typed.
  if (!range.contains(v))
    throw InputError(option, (std::isfinite(v) ? text : format_value(v)) + " is not allowed: " + range.describe_for(v));
  return v;
}

int parse_option_count(const std::string& text, const std::string& option, Range range) {
  const double v = parse_option_number(text, option, range);
  if (v != std::floor(v)) throw InputError(option, "'" + text + "' is not a whole number; " + range.describe());
  return static_cast<int>(v);
}

std::string unit_slip_hint(double v, Range fits, const std::string& unit, std::initializer_list<UnitSlip> slips) {
  for (const UnitSlip& s : slips) {
    const double converted = v * s.factor;
    if (fits.contains(converted))
      return "; is it in " + std::string(s.unit) + "? (" + format_value(v) + " " + s.unit + " = " + significant(converted, 4) + " " + unit + ")";
  }
  return "";
}

void check_physical(double v, Range physical, const std::string& unit, const std::string& why,
                    std::initializer_list<UnitSlip> slips, const std::string& where) {
  if (physical.contains(v)) return;
  throw InputError(where, format_value(v) + " " + unit + " is not allowed: " + why + "; " + physical.describe() + " " + unit +
                              unit_slip_hint(v, physical, unit, slips));
}

double checked_number(double v, const std::string& where, Range range) {
  if (!range.contains(v)) throw InputError(where, format_value(v) + " is not allowed: " + range.describe_for(v));
  return v;
}

}  // namespace rollsim
