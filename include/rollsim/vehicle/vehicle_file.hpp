// Vehicle files written back (diagnose --write-vehicle): the files they name resolved, so they load from anywhere.
#pragma once

#include <string>

namespace rollsim {

/// The path of the tyre file a vehicle file names: beside the vehicle file first (with or without .yaml), then the
/// shipped tyres/ folder. Throws InputError naming `where` when neither exists.
std::string resolve_tyre_path(const std::string& name, const std::string& vehicle_file, const std::string& where);

/// The text of the vehicle file at `vehicle_path` (possibly with blocks appended, as diagnose does) made loadable
/// from any folder: its tyres: block is rewritten with the absolute paths of the files it names, or, given
/// `tyre_override` (the --tyre the diagnosis used), with that tyre on all four wheels. Everything else, comments
/// included, is kept as it is.
std::string portable_vehicle_yaml(const std::string& text, const std::string& vehicle_path,
                                  const std::string& tyre_override = "");

}  // namespace rollsim
