#include "rollsim/common/input_file.hpp"

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "rollsim/common/error.hpp"
#include "rollsim/common/format.hpp"

namespace rollsim {

bool is_regular_file_path(const std::filesystem::path& path) {
  std::error_code ec;
  return std::filesystem::is_regular_file(path, ec);
}

bool is_folder_path(const std::filesystem::path& path) {
  std::error_code ec;
  return std::filesystem::is_directory(path, ec);
}

std::string why_not_a_file(const std::filesystem::path& path) {
  if (is_regular_file_path(path)) return "";
  if (is_folder_path(path)) return "is a folder; a file is expected here";
  std::error_code ec;
  if (std::filesystem::exists(path, ec)) return "is not a regular file (a device, pipe or socket?)";
  return "not found";
}

std::optional<std::string> file_beside(const std::string& name, const std::string& referring_file,
                                       const std::string& extension) {
  if (name.empty()) return std::nullopt;
  const std::string beside = (std::filesystem::path(referring_file).parent_path() / name).string();
  if (is_regular_file_path(beside)) return beside;
  if (!extension.empty() && is_regular_file_path(beside + extension)) return beside + extension;
  return std::nullopt;
}

std::string path_beside(const std::string& name, const std::string& referring_file) {
  return file_beside(name, referring_file).value_or(name);
}

std::string read_input_file(const std::string& path, std::uintmax_t max_bytes) {
  namespace fs = std::filesystem;
  std::error_code ec;
  const fs::file_status st = fs::status(path, ec);
  if (st.type() == fs::file_type::not_found) throw InputError(path, "file not found");
  if (ec) throw InputError(path, "cannot be read: " + ec.message());
  if (st.type() == fs::file_type::directory) throw InputError(path, "is a folder; a file is expected here");
  if (st.type() != fs::file_type::regular) throw InputError(path, "is not a regular file (a device, pipe or socket?)");
  const std::uintmax_t size = fs::file_size(path, ec);
  if (!ec && size > max_bytes) {
    // In bytes beside MiB: 4.77 MiB read "is 4 MiB; ... limited to 4 MiB" (session 23's outside testing).
    throw InputError(path, "is " + std::to_string(size) + " bytes (" + fixed(static_cast<double>(size) / (1 << 20), 2) +
                               " MiB); files of this kind are limited to " + std::to_string(max_bytes >> 20) + " MiB");
  }
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path, std::string("cannot be read: ") + std::strerror(errno));
  std::ostringstream buf;
  buf << in.rdbuf();
  if (in.bad()) throw InputError(path, std::string("reading failed: ") + std::strerror(errno));
  return buf.str();
}

}  // namespace rollsim
