// Every row of the EPA Test Car List simulated from its certification data and compared with its measured result.
#pragma once

#include <string>
#include <vector>

#include "rollsim/common/distribute.hpp"
#include "rollsim/validate/epa_car.hpp"
#include "rollsim/validate/epa_test_car.hpp"
#include "rollsim/validate/maker_calibration.hpp"

namespace rollsim::validate {

/// The split: a row belongs to the fitting half when the FNV-1a hash of its lower-cased "make|model" is even,
/// so every test of one model lands on the same side and held-out rows are models the constants never saw.
bool in_fitting_half(const EpaTestRow& row);

struct RowOutcome {
  const EpaTestRow* row = nullptr;
  SkipReason skip = SkipReason::none;
  std::string skip_detail;
  bool fitting_half = false;
  /// The line of the test's first row where the list repeats a test (one line per aftertreatment device), else 0.
  /// A repeat counts nowhere: skipped as `duplicate_test` where it would otherwise be simulated.
  std::size_t repeat_of_line = 0;
  std::string powertrain;       ///< "petrol", "diesel", "E85", "electric"
  std::string unit;             ///< "mpg" or "mpge"
  double measured = 0.0;        ///< in `unit`
  double predicted = 0.0;
  /// FTP-75 rows: the predicted economy [mpg] of bags 1 (cold), 2 and 3 (hot), to compare with the list's FE Bag
  /// 1..3; zero on other rows.
  double predicted_bag_mpg[3] = {0.0, 0.0, 0.0};
  /// The row's RND_ADJ_FE was read as kWh per 100 miles (electric rows below 60 "MPG", see README).
  bool measured_from_kwh_per_100mi = false;
  /// The maker calibration's factor on `predicted` (maker_calibration.hpp): learned on the fitting half, and for a
  /// fitting-half row without its own model's rows; 1 where the fitting half has no other car of its make and cycle.
  double maker_factor = 1.0;
  /// Its fuel's constant (or an FTP's cold-start excess) had no fitting-half row to fit it: predicted with the
  /// nominal value, so its error judges no fitted model.
  bool nominal_constants = false;
  double error_pct() const { return 100.0 * (predicted / measured - 1.0); }
  double maker_calibrated_error_pct() const { return 100.0 * (maker_factor * predicted / measured - 1.0); }
};

/// The constants fitted on the fitting half, with how many rows set each.
struct FittedConstants {
  EpaDefaults defaults;
  std::size_t petrol_rows = 0, diesel_rows = 0, electric_rows = 0, cold_start_rows = 0;
};

struct Validation {
  std::vector<RowOutcome> rows;   ///< one per input row, in file order
  FittedConstants fitted;
  MakerCalibration maker_calibration;  ///< learned on the fitting half's predictions with the fitted constants
};

/// Classifies every row (skips with reasons, hybrids by rule), simulates the rest by kinematic replay with the
/// nominal constants, fits the four constants of EpaDefaults on the fitting half, and predicts every row with
/// them; then learns the maker calibration on the fitting half and gives every row its factor. `threads`: 0 for
/// the hardware's concurrency; `map`: how the rows are spread (over MPI ranks by the CLI; empty: this process's
/// threads).
Validation validate_epa_list(const std::vector<EpaTestRow>& rows, unsigned threads, const CaseMap& map = {});

/// What a replay's trace (recorded) shows of the engine's transients: the sum of every rise of the segment fuel
/// rate, and how many times the fuel is cut off (a fuelled segment followed by one without fuel).
struct FuelEvents {
  double rises_m3_per_s = 0.0;
  int cut_offs = 0;
};
FuelEvents fuel_events(const SimulationResult& s);

/// What fuel_with_transients_m3 needs of a car with a fuel converter.
struct TransientFuelParams {
  double idle_fuel_m3_per_s = 0.0;
  double fuel_density_kg_per_m3 = 0.0;
  double fuel_energy_j_per_m3 = 0.0;
  double engine_inertia_kg_m2 = 0.0;   ///< 0: a powertrain without an engine map
  double marginal_efficiency = 1.0;    ///< brake work per fuel energy at the margin, what spinning the engine up costs
  bool continuously_variable = false;  ///< a variator, not clutches, changes the ratio
};
/// Read off the car's powertrain (its standstill fuel rate, fuel, and the engine map's inertia and efficiency).
TransientFuelParams transient_fuel_params(const VehicleModel& car);

/// The engine's kinetic energy [J] a run's trace asks the fuel for: every rise of 1/2 J w^2 between samples that
/// ends under power (a rise while coasting, a downshift, is paid by the wheels), less what the engine gives back
/// while it drives on in one gear (the car slowing under power) or, behind a variator, at any ratio (the belt
/// passes the inertia's torque to the wheels). A stepped upshift's drop (the clutches and the spark retard of the
/// shift take it) and a drop while coasting or braking (fuel is cut or the brakes take it) give nothing back.
double engine_spin_up_j(const SimulationResult& s, double inertia_kg_m2, bool continuously_variable = false);

/// The run's fuel [m3] with what a steady-state map leaves out (validate.cpp, after SAE 2017-01-0533): transient
/// fuelling (0.15 s of each rise of the fuel rate), per cut-off 1.5 s at the idle rate before it and a 0.3 g
/// catalyst purge after it, and the engine's spin-up (engine_spin_up_j) at the marginal efficiency. Needs the
/// run's trace; a density, fuel energy or efficiency that is not positive where it is needed is a ModelDomainError.
double fuel_with_transients_m3(const SimulationResult& s, const TransientFuelParams& p);

/// FTP-75 fuel economy [mpg] from its bags (40 CFR 600.113): 0.43 x the cold UDDS (bags 1 + 2) and 0.57 x the hot
/// UDDS (bags 3 + 2), weighted in gallons per mile. Bag 3 drives the same trace as bag 1.
double ftp75_weighted_mpg(double bag1_gal, double bag2_gal, double bag3_gal, double bag1_miles, double bag2_miles);

/// Median signed error, median and 90th percentile (nearest rank) of |error| [%] of a set of rows.
struct ErrorStats {
  double median_error_pct = 0.0, median_abs_error_pct = 0.0, p90_abs_error_pct = 0.0;
};

/// One line of the summary: a powertrain on a cycle, on one half: the physics' errors, and with the maker
/// calibration (a fitting-half row calibrated without its own model, so neither figure is in-sample).
struct SummaryLine {
  std::string powertrain, cycle, half;  ///< half: "held-out", "fitting"
  std::size_t count = 0;
  ErrorStats physics, maker_calibrated;
};
std::vector<SummaryLine> summarise(const Validation& v);

/// Rows simulated / rows of the four simulated kinds of test (FTP-75, HWFET, US06, charge-depleting) per half.
struct Coverage {
  std::size_t eligible = 0, simulated = 0;
};
Coverage coverage(const Validation& v, bool fitting_half);

}  // namespace rollsim::validate
