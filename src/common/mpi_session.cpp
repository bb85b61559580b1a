// librollsim_mpi.so: MPI's world for a ProcessGroup (src/common/mpi_session.hpp); the only code that calls MPI.
#include "mpi_session.hpp"

#include <mpi.h>

#include <algorithm>
#include <climits>
#include <stdexcept>

namespace rollsim {
namespace {

class OpenMpiSession final : public MpiSession {
 public:
  OpenMpiSession(int* argc, char*** argv) {
    int provided = 0;
    // Only the main thread calls MPI; the cases' worker threads do not.
    MPI_Init_thread(argc, argv, MPI_THREAD_FUNNELED, &provided);
    MPI_Comm_rank(MPI_COMM_WORLD, &rank);
    MPI_Comm_size(MPI_COMM_WORLD, &size);
    MPI_Comm node;
    MPI_Comm_split_type(MPI_COMM_WORLD, MPI_COMM_TYPE_SHARED, rank, MPI_INFO_NULL, &node);
    MPI_Comm_size(node, &ranks_on_node);
    MPI_Comm_free(&node);
  }
  ~OpenMpiSession() override { MPI_Finalize(); }

  std::vector<std::string> all_gather(const std::string& mine) const override {
    std::vector<long long> sizes(static_cast<std::size_t>(size));
    long long my_size = static_cast<long long>(mine.size());
    MPI_Allgather(&my_size, 1, MPI_LONG_LONG, sizes.data(), 1, MPI_LONG_LONG, MPI_COMM_WORLD);
    std::vector<int> counts, offsets;
    long long total = 0;
    for (long long s : sizes) {
      offsets.push_back(static_cast<int>(std::min<long long>(total, INT_MAX)));
      counts.push_back(static_cast<int>(std::min<long long>(s, INT_MAX)));
      total += s;
    }
    // Every rank sees the same sizes, so every rank throws here alike (MPI counts are ints).
    if (total > INT_MAX) {
      throw std::runtime_error("the gathered results (" + std::to_string(total) +
                               " bytes) exceed MPI's 2 GiB message limit: split the run into smaller ones");
    }
    std::string all(static_cast<std::size_t>(total), '\0');
    MPI_Allgatherv(mine.data(), counts[static_cast<std::size_t>(rank)], MPI_CHAR, all.data(), counts.data(),
                   offsets.data(), MPI_CHAR, MPI_COMM_WORLD);
    std::vector<std::string> out;
    for (std::size_t q = 0; q < sizes.size(); ++q) out.push_back(all.substr(static_cast<std::size_t>(offsets[q]), static_cast<std::size_t>(counts[q])));
    return out;
  }
};

}  // namespace
}  // namespace rollsim

extern "C" rollsim::MpiSession* rollsim_mpi_start(int* argc, char*** argv) { return new rollsim::OpenMpiSession(argc, argv); }
