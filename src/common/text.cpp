#include "rollsim/common/text.hpp"

#include <algorithm>

namespace rollsim {

std::string lower_ascii(std::string text) {
  // Not std::tolower: its answer depends on the process's locale, and a name must compare the same everywhere.
  std::transform(text.begin(), text.end(), text.begin(), [](char c) { return c >= 'A' && c <= 'Z' ? static_cast<char>(c - 'A' + 'a') : c; });
  return text;
}

std::string display_name(std::string name) {
  for (char& ch : name)
    if (static_cast<unsigned char>(ch) < 0x20 || ch == 0x7f) ch = ' ';
  return name;
}

std::string valid_utf8(const std::string& text) {
  std::string out;
  out.reserve(text.size());
  const auto byte = [&](std::size_t i) { return static_cast<unsigned char>(text[i]); };
  for (std::size_t i = 0; i < text.size();) {
    const unsigned char b = byte(i);
    std::size_t n = 0;  // continuation bytes the lead byte announces
    unsigned lo = 0x80, hi = 0xBF;  // the range the first continuation byte must lie in (RFC 3629's table)
    if (b < 0x80) n = 0;
    else if (b >= 0xC2 && b <= 0xDF) n = 1;
    else if (b == 0xE0) n = 2, lo = 0xA0;
    else if (b >= 0xE1 && b <= 0xEC) n = 2;
    else if (b == 0xED) n = 2, hi = 0x9F;  // no surrogates
    else if (b >= 0xEE && b <= 0xEF) n = 2;
    else if (b == 0xF0) n = 3, lo = 0x90;
    else if (b >= 0xF1 && b <= 0xF3) n = 3;
    else if (b == 0xF4) n = 3, hi = 0x8F;  // up to U+10FFFF
    else n = std::string::npos;
    bool ok = n != std::string::npos && i + n < text.size();  // the sequence's last byte is in the text
    for (std::size_t k = 1; ok && k <= n; ++k) {
      const unsigned char c = byte(i + k);
      ok = k == 1 ? c >= lo && c <= hi : c >= 0x80 && c <= 0xBF;
    }
    if (!ok) {
      out += "\xEF\xBF\xBD";  // U+FFFD, for this one byte; the next is looked at afresh
      ++i;
      continue;
    }
    out.append(text, i, n + 1);
    i += n + 1;
  }
  return out;
}

}  // namespace rollsim
