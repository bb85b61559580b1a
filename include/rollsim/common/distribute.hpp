// Spreads an indexed list of independent cases over processes (MPI ranks) and their threads, results in case order.
#pragma once

#include <cstddef>
#include <cstring>
#include <functional>
#include <memory>
#include <stdexcept>
#include <string>
#include <string_view>
#include <type_traits>
#include <vector>

namespace rollsim {

/// One case's result as plain bytes (the caller serialises it with put/take below, or as its output row).
using CaseBytes = std::string;
using CaseBody = std::function<CaseBytes(std::size_t)>;
/// (cases done, cases in all); called on the process that prints (rank 0) only.
using CaseProgress = std::function<void(std::size_t, std::size_t)>;

/// How a library loop runs its cases: body(k) for every k in [0, tasks), `threads` threads per process (0: the
/// process's share of the cores), every result returned in case order on every process. A library takes one of
/// these from its caller, so it never sees MPI; an empty CaseMap means map_cases_locally.
using CaseMap =
    std::function<std::vector<CaseBytes>(std::size_t tasks, unsigned threads, const CaseBody& body, const CaseProgress& progress)>;

/// A case whose body threw: every process throws the same one (the lowest failing case), so all of them end.
class CaseFailure : public std::runtime_error {
 public:
  CaseFailure(std::size_t case_index, const std::string& what, const std::string& reason, bool bad_input = false)
      : std::runtime_error(what), case_index_(case_index), reason_(reason), bad_input_(bad_input) {}
  std::size_t case_index() const { return case_index_; }
  const std::string& reason() const { return reason_; }  ///< the body's own message
  /// The body threw an InputError: the case met bad input (a manifest's file, a column), which the program reports
  /// as bad input, its own message alone, rather than as a case that failed to compute.
  bool bad_input() const { return bad_input_; }

 private:
  std::size_t case_index_;
  std::string reason_;
  bool bad_input_;
};

/// The map on this process alone (parallel_for over its threads).
std::vector<CaseBytes> map_cases_locally(std::size_t tasks, unsigned threads, const CaseBody& body,
                                         const CaseProgress& progress);

/// `map` if set, map_cases_locally otherwise.
std::vector<CaseBytes> map_cases(const CaseMap& map, std::size_t tasks, unsigned threads, const CaseBody& body,
                                 const CaseProgress& progress);

class MpiSession;  // src/common/mpi_session.hpp: loaded only under a launcher

/// The processes of one run: MPI's world when rollsim was built with MPI and launched by mpirun or srun, else this
/// process alone. Made once in main (it starts and ends MPI); not copyable.
class ProcessGroup {
 public:
  ProcessGroup(int& argc, char**& argv);
  ~ProcessGroup();
  ProcessGroup(const ProcessGroup&) = delete;
  ProcessGroup& operator=(const ProcessGroup&) = delete;

  int rank() const { return rank_; }
  int size() const { return size_; }
  bool is_root() const { return rank_ == 0; }  ///< the one process that prints and writes files
  /// Case k runs on rank k % size (cyclic, so uneven case costs balance); results are gathered to every rank.
  std::vector<CaseBytes> map(std::size_t tasks, unsigned threads, const CaseBody& body, const CaseProgress& progress) const;
  CaseMap mapper() const;

 private:
  int rank_ = 0;
  int size_ = 1;
  int ranks_on_node_ = 1;  ///< threads default to this node's cores over its ranks
  std::unique_ptr<MpiSession> mpi_;  ///< set when a launcher started this process
};

/// True when the environment says an MPI launcher (mpirun, srun) started this process.
bool launched_by_mpi();

// Plain serialisation of results for gathering: trivially copyable values as their bytes, strings length-prefixed.
template <class T>
void put(std::string& out, const T& v) {
  static_assert(std::is_trivially_copyable_v<T>);
  out.append(reinterpret_cast<const char*>(&v), sizeof v);
}
inline void put(std::string& out, const std::string& s) {
  put(out, s.size());
  out += s;
}
template <class T>
void put(std::string& out, const std::vector<T>& v) {
  put(out, v.size());
  for (const auto& x : v) put(out, x);
}

template <class T>
void take(std::string_view& in, T& v) {
  static_assert(std::is_trivially_copyable_v<T>);
  if (in.size() < sizeof v) throw std::logic_error("take: gathered case result is truncated");
  std::memcpy(&v, in.data(), sizeof v);
  in.remove_prefix(sizeof v);
}
inline void take(std::string_view& in, std::string& s) {
  std::size_t n = 0;
  take(in, n);
  if (in.size() < n) throw std::logic_error("take: gathered case result is truncated");
  s.assign(in.data(), n);
  in.remove_prefix(n);
}
template <class T>
void take(std::string_view& in, std::vector<T>& v) {
  std::size_t n = 0;
  take(in, n);
  if (n > in.size()) throw std::logic_error("take: gathered case result is truncated");
  v.assign(n, T{});
  for (auto& x : v) take(in, x);
}

}  // namespace rollsim
