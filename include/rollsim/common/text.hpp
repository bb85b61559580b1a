// Names read from files: compared without regard to case (column names, cycle names, makes and models), and made
// valid UTF-8 before they are written into JSON, HTML, SVG or CSV.
#pragma once

#include <string>

namespace rollsim {

/// `text` with its ASCII letters lower-cased; other bytes (UTF-8 included) unchanged.
std::string lower_ascii(std::string text);

/// `text` with every byte that does not belong to a well-formed UTF-8 sequence (a stray continuation byte, a
/// truncated or overlong sequence, a surrogate, beyond U+10FFFF) replaced by U+FFFD. A name read from a file as
/// bytes (a Latin-1 tyre name, a path) made every JSON output unreadable to a strict parser.
std::string valid_utf8(const std::string& text);

/// A name as a label: its control characters (line breaks, terminal escape sequences) as spaces. A tyre named with
/// ESC [2J cleared the terminal of whoever printed its table (session 21).
std::string display_name(std::string name);

}  // namespace rollsim
