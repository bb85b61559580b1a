#include "rollsim/report/table.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <stdexcept>

namespace rollsim::report {

TextTable::TextTable(std::vector<std::string> headers)
    : headers_(std::move(headers)), left_(headers_.size(), false) {}

void TextTable::set_left_aligned(std::size_t col) { left_.at(col) = true; }

void TextTable::add_row(std::vector<std::string> cells) {
  if (cells.size() != headers_.size()) throw std::logic_error("TextTable: row size differs from header size");
  // A cell is one line of printable text: a name's line break broke the table, and its escape sequences cleared
  // the user's terminal or set its title (session 21's outside testing).
  for (auto& cell : cells)
    for (char& ch : cell)
      if (static_cast<unsigned char>(ch) < 0x20 || ch == 0x7f) ch = ' ';
  rows_.push_back(std::move(cells));
}

std::string TextTable::render() const {
  std::vector<std::size_t> width(headers_.size());
  for (std::size_t c = 0; c < headers_.size(); ++c) {
    width[c] = headers_[c].size();
    for (const auto& r : rows_) width[c] = std::max(width[c], r[c].size());
  }
  auto line = [&](const std::vector<std::string>& cells) {
    std::string out;
    for (std::size_t c = 0; c < cells.size(); ++c) {
      const std::string pad(width[c] - cells[c].size(), ' ');
      if (c) out += "  ";
      out += left_[c] ? cells[c] + pad : pad + cells[c];
    }
    while (!out.empty() && out.back() == ' ') out.pop_back();
    return out + "\n";
  };
  std::string out = line(headers_);
  std::size_t total = 0;
  for (std::size_t c = 0; c < width.size(); ++c) total += width[c] + (c ? 2 : 0);
  out += std::string(total, '-') + "\n";
  for (const auto& r : rows_) out += line(r);
  return out;
}

}  // namespace rollsim::report
