// What `compare` and `sweep` are given and what their --json writes, shared by the CLI and the Python API.
#pragma once

#include <string>
#include <vector>

#include "rollsim/common/json.hpp"
#include <optional>

#include "rollsim/selection/compare.hpp"
#include "rollsim/selection/sensitivity.hpp"
#include "rollsim/selection/sweep.hpp"
#include "rollsim/tyre/tyre_spec.hpp"

namespace rollsim::selection {

/// Candidate tyres: each of `tyres` (file or shipped name), then with `use_catalogue` (or no `tyres`) every *.yaml
/// of `catalogue` (empty: the shipped tyres/catalogue). A broken catalogue file is skipped and its error kept.
struct CandidateList {
  std::vector<TyreSpec> tyres;
  std::vector<std::string> broken;  ///< one error message per skipped file
};
CandidateList load_candidates(const std::vector<std::string>& tyres, bool use_catalogue, const std::string& catalogue);

/// The outer-diameter tolerance given as text [%], checked to (0, 100].
double parse_diameter_tolerance_pct(const std::string& text);

/// "175/70 R14 84T", or "R305 W195" for a tyre given by geometry.
std::string tyre_size_text(const TyreSpec& tyre);

/// One object per tyre: the ranked ones best first, then the unfit ones (rank null).
std::vector<JsonObject> comparison_json(const Comparison& comparison);

/// One message per simulated tyre on which the car could not follow the cycle, saying what its figure measured
/// instead (report::shortfall_caveat; no "warning:" prefix: each front end adds its own); empty when all followed.
std::vector<std::string> trace_warnings(const Comparison& comparison);

/// The sensitivities a user asks for: the tyre (default: the car's own), with a car also its energy elasticities on
/// `cycle`; the operating point's load `load_n` [N] (default: the car's heaviest wheel load, else 80 % of the tyre's
/// maximum) at `speed_mps`. Errors name the option as the command line does (--tyre, --load-n) and, for a point
/// outside the model's domain, the tyre's file and the load.
Sensitivity sensitivity_of(const std::optional<Vehicle>& vehicle, const std::optional<TyreSpec>& tyre,
                           const DriveCycle& cycle, std::optional<double> load_n, double speed_mps);

/// One object: the point, RR power, each parameter's value (value_outer_diameter_mm, value_section_width_mm,
/// value_pressure_bar, value_load_n)
/// and elasticities (elasticity_rr_power_<key>, elasticity_rrc_<key>, elasticity_<unit>_<key> and its
/// ..._double_step), the dominant parameters; with a car its figure, followed_trace and energy_elasticities_smooth.
JsonObject sensitivity_json(const Sensitivity& sensitivity);

/// What a reader must know before using the figures (no "warning:" prefix): a tyre loaded past its rating, a car
/// that fell behind its cycle in the base run or a perturbed one, an energy elasticity that is not a slope.
std::vector<std::string> sensitivity_warnings(const Sensitivity& sensitivity);

/// A sweep as given: one --param, --from, --to (and optionally --steps) per axis; numbers as text.
struct SweepRequest {
  std::vector<std::string> params, from, to, steps;
  std::string load_n;              ///< empty: 80 % of the maximum load
  std::string speed_kmh;           ///< empty: 80 km/h; refused beside a speed axis, which sets the speed
  std::string threads;             ///< empty: every core
};
/// Parses and checks the axes, load, speed and threads (errors name the option, value and what is allowed).
SweepOptions sweep_options_from_request(const SweepRequest& request);

/// One object per valid point: the swept values (key_unit), load, speed, RRC, force, power, and the car's figure.
std::vector<JsonObject> sweep_json(const SweepResult& result);

}  // namespace rollsim::selection
