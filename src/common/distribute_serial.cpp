// Case distribution in a build without MPI: one process, every case on its threads.
#include <cstdlib>
#include <string>

#include "rollsim/common/distribute.hpp"
#include "rollsim/common/error.hpp"

namespace rollsim {

ProcessGroup::ProcessGroup(int&, char**&) {
  // Started as one of several ranks, every copy would run every case and print it: refuse instead.
  for (const char* v : {"OMPI_COMM_WORLD_SIZE", "PMI_SIZE", "SLURM_NTASKS"}) {
    const char* n = std::getenv(v);
    if (launched_by_mpi() && n && std::atoi(n) > 1) {
      throw InputError("mpirun", std::string("this rollsim was built without MPI (ROLLSIM_WITH_MPI=OFF), so ") + v + "=" + n +
                                     " ranks would each run every case; run it as one process, or rebuild with MPI "
                                     "(Debian: libopenmpi-dev openmpi-bin)");
    }
  }
}
ProcessGroup::~ProcessGroup() = default;

std::vector<CaseBytes> ProcessGroup::map(std::size_t tasks, unsigned threads, const CaseBody& body,
                                         const CaseProgress& progress) const {
  return map_cases_locally(tasks, threads, body, progress);
}

}  // namespace rollsim
