// The few MPI calls a ProcessGroup needs, behind one C entry point: the programs load Open MPI (a module,
// librollsim_mpi.so) only when a launcher started them, so a plain run never pays for loading it.
#pragma once

#include <string>
#include <vector>

namespace rollsim {

/// MPI's world, started by rollsim_mpi_start and finalised by the destructor.
class MpiSession {
 public:
  virtual ~MpiSession() = default;
  int rank = 0;
  int size = 1;
  int ranks_on_node = 1;  ///< ranks sharing this node's cores
  /// Every rank's bytes in rank order, on every rank (a collective: every rank calls it). Throws std::runtime_error,
  /// on every rank alike, when the total exceeds MPI's int counts.
  virtual std::vector<std::string> all_gather(const std::string& mine) const = 0;
};

}  // namespace rollsim

/// The module's one exported symbol: MPI_Init_thread (funneled) and the world's shape; the caller owns the result.
extern "C" rollsim::MpiSession* rollsim_mpi_start(int* argc, char*** argv);
using RollsimMpiStart = rollsim::MpiSession* (*)(int*, char***);
