// Figures through gnuplot (Debian's gnuplot-nox): finding it, quoting for its scripts, running a script.
#pragma once

#include <string>

namespace rollsim::report {

/// Full path of the gnuplot executable on PATH, or "" when it is not installed.
std::string find_gnuplot();

/// `text` escaped for a single-quoted gnuplot string (a quote is doubled).
std::string gnuplot_escape(const std::string& text);

/// Runs `gnuplot script_path`; returns "" on success, else what gnuplot wrote to stderr (never throws).
std::string run_gnuplot_script(const std::string& gnuplot, const std::string& script_path);

}  // namespace rollsim::report
