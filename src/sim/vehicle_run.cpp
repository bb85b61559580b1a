#include "rollsim/sim/vehicle_run.hpp"

#include <algorithm>
#include <stdexcept>

namespace rollsim {

VehicleRun run_vehicle(const Vehicle& base, const std::optional<TyreSpec>& tyre, const DriveCycle& cycle, bool replay,
                       const SimulationOptions& options) {
  // A car with other tyres behind than in front is labelled with both: the front's name alone made its row read as
  // the same tyre all round (session 22's outside testing: twizy's 125/145 beside --tyre 125-80R13).
  const bool mixed = base.front_tyre && base.rear_tyre && base.front_tyre->name != base.rear_tyre->name;
  VehicleRun run{base,
                 !base.front_tyre ? std::string("coast-down")
                 : mixed          ? "front " + base.front_tyre->name + " / rear " + base.rear_tyre->name
                                  : base.front_tyre->name,
                 {}, {}};
  if (tyre) {
    fit_tyres(run.vehicle, *tyre);
    run.tyre_label = tyre->name;
  }
  run.warnings = base.warnings;
  for (auto& w : check_tyre_loads(run.vehicle, tyre ? "--tyre '" + tyre->source + "'" : base.source, !tyre)) run.warnings.push_back(w);
  if (run.vehicle.front_tyre && !cycle.speed_mps.empty()) {
    const double top_mps = *std::max_element(cycle.speed_mps.begin(), cycle.speed_mps.end());
    const bool same = run.vehicle.front_tyre->name == run.vehicle.rear_tyre->name;
    for (const TyreSpec* t : {&*run.vehicle.front_tyre, same ? nullptr : &*run.vehicle.rear_tyre})
      if (t)
        if (std::string w = speed_rating_warning(*t, top_mps, cycle.name); !w.empty()) run.warnings.push_back(std::move(w));
  }
  // The column switches an engine: a car without one runs its auxiliaries on as before, which was not said (session
  // 22's notes).
  if (cycle.any_engine_off() && !run.vehicle.fuel())
    run.warnings.push_back(cycle.source + ": its engine_on column is not used: '" + run.vehicle.name + "' has no engine (the "
                           "auxiliaries run throughout; accessories_on switches them)");
  const VehicleModel model = VehicleModel::assemble(run.vehicle);
  try {
    run.result = replay ? simulate_replay(model, cycle, options) : simulate_forward(model, cycle, options);
  } catch (const SolverError& e) {
    throw std::runtime_error(std::string("simulation of '") + run.vehicle.name + "' on " + cycle.name +
                             " failed, no result is reported: " + e.what());
  }
  return run;
}

std::pair<std::string, std::string> tyre_files(const VehicleRun& run) {
  const Vehicle& v = run.vehicle;
  return {v.front_tyre ? v.front_tyre->source : "", v.rear_tyre ? v.rear_tyre->source : ""};
}

}  // namespace rollsim
