// Test support: a per-test folder for input files, running the built rollsim binary with its streams captured, and
// reading what it writes.
#pragma once

#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

namespace rollsim::test {

struct CmdResult {
  int exit_code = -1;
  std::string out;
  std::string err;
};

inline std::string slurp(const std::filesystem::path& p) {
  std::ifstream in(p);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

/// A scratch folder for this test process (ctest -j runs several at once), removed when the process ends.
inline std::filesystem::path temp_dir() {
  struct Scratch {
    std::filesystem::path path =
        std::filesystem::temp_directory_path() / ("rollsim_cli_test_" + std::to_string(::getpid()));
    Scratch() { std::filesystem::create_directories(path); }
    ~Scratch() {
      std::error_code ec;
      std::filesystem::remove_all(path, ec);
    }
  };
  static const Scratch scratch;
  std::filesystem::create_directories(scratch.path);
  return scratch.path;
}

/// Runs `[env] rollsim <args>` through the shell from the source folder (args are shell words, quote as needed).
/// ROLLSIM_TEST_BINARY, when set, names another rollsim to run (to show that a new test fails on an old build).
inline CmdResult run_rollsim(const std::string& args, const std::string& env = "") {
  const char* other = std::getenv("ROLLSIM_TEST_BINARY");
  const std::string binary = other && *other ? other : ROLLSIM_BINARY;
  const auto dir = temp_dir();
  const auto out = dir / "stdout.txt";
  const auto err = dir / "stderr.txt";
  const std::string cmd = "cd '" + std::string(ROLLSIM_SOURCE_DIR) + "' && " + env + " '" + binary + "' " +
                          args + " >'" + out.string() + "' 2>'" + err.string() + "'";
  const int status = std::system(cmd.c_str());
  CmdResult r;
  r.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  r.out = slurp(out);
  r.err = slurp(err);
  return r;
}

/// A fixture with a fresh folder per test for small input files (bad-input cases), removed after the test.
class FileFixture : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = std::filesystem::temp_directory_path() /
           ("rollsim_" + std::string(::testing::UnitTest::GetInstance()->current_test_info()->name()) + "_" +
            std::to_string(::getpid()));
    std::filesystem::create_directories(dir_);
  }
  void TearDown() override { std::filesystem::remove_all(dir_); }
  /// Writes `text` to `name` in the test's folder and returns its path.
  std::string write(const std::string& name, const std::string& text) {
    const std::filesystem::path p = dir_ / name;
    std::ofstream(p) << text;
    return p.string();
  }
  std::filesystem::path dir_;
};

/// The number after `"key": ` in JSON as rollsim writes it (NaN where the key is absent).
inline double json_number(const std::string& json, const std::string& key) {
  const auto at = json.find("\"" + key + "\": ");
  if (at == std::string::npos) return std::nan("");
  return std::strtod(json.c_str() + at + key.size() + 4, nullptr);
}

/// The non-empty lines of `text`.
inline std::vector<std::string> lines(const std::string& text) {
  std::vector<std::string> out;
  std::istringstream in(text);
  for (std::string l; std::getline(in, l);)
    if (!l.empty()) out.push_back(l);
  return out;
}

}  // namespace rollsim::test
