// Figures through gnuplot (Debian's gnuplot-nox): finding it, quoting for its scripts, running a script.
#pragma once

#include <filesystem>
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

/// A folder of its own for a gnuplot run's script, data and figure: made new by mkdtemp (mode 0700, a random name
/// under TMPDIR) and removed with what is in it when the object goes. A folder named by the process id, reused when
/// it existed, let another local user plant links in it, or swap the script between writing and running (session
/// 21's outside testing). Throws std::runtime_error when no folder can be made.
class ScratchDir {
 public:
  explicit ScratchDir(const std::string& prefix);
  ~ScratchDir();
  ScratchDir(const ScratchDir&) = delete;
  ScratchDir& operator=(const ScratchDir&) = delete;
  const std::filesystem::path& path() const { return path_; }

 private:
  std::filesystem::path path_;
};

/// Runs `gnuplot script_path`; returns "" on success, else what gnuplot wrote to stderr (never throws).
std::string run_gnuplot_script(const std::string& gnuplot, const std::string& script_path);

}  // namespace rollsim::report
