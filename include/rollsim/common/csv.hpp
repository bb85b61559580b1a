// Small strict CSV reader shared by every module that reads tabular input (cycles, recordings).
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace rollsim {

/// A CSV file read into text cells. The first non-blank line is the header; every data row keeps the
/// 1-based line number where it starts in the file, so errors can point at the line an editor shows.
struct CsvTable {
  std::string file;                            ///< path as given, for error messages
  std::vector<std::string> header;             ///< column names, surrounding whitespace trimmed
  std::size_t header_line = 0;                 ///< 1-based line of the header
  std::vector<std::vector<std::string>> rows;  ///< each row has exactly header.size() cells
  std::vector<std::size_t> row_line;           ///< 1-based line where each row starts

  /// Index of the column named exactly `name` (after trimming), if present; throws InputError when two columns
  /// carry that name.
  std::optional<std::size_t> column(const std::string& name) const;
  /// "a, b, c": the header, quoted, for "found columns: ..." in error messages.
  std::string columns_list() const;
  /// "file: line N, column 'name'" for an error about one cell.
  std::string where(std::size_t row, std::size_t col) const;
};

/// Reads `path`. Supports RFC 4180 quoting ("a,b" and "" inside quotes, line breaks inside quotes), CRLF
/// line ends and a UTF-8 byte-order mark. Blank lines are skipped, and so are empty cells past the header's last
/// named column (trailing commas). Throws InputError for a missing or unreadable file, an empty file, a UTF-16
/// file, a one-cell header holding ';' or a tab (another separator), a comment line ('#'), an unterminated
/// quote, a value in a column the header leaves unnamed, a row whose cell count differs from the header (saying
/// when its numbers look written with decimal commas), a file larger than kMaxCsvFileBytes (input_file.hpp) or
/// more than `max_rows` data rows (named `rows_are`).
CsvTable read_csv(const std::string& path, char delimiter = ',', std::size_t max_rows = SIZE_MAX,
                  const std::string& rows_are = "rows");

/// Parses a whole cell as a number (surrounding spaces allowed, nothing else). Returns nullopt for text
/// that is not a number. "nan" and "inf" parse (to NaN and infinity) so callers can reject them by name.
std::optional<double> parse_number(const std::string& text);

/// "'x' is not a number", saying so when the cell is a number written with a decimal comma ('1,5').
std::string not_a_number(const std::string& cell);

/// "" unless two cells written differently read as the same number `value` (a time of 1e16 s and the next sample's):
/// then a sentence saying that double precision is why, for an error that says the second is not after the first.
std::string same_in_double_precision(const std::string& cell, const std::string& previous_cell, double value,
                                     double previous_value);

/// Trims spaces and tabs at both ends.
std::string trim(const std::string& text);

}  // namespace rollsim
