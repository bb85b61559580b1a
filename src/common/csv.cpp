#include "rollsim/common/csv.hpp"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "rollsim/common/error.hpp"
#include "rollsim/common/input_file.hpp"

namespace rollsim {

std::string trim(const std::string& text) {
  const auto first = text.find_first_not_of(" \t");
  if (first == std::string::npos) return "";
  const auto last = text.find_last_not_of(" \t");
  return text.substr(first, last - first + 1);
}

std::optional<double> parse_number(const std::string& text) {
  std::string s = trim(text);
  if (s.empty()) return std::nullopt;
  // from_chars rejects a leading '+', which some loggers write.
  std::size_t start = (s[0] == '+' && s.size() > 1 && s[1] != '-') ? 1 : 0;
  double value = 0.0;
  const char* begin = s.data() + start;
  const char* end = s.data() + s.size();
  auto [ptr, ec] = std::from_chars(begin, end, value, std::chars_format::general);
  if (ptr != end) return std::nullopt;
  if (ec == std::errc::result_out_of_range) {
    // Overflow is reported as infinity so that callers reject it as non-finite, never as a clamped value.
    value = (s[start] == '-') ? -HUGE_VAL : HUGE_VAL;
    if (std::abs(std::strtod(s.c_str(), nullptr)) < 1.0) value = 0.0;  // underflow: a tiny number is 0
  } else if (ec != std::errc()) {
    return std::nullopt;
  }
  return value;
}

std::optional<std::size_t> CsvTable::column(const std::string& name) const {
  std::optional<std::size_t> found;
  for (std::size_t i = 0; i < header.size(); ++i) {
    if (header[i] != name) continue;
    // Two columns of one name: which one a reader took would be a silent guess.
    if (found) throw InputError(file + ": line " + std::to_string(header_line), "column '" + name + "' appears twice");
    found = i;
  }
  return found;
}

std::string CsvTable::columns_list() const {
  std::string out;
  for (std::size_t i = 0; i < header.size(); ++i) out += (i ? ", '" : "'") + header[i] + "'";
  return out;
}

std::string CsvTable::where(std::size_t row, std::size_t col) const {
  return file + ": line " + std::to_string(row_line.at(row)) + ", column '" + header.at(col) + "'";
}

CsvTable read_csv(const std::string& path, char delimiter, std::size_t max_rows, const std::string& rows_are) {
  std::string text = read_input_file(path, kMaxCsvFileBytes);
  if (text.size() >= 3 && text.compare(0, 3, "\xEF\xBB\xBF") == 0) text.erase(0, 3);

  CsvTable table;
  table.file = path;
  std::size_t line = 1;
  std::size_t pos = 0;
  bool have_header = false;
  while (pos < text.size()) {
    // Parse one record starting at `pos`; a record may span lines inside quotes.
    const std::size_t record_line = line;
    std::vector<std::string> cells;
    std::string cell;
    bool in_quotes = false;
    bool cell_was_quoted = false;
    bool record_done = false;
    while (pos < text.size() && !record_done) {
      const char c = text[pos];
      if (in_quotes) {
        if (c == '"') {
          if (pos + 1 < text.size() && text[pos + 1] == '"') {
            cell += '"';
            pos += 2;
            continue;
          }
          in_quotes = false;
          ++pos;
          continue;
        }
        if (c == '\n') ++line;
        cell += c;
        ++pos;
        continue;
      }
      if (c == '"' && trim(cell).empty() && !cell_was_quoted) {
        in_quotes = true;
        cell_was_quoted = true;
        cell.clear();
        ++pos;
      } else if (c == delimiter) {
        cells.push_back(cell_was_quoted ? cell : trim(cell));
        cell.clear();
        cell_was_quoted = false;
        ++pos;
      } else if (c == '\n' || c == '\r') {
        if (c == '\r' && pos + 1 < text.size() && text[pos + 1] == '\n') ++pos;
        ++pos;
        ++line;
        record_done = true;
      } else {
        if (cell_was_quoted && c != ' ' && c != '\t') {
          throw InputError(path + ": line " + std::to_string(line),
                           "text after a closing quote; a quote inside a quoted cell is written \"\"");
        }
        if (!cell_was_quoted) cell += c;
        ++pos;
      }
    }
    if (in_quotes) {
      throw InputError(path + ": line " + std::to_string(record_line),
                       "a quoted cell is never closed (missing \")");
    }
    cells.push_back(cell_was_quoted ? cell : trim(cell));
    const bool blank = cells.size() == 1 && cells[0].empty() && !cell_was_quoted;
    if (blank) continue;
    if (!have_header) {
      table.header = std::move(cells);
      table.header_line = record_line;
      have_header = true;
      continue;
    }
    if (cells.size() != table.header.size()) {
      throw InputError(path + ": line " + std::to_string(record_line),
                       "has " + std::to_string(cells.size()) + " cells but the header (line " +
                           std::to_string(table.header_line) + ") has " + std::to_string(table.header.size()) +
                           " columns: " + table.columns_list());
    }
    if (table.rows.size() == max_rows) {
      throw InputError(path + ": line " + std::to_string(record_line),
                       "more than " + std::to_string(max_rows) + " " + rows_are + "; the limit keeps memory bounded");
    }
    table.rows.push_back(std::move(cells));
    table.row_line.push_back(record_line);
  }
  if (!have_header) throw InputError(path, "file is empty: expected a header line naming the columns");
  return table;
}

}  // namespace rollsim
