// Case distribution over MPI ranks: cyclic split, every rank's results all-gathered in case order, and failures
// agreed collectively so that every rank ends with the same error instead of waiting on a dead peer.
#include <mpi.h>

#include <algorithm>
#include <climits>
#include <limits>
#include <thread>

#include "rollsim/common/distribute.hpp"

namespace rollsim {

ProcessGroup::ProcessGroup(int& argc, char**& argv) {
  // A plain `rollsim` run never starts MPI: no launcher, no start-up cost, and no MPI needed at run time.
  if (!launched_by_mpi()) return;
  int provided = 0;
  // Only the main thread calls MPI; the cases' worker threads do not.
  MPI_Init_thread(&argc, &argv, MPI_THREAD_FUNNELED, &provided);
  mpi_ = true;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank_);
  MPI_Comm_size(MPI_COMM_WORLD, &size_);
  MPI_Comm node;
  MPI_Comm_split_type(MPI_COMM_WORLD, MPI_COMM_TYPE_SHARED, rank_, MPI_INFO_NULL, &node);
  MPI_Comm_size(node, &ranks_on_node_);
  MPI_Comm_free(&node);
}

ProcessGroup::~ProcessGroup() {
  if (mpi_) MPI_Finalize();
}

namespace {

// This rank's results (status 0, then each case's bytes) or its lowest failure (status 1, case, message).
std::string local_blob(std::size_t tasks, unsigned threads, int rank, int size, const CaseBody& body,
                       const CaseProgress& progress) {
  const auto r = static_cast<std::size_t>(rank), n = static_cast<std::size_t>(size);
  const std::size_t mine = tasks > r ? (tasks - 1 - r) / n + 1 : 0;
  // Local case j is case r + j n: the lowest failing j is this rank's lowest failing case.
  const auto global_body = [&](std::size_t j) { return body(r + j * n); };
  // Rank 0's share stands for the whole run's progress: the shares are equal to one case.
  CaseProgress share_progress;
  if (progress) share_progress = [&](std::size_t d, std::size_t t) { progress(std::min(tasks, d * tasks / t), tasks); };
  std::string blob(1, '\0');
  try {
    for (auto& bytes : map_cases_locally(mine, threads, global_body, share_progress)) put(blob, bytes);
  } catch (const CaseFailure& e) {
    blob.assign(1, '\1');
    put(blob, r + e.case_index() * n);
    put(blob, e.reason());
  }
  return blob;
}

}  // namespace

std::vector<CaseBytes> ProcessGroup::map(std::size_t tasks, unsigned threads, const CaseBody& body,
                                         const CaseProgress& progress) const {
  if (!mpi_ || size_ == 1) return map_cases_locally(tasks, threads, body, progress);
  if (threads == 0) threads = std::max(1u, std::thread::hardware_concurrency() / static_cast<unsigned>(ranks_on_node_));
  const std::string blob = local_blob(tasks, threads, rank_, size_, body, is_root() ? progress : CaseProgress{});

  std::vector<long long> sizes(static_cast<std::size_t>(size_));
  long long mine = static_cast<long long>(blob.size());
  MPI_Allgather(&mine, 1, MPI_LONG_LONG, sizes.data(), 1, MPI_LONG_LONG, MPI_COMM_WORLD);
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
  MPI_Allgatherv(blob.data(), counts[static_cast<std::size_t>(rank_)], MPI_CHAR, all.data(), counts.data(),
                 offsets.data(), MPI_CHAR, MPI_COMM_WORLD);

  std::vector<CaseBytes> out(tasks);
  std::size_t failed = std::numeric_limits<std::size_t>::max();
  std::string why;
  for (int q = 0; q < size_; ++q) {
    std::string_view in(all.data() + offsets[static_cast<std::size_t>(q)], static_cast<std::size_t>(counts[static_cast<std::size_t>(q)]));
    const char status = in.front();
    in.remove_prefix(1);
    if (status != 0) {
      std::size_t k = 0;
      std::string w;
      take(in, k);
      take(in, w);
      if (k < failed) {
        failed = k;
        why = w;
      }
      continue;
    }
    for (std::size_t k = static_cast<std::size_t>(q); k < tasks; k += static_cast<std::size_t>(size_)) take(in, out[k]);
  }
  if (failed != std::numeric_limits<std::size_t>::max()) {
    throw CaseFailure(failed,
                      "case " + std::to_string(failed + 1) + " of " + std::to_string(tasks) + " failed (rank " +
                          std::to_string(failed % static_cast<std::size_t>(size_)) + "): " + why,
                      why);
  }
  return out;
}

}  // namespace rollsim
