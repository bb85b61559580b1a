#include "rollsim/common/atomic_file.hpp"

#include <unistd.h>

#include <cerrno>
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

bool writable_dir(const fs::path& dir) {
  std::error_code ec;
  return fs::is_directory(dir, ec) && ::access(dir.c_str(), W_OK | X_OK) == 0;
}

// The temporary sits in the target's folder so that the rename cannot cross file systems.
fs::path temporary_for(const std::string& path) {
  const fs::path target(path);
  // Appended, not "." + string&&: GCC 12 warns falsely (-Wrestrict) on the latter once it is inlined.
  std::string name = ".";
  name += target.filename().string();
  name += ".tmp" + std::to_string(::getpid());
  return folder_of(path) / name;
}

}  // namespace

void check_output_file(const std::string& path, const std::string& option) {
  std::error_code ec;
  if (path.empty()) throw InputError(option, "an empty file name");
  if (fs::is_directory(path, ec)) throw InputError(where(option, path), "is a folder; give a file name");
  if (!fs::exists(folder_of(path), ec))
    throw InputError(where(option, path), "cannot write there: folder '" + folder_of(path).string() + "' does not exist");
  if (!writable_dir(folder_of(path)))
    throw InputError(where(option, path), "cannot write there: folder '" + folder_of(path).string() + "' is not a writable folder");
}

void check_output_dir(const std::string& dir, const std::string& option) {
  std::error_code ec;
  fs::path p = fs::absolute(fs::path(dir), ec);
  if (fs::exists(p, ec)) {
    if (!writable_dir(p)) throw InputError(where(option, dir), "is not a writable folder");
    return;
  }
  while (p.has_parent_path() && p != p.parent_path() && !fs::exists(p, ec)) p = p.parent_path();
  if (!writable_dir(p)) throw InputError(where(option, dir), "cannot be created: '" + p.string() + "' is not a writable folder");
}

void write_files_atomically(const std::vector<OutputFile>& files) {
  std::vector<fs::path> written;
  auto discard = [&] {
    std::error_code ec;
    for (const auto& t : written) fs::remove(t, ec);
  };
  for (const auto& f : files) {
    std::error_code ec;
    fs::create_directories(folder_of(f.path), ec);
    const fs::path tmp = temporary_for(f.path);
    std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
    if (!out) {
      const std::string why = std::strerror(errno);
      discard();
      throw InputError(where(f.option, f.path), "cannot write there: " + why + "; nothing was written");
    }
    written.push_back(tmp);
    out << f.content;
    out.flush();
    if (!out) {
      discard();
      throw InputError(where(f.option, f.path), "writing failed (disk full?); nothing was written");
    }
  }
  for (std::size_t i = 0; i < files.size(); ++i) {
    std::error_code ec;
    fs::rename(written[i], files[i].path, ec);
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
