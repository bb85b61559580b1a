#include "rollsim/report/gnuplot.hpp"

#include <unistd.h>

#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>

#include "rollsim/common/text.hpp"

namespace rollsim::report {
namespace {

// POSIX single quotes: the only character to escape is the quote itself.
std::string shell_quote(const std::string& s) {
  std::string o = "'";
  for (char c : s) o += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return o + "'";
}

}  // namespace

ScratchDir::ScratchDir(const std::string& prefix) {
  std::string pattern = (std::filesystem::temp_directory_path() / (prefix + "XXXXXX")).string();
  if (mkdtemp(pattern.data()) == nullptr) {
    throw std::runtime_error("cannot make a scratch folder for gnuplot under " +
                             std::filesystem::temp_directory_path().string() + ": " + std::strerror(errno));
  }
  path_ = pattern;
}

ScratchDir::~ScratchDir() {
  std::error_code ec;
  std::filesystem::remove_all(path_, ec);
}

std::string find_gnuplot() {
  const char* path = std::getenv("PATH");
  std::stringstream ss(path ? path : "");
  for (std::string dir; std::getline(ss, dir, ':');) {
    const std::string p = (dir.empty() ? "." : dir) + "/gnuplot";
    if (access(p.c_str(), X_OK) == 0) return p;
  }
  return "";
}

std::string gnuplot_string(const std::string& given) {
  // Valid UTF-8 (the SVG is XML; a stray byte made it ill-formed), and no "]]>", which XML text may not hold and
  // gnuplot's SVG terminal writes as it is (session 21's outside testing).
  std::string text = valid_utf8(given);
  for (std::size_t at = text.find("]]>"); at != std::string::npos; at = text.find("]]>", at)) text.insert(at + 2, " ");
  // gnuplot reads a string that opens with a doubled quote ('''93 Winter') as an empty string and then a stray
  // token, so a leading quote is a double-quoted "'" joined on with gnuplot's string operator '.' (a double-quoted
  // string holding only a quote expands nothing).
  const bool leading_quote = !text.empty() && text.front() == '\'';
  std::string o = leading_quote ? "\"'\" . '" : "'";
  for (std::size_t i = leading_quote ? 1 : 0; i < text.size(); ++i) {
    const char c = text[i];
    const auto u = static_cast<unsigned char>(c);
    if (c == '\'') o += "''";
    else if (u < 0x20 || u == 0x7f) o += ' ';
    else o += c;
  }
  return o + "'";
}

std::string gnuplot_terminal(const std::string& terminal) {
  return "set terminal " + terminal + "\nset termoption noenhanced\n";
}

std::string run_gnuplot_script(const std::string& gnuplot, const std::string& script_path) {
  const std::string err_path = script_path + ".err";
  const std::string cmd = shell_quote(gnuplot) + " " + shell_quote(script_path) + " 2>" + shell_quote(err_path);
  const int status = std::system(cmd.c_str());
  std::string err;
  if (status != 0) {
    std::ifstream in(err_path);
    std::stringstream text;
    text << in.rdbuf();
    err = text.str().empty() ? "exit status " + std::to_string(status) : text.str();
  }
  std::error_code ec;
  std::filesystem::remove(err_path, ec);
  return err;
}

}  // namespace rollsim::report
