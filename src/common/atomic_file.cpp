#include "rollsim/common/atomic_file.hpp"

#include <pthread.h>
#include <unistd.h>

#include <csignal>
#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "rollsim/common/error.hpp"

namespace rollsim {
namespace {

namespace fs = std::filesystem;

std::string where(const std::string& option, const std::string& path) { return option + " '" + path + "'"; }

fs::path folder_of(const std::string& path) {
  const fs::path p(path);
  return p.has_parent_path() ? p.parent_path() : fs::path(".");
}

// A folder a file can be made in. access() answers from the permission bits, which root passes everywhere: /proc and
// /sys (or a read-only mount) passed the check and the write failed after the whole computation (a diagnosis run in
// full, then "cannot write there": session 25's outside testing). So a file is made there and removed at once.
bool writable_dir(const fs::path& dir) {
  std::error_code ec;
  if (!fs::is_directory(dir, ec) || ::access(dir.c_str(), W_OK | X_OK) != 0) return false;
  std::string probe = (dir / ".rollsim-probe-XXXXXX").string();
  const int fd = ::mkstemp(probe.data());
  if (fd < 0) return false;
  ::close(fd);
  ::unlink(probe.c_str());
  return true;
}

// Where an output's content lands. A symlink is followed (through a chain, to a file that may not exist yet): its
// target is replaced and the link stays a link. A device, pipe or socket, and a descriptor's alias (/dev/stdout,
// /dev/fd/N, /proc/self/fd/N), is written in place (appended), since a rename would replace the node itself with a
// plain file; a regular file elsewhere under /dev or /proc (/dev/shm) is replaced like any other.
struct Destination {
  fs::path path;
  bool in_place = false;
};

bool descriptor_alias(const fs::path& p) {
  std::error_code ec;
  const std::string a = fs::absolute(p, ec).lexically_normal().string();
  if (a == "/dev/stdout" || a == "/dev/stderr" || a.rfind("/dev/fd/", 0) == 0) return true;
  return a.rfind("/proc/", 0) == 0 && a.find("/fd/") != std::string::npos;
}

Destination destination_of(const std::string& path) {
  std::error_code ec;
  const fs::file_status target = fs::status(path, ec);  // follows symlinks
  if (fs::exists(target) && !fs::is_regular_file(target)) return {path, true};
  fs::path p = path;
  for (int hop = 0; hop < 40; ++hop) {  // a symlink chain, as the system follows one
    if (descriptor_alias(p)) return {path, true};
    if (!fs::is_symlink(fs::symlink_status(p, ec))) return {p, false};
    const fs::path named = fs::read_symlink(p, ec);
    if (ec) return {p, false};
    p = named.is_absolute() ? named : folder_of(p.string()) / named;
  }
  return {p, false};
}

// One file under two names (either may not exist yet): both made absolute first, since weakly_canonical leaves a
// path relative when none of it exists.
bool same_file(const fs::path& a, const fs::path& b) {
  std::error_code ec;
  if (fs::equivalent(a, b, ec)) return true;
  const fs::path ca = fs::weakly_canonical(fs::absolute(a, ec), ec);
  if (ec) return false;
  const fs::path cb = fs::weakly_canonical(fs::absolute(b, ec), ec);
  return !ec && ca == cb;
}

// The temporary sits in the target's folder so that the rename cannot cross file systems.
fs::path temporary_for(const fs::path& target) {
  // Appended, not "." + string&&: GCC 12 warns falsely (-Wrestrict) on the latter once it is inlined.
  std::string name = ".";
  name += target.filename().string();
  name += ".tmp" + std::to_string(::getpid());
  return folder_of(target.string()) / name;
}

// The signals that end a run from outside (Ctrl-C, kill, a closed terminal) are held while the outputs are written, so
// that one arriving mid-write cannot leave a temporary behind (a SIGTERM during the write did: session 24's note).
// Held, not handled: a handler would need the temporaries' names in a global. Only this thread's mask changes; the
// threads a command starts are joined before it writes.
class TerminationSignalsHeld {
 public:
  TerminationSignalsHeld() {
    sigemptyset(&held_);
    for (int s : kSignals) sigaddset(&held_, s);
    pthread_sigmask(SIG_BLOCK, &held_, &before_);
  }
  ~TerminationSignalsHeld() { pthread_sigmask(SIG_SETMASK, &before_, nullptr); }
  TerminationSignalsHeld(const TerminationSignalsHeld&) = delete;
  TerminationSignalsHeld& operator=(const TerminationSignalsHeld&) = delete;

  // Whether a held signal would stop the run once let through: one that is ignored (nohup's SIGHUP) would not.
  [[nodiscard]] bool stop_requested() const {
    sigset_t pending;
    if (sigpending(&pending) != 0) return false;
    for (int s : kSignals) {
      if (sigismember(&held_, s) != 1 || sigismember(&before_, s) == 1 || sigismember(&pending, s) != 1) continue;
      struct sigaction now {};
      if (sigaction(s, nullptr, &now) == 0 && now.sa_handler != SIG_IGN) return true;
    }
    return false;
  }

