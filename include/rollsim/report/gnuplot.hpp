// Figures through gnuplot (Debian's gnuplot-nox): finding it, quoting for its scripts, running a script.
#pragma once

#include <string>

namespace rollsim::report {

/// Full path of the gnuplot executable on PATH, or "" when it is not installed.
std::string find_gnuplot();

/// Any text (a tyre's name, a path, a caption) as a gnuplot string literal, quotes included: single quotes,
/// in which gnuplot expands nothing (no backquote commands, no macros, no backslash escapes), with a quote
/// doubled and line breaks and other control characters turned into spaces (a line break would end the
/// command and start a new one). Every label, title, key entry and file name in a script goes through this.
std::string gnuplot_string(const std::string& text);

/// The script's first lines: `set terminal <terminal>` and enhanced text off, so that labels render as
/// written ("fuel_rate" without a subscript, "m/s^2" without a superscript).
std::string gnuplot_terminal(const std::string& terminal);

/// Runs `gnuplot script_path`; returns "" on success, else what gnuplot wrote to stderr (never throws).
std::string run_gnuplot_script(const std::string& gnuplot, const std::string& script_path);

}  // namespace rollsim::report
