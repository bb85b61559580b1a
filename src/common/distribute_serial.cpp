// Case distribution in a build without MPI: one process, every case on its threads.
#include "rollsim/common/distribute.hpp"

namespace rollsim {

ProcessGroup::ProcessGroup(int&, char**&) {}
ProcessGroup::~ProcessGroup() = default;

std::vector<CaseBytes> ProcessGroup::map(std::size_t tasks, unsigned threads, const CaseBody& body,
                                         const CaseProgress& progress) const {
  return map_cases_locally(tasks, threads, body, progress);
}

}  // namespace rollsim