 private:
  static constexpr int kSignals[] = {SIGINT, SIGTERM, SIGHUP, SIGQUIT};
  sigset_t held_{};
  sigset_t before_{};
};

}  // namespace

void check_not_an_input(const std::string& path, const std::string& option, const std::vector<std::string>& inputs) {
  std::error_code ec;
  for (const auto& in : inputs) {
    if (!in.empty() && fs::equivalent(path, in, ec)) {
      throw InputError(where(option, path), "is the same file as the input '" + in +
                                                "', which writing it would destroy; give another file name");
    }
  }
}

void check_output_file(const std::string& path, const std::string& option, const std::vector<std::string>& inputs) {
  std::error_code ec;
  if (path.empty()) throw InputError(option, "an empty file name");
  if (fs::is_directory(path, ec)) throw InputError(where(option, path), "is a folder; give a file name");
  check_not_an_input(path, option, inputs);
  const Destination d = destination_of(path);
  if (d.in_place) {
    if (::access(d.path.c_str(), W_OK) != 0) throw InputError(where(option, path), "cannot write there: " + std::string(std::strerror(errno)));
    return;
  }
  const fs::path folder = folder_of(d.path.string());
  if (!fs::exists(folder, ec))
    throw InputError(where(option, path), "cannot write there: folder '" + folder.string() + "' does not exist");
  if (!writable_dir(folder))
    throw InputError(where(option, path), "cannot write there: folder '" + folder.string() + "' is not a writable folder");
}

void check_outputs_distinct(const std::vector<std::pair<std::string, std::string>>& path_and_option) {
  for (std::size_t j = 0; j < path_and_option.size(); ++j) {
    for (std::size_t i = 0; i < j; ++i) {
      const auto& [a, a_option] = path_and_option[i];
      const auto& [b, b_option] = path_and_option[j];
      if (!a.empty() && !b.empty() && same_file(destination_of(a).path, destination_of(b).path)) {
        throw InputError(where(b_option, b), "is the same file as " + where(a_option, a) + "; give each output its own file");
      }
    }
  }
}

void check_output_dir(const std::string& dir, const std::string& option) {
  std::error_code ec;
  fs::path p = fs::absolute(fs::path(dir), ec);
  if (fs::exists(p, ec)) {
    if (!writable_dir(p)) throw InputError(where(option, dir), "is not a writable folder");
    return;
  }
  // The folder itself is made, in a folder that exists, as every other output's file is: a mistyped parent made a
  // tree of folders where --json and --output refuse (session 27's outside tester).
  const fs::path parent = p.parent_path();
  if (!fs::exists(parent, ec))
    throw InputError(where(option, dir), "cannot be created: folder '" + parent.string() + "' does not exist");
  if (!writable_dir(parent)) throw InputError(where(option, dir), "cannot be created: '" + parent.string() + "' is not a writable folder");
}

void write_files_atomically(const std::vector<OutputFile>& files) {
  std::vector<std::pair<std::string, std::string>> named;
  for (const auto& f : files) named.emplace_back(f.path, f.option);
  check_outputs_distinct(named);
  std::vector<Destination> dest;
  for (const auto& f : files) dest.push_back(destination_of(f.path));
  std::vector<fs::path> temporaries(files.size());
  const TerminationSignalsHeld held;
  // Folders made here, deepest last: a failed write removes them too, so nothing is left (a failed diagnosis left
  // its --report folders behind: session 22's outside testing).
  std::vector<fs::path> created;
  auto discard = [&] {
    std::error_code ec;
    for (const auto& t : temporaries)
      if (!t.empty()) fs::remove(t, ec);
    for (auto it = created.rbegin(); it != created.rend(); ++it) fs::remove(*it, ec);  // only if empty
  };
  auto put = [&](const OutputFile& f, const fs::path& at, bool in_place) {
    std::ofstream out(at, std::ios::binary | (in_place ? std::ios::app : std::ios::trunc));
    if (!out) {
      const std::string why = std::strerror(errno);
      discard();
      throw InputError(where(f.option, f.path), "cannot write there: " + why + "; nothing was written");
    }
    out << f.content;
    out.flush();
    if (!out) {
      discard();
      throw InputError(where(f.option, f.path), "writing failed (disk full?); nothing was written");
    }
  };
  for (std::size_t i = 0; i < files.size(); ++i) {
    if (dest[i].in_place) continue;
    std::error_code ec;
    std::vector<fs::path> missing;
    for (fs::path p = fs::absolute(folder_of(dest[i].path.string()), ec); !p.empty() && !fs::exists(p, ec) && p != p.parent_path();
         p = p.parent_path())
      missing.push_back(p);
    fs::create_directories(folder_of(dest[i].path.string()), ec);
    created.insert(created.end(), missing.rbegin(), missing.rend());
    temporaries[i] = temporary_for(dest[i].path);
    put(files[i], temporaries[i], false);
    // A file replaced keeps its permissions: a baseline kept at 600 came back 644, readable by all (session 23's
    // outside testing). The temporary is the writer's own, so this cannot fail short of the folder vanishing.
    const fs::file_status old = fs::status(dest[i].path, ec);
    if (!ec && fs::is_regular_file(old)) fs::permissions(temporaries[i], old.permissions(), fs::perm_options::replace, ec);
  }
  // Devices and pipes last before the renames: a failure there still leaves no regular file written.
  for (std::size_t i = 0; i < files.size(); ++i)
    if (dest[i].in_place) put(files[i], dest[i].path, true);
  // A stop asked for during the write is obeyed before any file is replaced: the signal, let through as `held` ends,
  // then ends the run with nothing written (where it is caught instead, as by Python, the error says why).
  if (!files.empty() && held.stop_requested()) {
    discard();
    throw InputError(where(files.front().option, files.front().path), "interrupted by a signal; nothing was written");
  }
  for (std::size_t i = 0; i < files.size(); ++i) {
    if (dest[i].in_place) continue;
    std::error_code ec;
    fs::rename(temporaries[i], dest[i].path, ec);
    if (ec) {
      discard();
      throw InputError(where(files[i].option, files[i].path), "cannot replace the file: " + ec.message());
    }
  }
}

void write_file_atomically(const std::string& path, const std::string& option,
                           const std::function<void(std::ostream&)>& write) {
  std::ostringstream content;
  write(content);
  write_files_atomically({{path, option, content.str()}});
}

}  // namespace rollsim
