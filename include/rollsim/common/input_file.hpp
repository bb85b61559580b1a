// Reading an input file whole, after the checks that give each way it can be wrong its own named error.
#pragma once

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>

namespace rollsim {

/// Largest YAML input (tyre, vehicle, baseline files are a few kB; the limit keeps a wrong file from
/// filling memory inside the YAML parser).
inline constexpr std::uintmax_t kMaxYamlFileBytes = 4u << 20;
/// Largest CSV input (cycles, recordings). A recording takes about 600 bytes of memory per sample once
/// loaded; recordings are also limited to kMaxRecordingSamples rows (see recording.hpp).
inline constexpr std::uintmax_t kMaxCsvFileBytes = 256u << 20;

/// The whole content of `path`. Throws InputError naming the path for each way it cannot be input: not
/// found, a folder, not a regular file, not readable (with the system's reason), larger than `max_bytes`.
std::string read_input_file(const std::string& path, std::uintmax_t max_bytes);

/// Whether `path` is a regular file, or a folder. False for every way it cannot be one, including a name the system
/// refuses (longer than NAME_MAX, say), where std::filesystem's throwing queries would end the run with a system
/// error instead of the caller's named "not found".
bool is_regular_file_path(const std::filesystem::path& path);
bool is_folder_path(const std::filesystem::path& path);
/// Why `path` is not a file to read, in the words of an error ("is a folder; a file is expected here", "is not a
/// regular file (a device, pipe or socket?)", "not found"); empty when it is a regular file. A folder or /dev/null
/// named inside another file read "not found" (session 21).
std::string why_not_a_file(const std::filesystem::path& path);

/// A file named inside another file (a vehicle file's tyres, a fleet manifest, a regression baseline) travels with
/// it: `name` (or `name` + `extension`) resolved against `referring_file`'s folder, if that is a file (an absolute
/// `name` resolves to itself).
std::optional<std::string> file_beside(const std::string& name, const std::string& referring_file,
                                       const std::string& extension = "");
/// file_beside, else `name` unchanged for the usual lookup (the current folder, then the shipped data).
std::string path_beside(const std::string& name, const std::string& referring_file);

}  // namespace rollsim
