// Presenting simulation results: readable summary, JSON, the time-series trace CSV, and comparison tables.
#pragma once

#include <ostream>
#include <string>
#include <vector>

#include "rollsim/report/table.hpp"
#include "rollsim/sim/simulation.hpp"

namespace rollsim::report {

/// Where the energy went, in kWh, in the order a reader expects (wheel uses, then powertrain losses).
std::vector<std::pair<std::string, double>> energy_terms_kwh(const SimulationResult& r);

/// Multi-line human summary: consumption, range or fuel and CO2, energy breakdown with shares, balance
/// closure, tracking error and shortfalls; with `solver_stats`, CVODE's counters.
std::string summary_text(const SimulationResult& r, bool solver_stats);

/// What a run that did not follow its trace (`trace.followed` false) measured instead: the one wording of every
/// front end's warning about such a run.
std::string shortfall_caveat(const TraceFollowing& trace);

/// A range for a table: "N km" to `decimals`, or what to say when it is undefined (NaN: the battery ends with more
/// charge than it began, or the car did not move).
std::string range_text(double range_km, int decimals);

/// What a run that charged its battery past full booked that a real car could not (no charge limit is modelled),
/// or empty: the one wording of every front end's warning about such a run.
std::string overcharge_caveat(const SimulationResult& r);

/// One line per thing that makes a run's figures differ from the trace's own: the battery charged past full, the
/// car fell behind it (or, in a replay, could not deliver it), or the usable battery ran empty; empty when none. For tables of several runs,
/// where the summary's own warnings are not printed.
std::vector<std::string> run_caveats(const SimulationResult& r);

/// JSON with at least distance_km, aec_kwh_per_10km (electric), fuel_l_per_100km (combustion), co2_g_per_km,
/// energy_breakdown_kwh, max_speed_error_kmh.
JsonObject to_json(const SimulationResult& r, const std::string& tyre_label);

/// The input files a run was read from, as `vehicle_file`, `tyre_file` (the front tyres', the car's own where no tyre
/// set was given), `cycle_file` (null where the input was not a file: a Python dict or arrays, a car without tyres),
/// and `rear_tyre_file` where the rear tyres came from another file. Two cycles or tyres of one name read alike
/// without them.
struct RunInputFiles {
  std::string vehicle, tyre, cycle;  ///< empty: not a file
  std::string rear_tyre;             ///< empty: the front's
};
void add_input_files(JsonObject& j, const RunInputFiles& files);

/// One named column of the trace, in the units its name carries (as the --trace CSV writes it).
struct TraceColumn {
  std::string name;
  std::vector<double> values;
};

/// The --trace columns in file order, one value per trace point. Powers and rates are the values at the point
/// (traction_power_kw: the power the drive delivers at the wheels, 0 when braking). A battery's columns
/// (battery_power_kw, battery_current_a, soc_pct, battery_energy_kwh) and a fuel's (fuel_rate_lph, fuel_l) appear
/// only for a car that has one. battery_energy_kwh and fuel_l are running totals from the start, as the run
/// integrates them: a difference of two rows is that interval's energy or fuel exactly, where point rates summed
/// over a 1 Hz trace miss every kink. The forward run's rows are the cycle's samples; the replay's are its segment
/// starts (the last sample is not a row, so the last row's totals lack the last segment).
std::vector<TraceColumn> trace_columns(const SimulationResult& r);

/// One row per trace point, the columns of trace_columns.
void write_trace_csv(std::ostream& out, const SimulationResult& r);

/// The figure a run is judged by: kWh/10 km for electric cars, l/100 km for combustion ones.
double headline_value(const SimulationResult& r);
std::string headline_unit(const SimulationResult& r);

}  // namespace rollsim::report
