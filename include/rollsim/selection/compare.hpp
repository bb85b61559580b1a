// Tyre selection for a car: fit checks (load capacity, outer diameter) and a ranking by cycle energy or fuel.
#pragma once

#include <string>
#include <vector>

#include "rollsim/common/distribute.hpp"
#include "rollsim/cycle/drive_cycle.hpp"
#include "rollsim/sim/simulation.hpp"
#include "rollsim/tyre/tyre_spec.hpp"
#include "rollsim/vehicle/vehicle.hpp"
#include "rollsim/common/units.hpp"

namespace rollsim::selection {

/// ETRTO reference pressure of a tyre's load rating: 2.9 bar for extra-load (XL) sizes, 2.5 bar otherwise.
double reference_pressure_pa(const TyreSpec& tyre);

/// Load capacity [N] at the tyre's own inflation pressure: the rated maximum load scaled by
/// (p / p_ref)^0.585 below the reference pressure (the load-inflation exponent of the TRA/ETRTO passenger
/// tables, which these tables follow within a few per cent) and not raised above it. 0 when the rating is unknown,
/// and for a light-truck (LT) size, whose reference pressure is its load range's and not in the designation.
double load_capacity_at_pressure_n(const TyreSpec& tyre);

/// Does `candidate` fit the car whose own tyre is `own`?
struct FitCheck {
  bool fits = true;
  double wheel_load_n = 0.0;          ///< heaviest axle's static load per wheel
  double capacity_n = 0.0;            ///< load_capacity_at_pressure_n (0: unknown)
  double diameter_change_pct = 0.0;   ///< outer diameter relative to the own tyre
  std::string reason;                 ///< "does not fit: ..." or empty
};
FitCheck check_fit(const Vehicle& vehicle, const TyreSpec& own, const TyreSpec& candidate,
                   double diameter_tolerance_pct);

struct CandidateResult {
  TyreSpec tyre;
  bool is_own = false;            ///< the vehicle's own tyre (the reference of the % column)
  FitCheck fit;
  double rrc_80 = 0.0;            ///< RRC at 80 km/h at the heaviest axle's wheel load
  double rr_power_80_w = 0.0;     ///< one tyre's RR power there
  bool simulated = false;         ///< false when the car could not be run on this tyre (see error)
  std::string error;
  double value = 0.0;             ///< energy or fuel per distance (unit of the table)
  double diff_pct = 0.0;          ///< relative to the own tyre, + = uses more
  double range_km = 0.0;          ///< battery-only cars
  double range_change_km = 0.0;   ///< battery-only cars, + = gains range
  TraceFollowing trace;           ///< whether the car kept to the cycle on this tyre (EnergyFigure)
  std::string overcharge;         ///< the battery charged past full on this tyre (EnergyFigure), or empty
};

/// One vehicle on one cycle: the fitting tyres ranked best first, then the unfit ones (unranked, same order as given).
struct Comparison {
  std::string vehicle;
  std::string cycle;
  bool shows_range = false;  ///< the figure is battery energy (no fuel burned): range columns apply
  std::string unit;
  double own_value = 0.0;
  double own_range_km = 0.0;
  double wheel_load_n = 0.0;  ///< the heavier axle's static wheel load, at which RRC and RR power are given
  std::vector<CandidateResult> ranked;
  std::vector<CandidateResult> unfit;
};

/// The candidates read from files without the car's own tyre file and without a file already among them (named by
/// name and by path, it was ranked twice: session 23's outside testing); each one left out is said in `left_out`.
/// Candidates that are not files (built in memory) are all kept.
std::vector<TyreSpec> without_duplicate_files(const Vehicle& vehicle, const std::vector<TyreSpec>& candidates,
                                              std::vector<std::string>& left_out);

struct CompareOptions {
  double diameter_tolerance_pct = 3.0;
  double reference_speed_mps = units::kmh_to_mps(80.0);
  bool replay = false;   ///< kinematic replay instead of the forward simulation
  unsigned threads = 0;  ///< 0: every core
  /// How the candidates are spread (over MPI ranks by the CLI); empty = this process's threads.
  CaseMap map_cases;
};

/// Runs the car (forward simulation, or replay) with its own tyre and with each candidate on all four wheels,
/// the car assembled once and only its tyres made per candidate.
/// Throws InputError if the car cannot be run on its own tyre.
Comparison compare_tyres(const Vehicle& vehicle, const std::vector<TyreSpec>& candidates, const DriveCycle& cycle,
                         const CompareOptions& options = {});

}  // namespace rollsim::selection
