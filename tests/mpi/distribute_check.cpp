// Run under mpirun: the distributed map returns every case in order on every rank, and a case failing on one rank
// ends every rank with the same CaseFailure (no rank left waiting). Exit 0 when every check holds on this rank.
#include <cstdio>
#include <stdexcept>
#include <string>

#include "rollsim/common/distribute.hpp"

int main(int argc, char** argv) {
  const rollsim::ProcessGroup group(argc, argv);
  int failures = 0;
  auto check = [&](bool ok, const std::string& what) {
    if (!ok) std::fprintf(stderr, "rank %d: FAILED: %s\n", group.rank(), what.c_str());
    failures += ok ? 0 : 1;
  };
  check(rollsim::launched_by_mpi() && group.size() >= 2, "runs under an MPI launcher with at least 2 ranks");
  for (std::size_t tasks : {0u, 1u, 7u, 100u}) {
    const auto out = group.map(tasks, 2, [](std::size_t k) { return std::to_string(k * 3) + std::string(k % 5, 'x'); }, {});
    bool ordered = out.size() == tasks;
    for (std::size_t k = 0; ordered && k < tasks; ++k) ordered = out[k] == std::to_string(k * 3) + std::string(k % 5, 'x');
    check(ordered, "every case of " + std::to_string(tasks) + " in case order");
  }
  // Case 3 runs on rank 3 % size; 5 fails too, later, so the reported case must be the lowest.
  try {
    group.map(12, 1, [](std::size_t k) -> std::string {
      if (k == 3 || k == 5) throw std::runtime_error("no solution at point " + std::to_string(k));
      return "ok";
    }, {});
    check(false, "a failing case is reported");
  } catch (const rollsim::CaseFailure& e) {
    check(e.case_index() == 3, "the lowest failing case (3) is named, got " + std::to_string(e.case_index()));
    check(std::string(e.what()).find("no solution at point 3") != std::string::npos, std::string("message: ") + e.what());
  }
  if (group.is_root() && failures == 0) std::printf("distribute_check: %d ranks ok\n", group.size());
  return failures == 0 ? 0 : 1;
}
