// The part of ProcessGroup that both back-ends share (distribute_mpi.cpp, distribute_serial.cpp). It lives outside
// rollsim_lib, with the back-end, so that the library and the Python module never link MPI.
#include "rollsim/common/distribute.hpp"

namespace rollsim {

CaseMap ProcessGroup::mapper() const {
  return [this](std::size_t tasks, unsigned threads, const CaseBody& body, const CaseProgress& progress) {
    return map(tasks, threads, body, progress);
  };
}

}  // namespace rollsim
