// The local half of case distribution (threads, failure agreement within a process), shared by the MPI build and
// the build without it.
#include "rollsim/common/distribute.hpp"

#include <atomic>
#include <cstdlib>
#include <limits>
#include <mutex>

#include "rollsim/common/error.hpp"
#include "rollsim/common/parallel.hpp"

namespace rollsim {

std::vector<CaseBytes> map_cases_locally(std::size_t tasks, unsigned threads, const CaseBody& body,
                                         const CaseProgress& progress) {
  std::vector<CaseBytes> out(tasks);
  std::atomic<std::size_t> done{0};
  std::mutex failure_mutex;
  std::size_t failed_case = std::numeric_limits<std::size_t>::max();
  std::string failure;
  bool bad_input = false;
  try {
    parallel_for(tasks, threads, [&](std::size_t k) {
      try {
        out[k] = body(k);
      } catch (const std::exception& e) {
        const std::lock_guard<std::mutex> lock(failure_mutex);
        // The lowest failing case, so the message does not depend on which thread got there first.
        if (k < failed_case) {
          failed_case = k;
          failure = e.what();
          bad_input = dynamic_cast<const InputError*>(&e) != nullptr;
        }
        throw;
      }
      const std::size_t n = ++done;
      if (progress) progress(n, tasks);
    });
  } catch (const std::exception&) {
    throw CaseFailure(failed_case,
                      "case " + std::to_string(failed_case + 1) + " of " + std::to_string(tasks) + " failed: " + failure,
                      failure, bad_input);
  }
  return out;
}

std::vector<CaseBytes> map_cases(const CaseMap& map, std::size_t tasks, unsigned threads, const CaseBody& body,
                                 const CaseProgress& progress) {
  return map ? map(tasks, threads, body, progress) : map_cases_locally(tasks, threads, body, progress);
}

bool launched_by_mpi() {
  // Open MPI's mpirun, then Slurm's srun with PMIx or PMI-2 (srun --mpi=pmix|pmi2).
  for (const char* v : {"OMPI_COMM_WORLD_SIZE", "PMIX_RANK", "PMI_SIZE"})
    if (std::getenv(v)) return true;
  return false;
}

}  // namespace rollsim
