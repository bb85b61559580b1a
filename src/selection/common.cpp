// Running a car for tyre selection and its headline figure.
#include "rollsim/selection/common.hpp"

#include "rollsim/common/error.hpp"
#include "rollsim/report/simulation_report.hpp"

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
  f.trace = r.trace_following();
  f.overcharge = report::overcharge_caveat(r);
  return f;
}

EnergyFigure run_forward(const Vehicle& vehicle, const DriveCycle& cycle) {
  const VehicleModel model = VehicleModel::assemble(vehicle);
  return energy_figure(simulate_forward(model, cycle));
}

EnergyFigure run_model(const VehicleModel& model, const DriveCycle& cycle, bool replay) {
  return energy_figure(replay ? simulate_replay(model, cycle) : simulate_forward(model, cycle));
}

void require_distance(const DriveCycle& cycle) {
  if (cycle.distance_m() > 0.0) return;
  throw InputError("cycle '" + cycle.name + "'", "covers no distance (its speed is 0 throughout): energy per distance is "
                                                 "undefined, so no tyre can be ranked, swept or differentiated on it");
}

void require_one_tyre_set(const Vehicle& vehicle, const std::string& what) {
  if (!vehicle.front_tyre || !vehicle.rear_tyre) return;
  const TyreSpec& f = *vehicle.front_tyre;
  const TyreSpec& r = *vehicle.rear_tyre;
  if (f.source == r.source && f.name == r.name) return;
  throw InputError(vehicle.source, "has different front and rear tyres ('" + f.name + "', '" + r.name + "'); " + what +
                                       " fits one tyre on all four wheels, so the car's own figure would not be the car "
                                       "as built");
}

std::string run_mode_label(bool replay) { return replay ? "kinematic replay" : "forward simulation"; }

}  // namespace rollsim::selection
