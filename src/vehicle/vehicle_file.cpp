// Vehicle files written back: tyre files resolved to absolute paths, so a file written elsewhere still loads.
#include "rollsim/vehicle/vehicle_file.hpp"

#include <filesystem>
#include <sstream>
#include <vector>

#include "rollsim/common/error.hpp"
#include "rollsim/common/input_file.hpp"
#include "rollsim/common/yaml_reader.hpp"

namespace rollsim {

std::string resolve_tyre_path(const std::string& name, const std::string& vehicle_file, const std::string& where) {
  // Beside the vehicle file, then shipped: never the current folder, or one vehicle file would give another car
  // depending on where it is run from.
  if (auto beside = file_beside(name, vehicle_file, ".yaml")) return *beside;
  if (auto shipped = shipped_data_file(name, "tyres", ".yaml")) return *shipped;
  const auto beside = std::filesystem::path(vehicle_file).parent_path() / name;
  if (const std::string why = why_not_a_file(beside); why != "not found") throw InputError(where, "tyre file '" + beside.string() + "' " + why);
  throw InputError(where, "tyre file '" + name + "' not found beside the vehicle file or in the shipped tyres/");
}

namespace {

// The line (from 0) of the body's wheel_radius_m key, or -1. A vehicle file refuses the key beside tyres, so a
// coast-down file written back with the --tyre its diagnosis used must drop it to load again.
int wheel_radius_line(const std::string& vehicle_path) {
  const YAML::Node body = YamlMap::load_file(vehicle_path).node()["body"];
  if (!body.IsMap()) return -1;
  for (const auto& kv : body)
    if (kv.first.Scalar() == "wheel_radius_m") return kv.first.Mark().line;
  return -1;
}

}  // namespace

std::string portable_vehicle_yaml(const std::string& text, const std::string& vehicle_path, const std::string& tyre_override) {
  namespace fs = std::filesystem;
  auto quoted = [](const std::string& path) {
    std::string q = "\"";  // appended: GCC 12 warns falsely (-Wrestrict) on "\"" + string&& once inlined
    q += fs::absolute(path).lexically_normal().string();
    return q + "\"";
  };
  // The tyres the file names, resolved as load_vehicle_file resolves them.
  std::vector<std::pair<std::string, std::string>> tyres;  // key, absolute path
  if (!tyre_override.empty()) {
    tyres.emplace_back("all", quoted(tyre_override));
  } else {
    YamlMap root = YamlMap::load_file(vehicle_path);
    auto t = root.optional_map("tyres");
    if (!t) return text;  // coast-down only: nothing to resolve
    for (const char* key : {"all", "front", "rear"})
      if (t->has(key)) tyres.emplace_back(key, quoted(resolve_tyre_path(t->string(key), vehicle_path, t->where(key))));
  }
  // Replace the top-level tyres: block (its line and the indented or blank lines under it) by the resolved one.
  std::istringstream in(text);
  std::ostringstream out;
  bool in_block = false, written = false;
  auto write_block = [&] {
    out << "tyres:  # resolved to absolute paths when this file was written\n";
    for (const auto& [key, path] : tyres) out << "  " << key << ": " << path << "\n";
    written = true;
  };
  const int radius_line = tyres.empty() ? -1 : wheel_radius_line(vehicle_path);
  int n = -1;
  for (std::string line; std::getline(in, line);) {
    if (++n == radius_line) {
      const std::size_t at = line.find_first_not_of(" ");
      if (at == std::string::npos || line.compare(at, 14, "wheel_radius_m") != 0)
        throw InputError(vehicle_path + ": key 'body.wheel_radius_m'", "must stand on its own line to be dropped beside the tyres");
      out << line.substr(0, at) << "# " << line.substr(at) << "  # dropped by rollsim: the tyres below gear the car\n";
      continue;
    }
    const bool top_level = !line.empty() && line[0] != ' ' && line[0] != '\t' && line[0] != '#';
    if (in_block && top_level) in_block = false;
    if (in_block) continue;
    if (line.rfind("tyres:", 0) == 0) {
      in_block = true;
      write_block();
      continue;
    }
    out << line << "\n";
  }
  if (!written) {
    std::string s = out.str();
    std::ostringstream o2;
    o2 << s;
    out.swap(o2);
    write_block();  // a --tyre on a coast-down vehicle file: the tyres join it
  }
  return out.str();
}

}  // namespace rollsim
