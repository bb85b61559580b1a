// Progress display shared by the tyre-selection commands (compare, sweep, sensitivity, regress).
#pragma once

#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <iostream>
#include <mutex>
#include <string>

#include "rollsim/common/error.hpp"
#include "rollsim/common/yaml_reader.hpp"

namespace rollsim::cli {

/// Progress on stderr, only when stderr is a terminal (pipes and logs stay clean). Thread-safe.
class Progress {
 public:
  explicit Progress(bool wanted) : on_(wanted && isatty(STDERR_FILENO)) {}
  void operator()(std::size_t done, std::size_t total) {
    if (!on_) return;
    std::lock_guard<std::mutex> lock(m_);
    // At most one line per per-mille: a million-point tyre sweep must not spend its time printing.
    const std::size_t step = std::max<std::size_t>(1, total / 1000);
    if (done % step != 0 && done != total) return;
    std::fprintf(stderr, "\r%zu/%zu points", done, total);
    if (done == total) std::fprintf(stderr, "\n");
    std::fflush(stderr);
  }

 private:
  bool on_;
  std::mutex m_;
};

}  // namespace rollsim::cli
