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
#include "rollsim/vehicle/vehicle.hpp"

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

/// A car whose road load is its coast-down curve takes no rolling resistance from its tyres, only their gearing: a
/// tyre's figures for it say so, or a pressure elasticity of -0.009 on fuel beside -0.36 on the tyre's own power reads
/// as "pressure barely matters" (session 27's outside tester; `compare` refuses such a car).
inline void warn_if_coastdown(const Vehicle& v, const std::string& what) {
  if (!v.coastdown) return;
  std::cerr << "warning: " << v.source << ": this car's road load is its coast-down curve (coastdown: A, B, C), which "
            << "holds its tyres' rolling resistance at the tested tyres': a tyre changes only its gearing here, so "
            << what << " carry no rolling resistance of the tyre (give the car a body with tyres and no coastdown block "
               "to see it)\n";
}

}  // namespace rollsim::cli
