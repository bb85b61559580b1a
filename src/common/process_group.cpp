// The processes of a run: this process alone, or MPI's world when a launcher started it. MPI itself lives in a
// module loaded only then (mpi_session.hpp), and this file lives outside rollsim_lib, so that the library, the
// Python module and a plain CLI run never load Open MPI.
#include <dlfcn.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <limits>
#include <string>
#include <thread>

#include "mpi_session.hpp"
#include "rollsim/common/distribute.hpp"
#include "rollsim/common/error.hpp"

namespace rollsim {
namespace {

// Beside the program (the build tree), else where `cmake --install` puts it (PREFIX/lib/rollsim).
std::filesystem::path mpi_module_path() {
  std::error_code ec;
  const std::filesystem::path dir = std::filesystem::read_symlink("/proc/self/exe", ec).parent_path();
  const std::filesystem::path beside = dir / ROLLSIM_MPI_MODULE, installed = dir.parent_path() / "lib" / "rollsim" / ROLLSIM_MPI_MODULE;
  for (const auto& p : {beside, installed})
    if (std::filesystem::exists(p, ec)) return p;
  throw InputError("mpirun", std::string("this rollsim's MPI module (") + ROLLSIM_MPI_MODULE + ") is neither at " + beside.string() +
                                 " nor at " + installed.string() + "; rebuild rollsim with MPI (Debian: libopenmpi-dev "
                                 "openmpi-bin) or run it as one process");
}

MpiSession* start_mpi(int& argc, char**& argv) {
  const std::filesystem::path path = mpi_module_path();
  // Global: Open MPI's own components resolve their symbols against the libraries this brings in.
  void* handle = dlopen(path.c_str(), RTLD_NOW | RTLD_GLOBAL);
  if (!handle) throw InputError(path.string(), std::string("cannot be loaded: ") + dlerror());
  // Never dlclose'd: Open MPI does not support being unloaded.
  const auto start = reinterpret_cast<RollsimMpiStart>(dlsym(handle, "rollsim_mpi_start"));
  if (!start) throw InputError(path.string(), "has no rollsim_mpi_start: not rollsim's MPI module");
  return start(&argc, &argv);
}

// Started as one of several ranks, every copy would run every case and print it: refuse instead.
void refuse_ranks_without_mpi() {
  for (const char* v : {"OMPI_COMM_WORLD_SIZE", "PMI_SIZE", "SLURM_NTASKS"}) {
    const char* n = std::getenv(v);
    if (n && std::atoi(n) > 1) {
      throw InputError("mpirun", std::string("this rollsim was built without MPI (ROLLSIM_WITH_MPI=OFF), so ") + v + "=" + n +
                                     " ranks would each run every case; run it as one process, or rebuild with MPI "
                                     "(Debian: libopenmpi-dev openmpi-bin)");
    }
  }
}

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
    put(blob, e.bad_input());
  }
  return blob;
}

}  // namespace

ProcessGroup::ProcessGroup(int& argc, char**& argv) {
  // A plain `rollsim` run never starts MPI: no launcher, no start-up cost, and no MPI needed at run time.
  if (!launched_by_mpi()) return;
  if (!ROLLSIM_WITH_MPI) {
    refuse_ranks_without_mpi();
    return;
  }
  mpi_.reset(start_mpi(argc, argv));
  rank_ = mpi_->rank;
  size_ = mpi_->size;
  ranks_on_node_ = mpi_->ranks_on_node;
}

ProcessGroup::~ProcessGroup() = default;

std::vector<CaseBytes> ProcessGroup::map(std::size_t tasks, unsigned threads, const CaseBody& body,
                                         const CaseProgress& progress) const {
  if (!mpi_ || size_ == 1) return map_cases_locally(tasks, threads, body, progress);
  if (threads == 0) threads = std::max(1u, std::thread::hardware_concurrency() / static_cast<unsigned>(ranks_on_node_));
  const std::vector<std::string> blobs =
      mpi_->all_gather(local_blob(tasks, threads, rank_, size_, body, is_root() ? progress : CaseProgress{}));
  std::vector<CaseBytes> out(tasks);
  std::size_t failed = std::numeric_limits<std::size_t>::max();
  std::string why;
  bool bad_input = false;
  for (std::size_t q = 0; q < blobs.size(); ++q) {
    std::string_view in(blobs[q]);
    const char status = in.front();
    in.remove_prefix(1);
    if (status != 0) {
      std::size_t k = 0;
      std::string w;
      bool input = false;
      take(in, k);
      take(in, w);
      take(in, input);
      if (k < failed) {
        failed = k;
        why = w;
        bad_input = input;
      }
      continue;
    }
    for (std::size_t k = q; k < tasks; k += blobs.size()) take(in, out[k]);
  }
  if (failed != std::numeric_limits<std::size_t>::max()) {
    throw CaseFailure(failed,
                      "case " + std::to_string(failed + 1) + " of " + std::to_string(tasks) + " failed (rank " +
                          std::to_string(failed % static_cast<std::size_t>(size_)) + "): " + why,
                      why, bad_input);
  }
  return out;
}

CaseMap ProcessGroup::mapper() const {
  return [this](std::size_t tasks, unsigned threads, const CaseBody& body, const CaseProgress& progress) {
    return map(tasks, threads, body, progress);
  };
}

}  // namespace rollsim
