#include "rollsim/common/csv.hpp"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdlib>
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

std::string not_a_number(const std::string& cell) {
  std::string point = cell;
  const auto comma = point.find(',');
  if (comma != std::string::npos) point[comma] = '.';
  const bool decimal_comma = comma != std::string::npos && parse_number(point).has_value();
  return "'" + cell + "' is not a number" +
         (decimal_comma ? "; rollsim reads a decimal point (" + point + "), not a decimal comma" : std::string());
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

namespace {

// Excel's "Unicode text" and some loggers write UTF-16: every other byte is NUL, and read as UTF-8 the first
// message would show mojibake. Said once, at the file, with the way out.
void refuse_utf16(const std::string& path, const std::string& text) {
  const bool bom = text.size() >= 2 && ((text[0] == '\xFF' && text[1] == '\xFE') || (text[0] == '\xFE' && text[1] == '\xFF'));
  const auto nul = text.find('\0');
  if (!bom && nul == std::string::npos) return;
  const std::string line = std::to_string(1 + std::count(text.begin(), text.begin() + static_cast<std::ptrdiff_t>(bom ? 0 : nul), '\n'));
  throw InputError(path + (bom ? "" : ": line " + line),
                   bom ? "the file is UTF-16 (a UTF-16 byte-order mark; Excel's \"Unicode text\"); rollsim reads UTF-8: save "
                         "it as \"CSV UTF-8 (comma delimited)\""
                       : "holds a NUL byte: the file looks UTF-16 (or binary); rollsim reads UTF-8 text: save it as "
                         "\"CSV UTF-8 (comma delimited)\"");
}

// A one-cell header holding ';' or a tab is a file with another separator (Excel writes ';' where the decimal mark
// is a comma). Reading it as one column would blame a misspelt column or the first decimal, far from the cause.
void refuse_other_separator(const CsvTable& t) {
  if (t.header.size() != 1) return;
  const std::string& h = t.header.front();
  const bool semicolon = h.find(';') != std::string::npos;
  if (!semicolon && h.find('\t') == std::string::npos) return;
  throw InputError(t.file + ": line " + std::to_string(t.header_line),
                   "the header holds " + std::string(semicolon ? "';'" : "tabs") + " and no comma: the file looks " +
                       (semicolon ? "semicolon" : "tab") +
                       "-separated (perhaps with decimal commas); rollsim reads comma-separated CSV with a decimal point "
                       "(1.5): save it with ',' between cells and '.' as the decimal mark");
}

// No reader has a comment convention; a '#' line would be read as the header or as a short row.
bool starts_comment(const std::string& text, std::size_t at) {
  const auto first = text.find_first_not_of(" \t", at);
  return first != std::string::npos && text[first] == '#';
}

std::string first_line_of(const std::string& text, std::size_t at) {
  const auto end = text.find_first_of("\r\n", at);
  return trim(text.substr(at, end == std::string::npos ? std::string::npos : end - at));
}

[[noreturn]] void refuse_comment(const std::string& path, std::size_t line, const std::string& text) {
  throw InputError(path + ": line " + std::to_string(line),
                   "'" + text + "' is a comment line; comment lines are not allowed (a header line, then data rows): delete it");
}

// Text after a quoted cell's closing quote. When the cell ran over lines, the quote that opened it is the likely
// fault (one missing closing quote swallows the commas and line ends up to the next quote in the file), so the
// line where it opened is named, not only the line the reader stopped at (session 22's outside testing).
[[noreturn]] void refuse_text_after_quote(const std::string& path, std::size_t opened_line, std::size_t line) {
  const std::string quote_rule = "a quote inside a quoted cell is written \"\"";
  if (opened_line == line) throw InputError(path + ": line " + std::to_string(line), "text after a closing quote; " + quote_rule);
  throw InputError(path + ": line " + std::to_string(opened_line),
                   "a quoted cell opens here and runs over " + std::to_string(line - opened_line + 1) + " lines to line " +
                       std::to_string(line) + ", where text follows its closing quote: is a closing quote missing on line " +
                       std::to_string(opened_line) + "? (" + quote_rule + ")");
}

bool looks_integer(const std::string& cell) {
  const std::size_t start = (!cell.empty() && (cell[0] == '-' || cell[0] == '+')) ? 1 : 0;
  return cell.size() > start && std::all_of(cell.begin() + static_cast<std::ptrdiff_t>(start), cell.end(),
                                            [](unsigned char c) { return std::isdigit(c); });
}

// A row wider than its header, every cell a whole number: most likely "1,5" written for 1.5.
std::string width_mismatch(const CsvTable& t, const std::vector<std::string>& cells) {
  std::string msg = "has " + std::to_string(cells.size()) + " cells but the header (line " + std::to_string(t.header_line) +
                    ") has " + std::to_string(t.header.size()) + " columns: " + t.columns_list();
  if (cells.size() > t.header.size() && std::all_of(cells.begin(), cells.end(), looks_integer)) {
    msg += "; the numbers look written with decimal commas (1,5): rollsim reads comma-separated CSV with a decimal "
           "point (1.5)";
  }
  return msg;
}

// A trailing comma (an empty last field, as spreadsheets pad rows) loses nothing: such empty cells past the header's
// named columns are dropped, in the header and in every row, by every reader alike. A value there is refused.
void drop_trailing_empty_cells(std::vector<std::string>& cells, std::size_t keep) {
  while (cells.size() > keep && cells.back().empty()) cells.pop_back();
}

}  // namespace

CsvTable read_csv(const std::string& path, char delimiter, std::size_t max_rows, const std::string& rows_are) {
  std::string text = read_input_file(path, kMaxCsvFileBytes);
  refuse_utf16(path, text);
  if (text.size() >= 3 && text.compare(0, 3, "\xEF\xBB\xBF") == 0) text.erase(0, 3);

  CsvTable table;
  table.file = path;
  std::size_t line = 1;
  std::size_t pos = 0;
  bool have_header = false;
  std::size_t unnamed_columns = 0;  // empty names after the header's last named column (a trailing comma)
  std::size_t header_start = 0;
  while (pos < text.size()) {
    // Parse one record starting at `pos`; a record may span lines inside quotes.
    const std::size_t record_line = line;
    const std::size_t record_start = pos;
    std::vector<std::string> cells;
    std::string cell;
    bool in_quotes = false;
    bool cell_was_quoted = false;
    std::size_t quote_line = line;  // where the last quoted cell opened
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
        quote_line = line;
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
        if (cell_was_quoted && c != ' ' && c != '\t') refuse_text_after_quote(path, quote_line, line);
        if (!cell_was_quoted) cell += c;
        ++pos;
      }
    }
    if (in_quotes) {
      throw InputError(path + ": line " + std::to_string(quote_line),
                       "a quoted cell opens here and is never closed (missing \")");
    }
    cells.push_back(cell_was_quoted ? cell : trim(cell));
    const bool blank = cells.size() == 1 && cells[0].empty() && !cell_was_quoted;
    if (blank) continue;
    if (!have_header) {
      table.header = std::move(cells);
      table.header_line = record_line;
      header_start = record_start;
      have_header = true;
      const std::size_t width = table.header.size();
      drop_trailing_empty_cells(table.header, 1);
      unnamed_columns = width - table.header.size();
      refuse_other_separator(table);
      continue;
    }
    if (starts_comment(text, record_start)) refuse_comment(path, record_line, first_line_of(text, record_start));
    drop_trailing_empty_cells(cells, table.header.size());
    if (cells.size() > table.header.size() && cells.size() <= table.header.size() + unnamed_columns) {
      throw InputError(path + ": line " + std::to_string(record_line),
                       "'" + cells.back() + "' in column " + std::to_string(cells.size()) +
                           ", which has no name in the header (line " + std::to_string(table.header_line) + ")");
    }
    if (cells.size() != table.header.size()) {
      // A '#' header is a comment line that the header's place hid until the rows disagreed with it.
      if (table.header.front().rfind('#', 0) == 0) refuse_comment(path, table.header_line, first_line_of(text, header_start));
      throw InputError(path + ": line " + std::to_string(record_line), width_mismatch(table, cells));
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

std::string same_in_double_precision(const std::string& cell, const std::string& previous_cell, double value,
                                     double previous_value) {
  if (value != previous_value) return "";
  const auto wide = [](const std::string& text) -> std::optional<long double> {
    const std::string t = trim(text);
    char* end = nullptr;
    const long double v = std::strtold(t.c_str(), &end);
    if (t.empty() || end != t.c_str() + t.size()) return std::nullopt;
    return v;
  };
  const auto a = wide(cell), b = wide(previous_cell);
  if (!a || !b || *a == *b) return "";  // the same number written two ways, or not a plain number (a clock time)
  return " (written as '" + trim(previous_cell) + "' and '" + trim(cell) +
         "', they are one number in double precision, about 16 significant digits: give times from the start)";
}

}  // namespace rollsim
