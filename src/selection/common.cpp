// Running a car for tyre selection, its headline figure, and atomic file writes.
#include "rollsim/selection/common.hpp"

#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <fstream>

#include "rollsim/common/error.hpp"

namespace rollsim::selection {

std::string energy_unit(const Vehicle& vehicle) { return make_powertrain(vehicle)->fuel() ? "l_per_100km" : "kwh_per_10km"; }

std::string energy_unit_label(const std::string& unit) {
  return unit == "kwh_per_10km" ? "kWh/10 km" : unit == "l_per_100km" ? "l/100 km" : unit;
}

EnergyFigure energy_figure(const SimulationResult& r) {
  EnergyFigure f;
  if (r.fuel) {
    f.value = r.fuel_l_per_100km();
    f.unit = "l_per_100km";
  } else {
    f.value = r.aec_kwh_per_10km();
    f.unit = "kwh_per_10km";
    f.range_km = r.range_km();
  }
  return f;
}

EnergyFigure run_forward(const Vehicle& vehicle, const DriveCycle& cycle) {
  const VehicleModel model = VehicleModel::assemble(vehicle);
  return energy_figure(simulate_forward(model, cycle));
}

void write_file_atomically(const std::string& path, const std::string& content, const std::string& option) {
  namespace fs = std::filesystem;
  const fs::path target(path);
  const fs::path dir = target.has_parent_path() ? target.parent_path() : fs::path(".");
  // The temporary file sits in the target's folder so that the rename cannot cross file systems.
  const fs::path tmp = dir / ("." + target.filename().string() + ".tmp" + std::to_string(getpid()));
  {
    std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
    if (!out) throw InputError(option + " " + path, "cannot write here (folder missing or not writable)");
    out << content;
    out.flush();
    if (!out) {
      std::error_code ec;
      fs::remove(tmp, ec);
      throw InputError(option + " " + path, "writing failed (disk full?); nothing was written");
    }
  }
  std::error_code ec;
  fs::rename(tmp, target, ec);
  if (ec) {
    fs::remove(tmp, ec);
    throw InputError(option + " " + path, "cannot replace the file: " + ec.message());
  }
}

}  // namespace rollsim::selection
