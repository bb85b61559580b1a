#include "rollsim/sim/vehicle_run.hpp"

#include <stdexcept>

namespace rollsim {

VehicleRun run_vehicle(const Vehicle& base, const std::optional<TyreSpec>& tyre, const DriveCycle& cycle, bool replay,
                       const SimulationOptions& options) {
  VehicleRun run{base, base.front_tyre ? base.front_tyre->name : "coast-down", {}, {}};
  if (tyre) {
    fit_tyres(run.vehicle, *tyre);
    run.tyre_label = tyre->name;
  }
  run.warnings = base.warnings;
  for (auto& w : check_tyre_loads(run.vehicle, tyre ? "--tyre '" + tyre->source + "'" : base.source)) run.warnings.push_back(w);
  const VehicleModel model = VehicleModel::assemble(run.vehicle);
  try {
    run.result = replay ? simulate_replay(model, cycle, options) : simulate_forward(model, cycle, options);
  } catch (const SolverError& e) {
    throw std::runtime_error(std::string("simulation of '") + run.vehicle.name + "' on " + cycle.name +
                             " failed, no result is reported: " + e.what());
  }
  return run;
}

}  // namespace rollsim
