// Tyre selection: fit checks against the car and its own tyre, and a ranking by forward-simulated energy or fuel.
#include "rollsim/selection/compare.hpp"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <set>

#include "rollsim/common/error.hpp"
#include "rollsim/common/format.hpp"
#include "rollsim/common/units.hpp"
#include "rollsim/report/table.hpp"
#include "rollsim/selection/common.hpp"
#include "rollsim/tyre/tyre_model.hpp"

namespace rollsim::selection {

double reference_pressure_pa(const TyreSpec& tyre) {
  const bool xl = tyre.size && tyre.size->extra_load;
  return units::bar_to_pa(xl ? 2.9 : 2.5);
}

namespace {
// A light-truck (or van or truck) tyre's load index holds at its load range's inflation (TRA: C 350, D 450, E 550 kPa),
// which the size designation does not carry; the passenger reference overstated its capacity at car pressures by ~60 %
// (session 20).
bool light_truck(const TyreSpec& tyre) { return tyre.size && tyre.size->commercial; }
}  // namespace

double load_capacity_at_pressure_n(const TyreSpec& tyre) {
  if (!(tyre.max_load_n > 0.0) || light_truck(tyre)) return 0.0;
  const double ratio = tyre.state.pressure_pa / reference_pressure_pa(tyre);
  // Above the reference pressure the rating does not grow: the load index is the tyre's ceiling.
  return ratio >= 1.0 ? tyre.max_load_n : tyre.max_load_n * std::pow(ratio, 0.585);
}

FitCheck check_fit(const Vehicle& vehicle, const TyreSpec& own, const TyreSpec& candidate,
                   double diameter_tolerance_pct) {
  FitCheck f;
  const AxleWheelLoads loads = wheel_loads(vehicle.body, 0.0);
  f.wheel_load_n = std::max(loads.front_n, loads.rear_n);
  f.capacity_n = load_capacity_at_pressure_n(candidate);
  const double d_own = 2.0 * own.state.geometry.outer_radius_m;
  const double d_new = 2.0 * candidate.state.geometry.outer_radius_m;
  f.diameter_change_pct = (d_new / d_own - 1.0) * 100.0;
  std::vector<std::string> reasons;
  if (f.capacity_n <= 0.0) {
    reasons.push_back(light_truck(candidate) ? "load capacity unknown: a light-truck (LT) tyre's load index holds at its "
                                               "load range's pressure (C 350, D 450, E 550 kPa), which the size does not give"
                                             : "load capacity unknown (no load index or max load)");
  } else if (f.wheel_load_n > f.capacity_n) {
    // "load 3999 N > 3999 N capacity" and "+3.0 % (tolerance 3 %)" said a tyre failed a check its figures passed.
    const int d = decimals_apart(f.wheel_load_n, f.capacity_n, 0, 6);
    reasons.push_back("load " + fixed(f.wheel_load_n, d) + " N > " + fixed(f.capacity_n, d) +
                      " N capacity at " + fixed(units::pa_to_bar(candidate.state.pressure_pa), 1) + " bar");
  }
  // A change that is the tolerance to rounding (628.3 mm against 610 mm: 3.0000000000000027 %) is within it.
  if (std::abs(f.diameter_change_pct) > diameter_tolerance_pct * (1.0 + 1e-12)) {
    const int d = decimals_apart(std::abs(f.diameter_change_pct), diameter_tolerance_pct, 1, 6);
    reasons.push_back("diameter " + fixed(d_new * 1e3, d > 1 ? 2 : 0) + " mm is " +
                      (f.diameter_change_pct > 0 ? "+" : "") + fixed(f.diameter_change_pct, d) + " % from " +
                      fixed(d_own * 1e3, 0) + " mm (tolerance " + format_value(diameter_tolerance_pct) + " %)");
  }
  f.fits = reasons.empty();
  if (!f.fits) {
    f.reason = "does not fit: ";
    for (std::size_t i = 0; i < reasons.size(); ++i) f.reason += (i ? "; " : "") + reasons[i];
  }
  return f;
}

namespace {

// One candidate's simulated figures, as bytes: it may be run on another MPI rank.
std::string simulate_candidate(const Vehicle& vehicle, const VehicleModel& base, const TyreSpec& tyre,
                               const DriveCycle& cycle, double wheel_load_n, const CompareOptions& o) {
  CandidateResult c;
  try {
    const RollingResistance rr = evaluate_rolling_resistance(tyre.state, wheel_load_n, o.reference_speed_mps);
    c.rrc_80 = rr.rrc;
    c.rr_power_80_w = rr.rr_power_w;
    Vehicle v = vehicle;
    fit_tyres(v, tyre);
    const EnergyFigure e = run_model(VehicleModel::with_tyres_of(base, v), cycle, o.replay);
    c.value = e.value;
    c.range_km = e.range_km;
    c.trace = e.trace;
    c.overcharge = e.overcharge;
    c.simulated = true;
  } catch (const std::exception& e) {
    // An overloaded tyre may have no solution at all; it is reported, not ranked.
    c.error = e.what();
    c.rrc_80 = c.rr_power_80_w = NAN;
    c.value = c.range_km = NAN;
  }
  std::string bytes;
  for (double x : {c.rrc_80, c.rr_power_80_w, c.value, c.range_km}) put(bytes, x);
  put(bytes, c.simulated);
  put(bytes, c.trace);
  put(bytes, c.overcharge);
  put(bytes, c.error);
  return bytes;
}

CandidateResult evaluated(const Vehicle& vehicle, const TyreSpec& own, const TyreSpec& tyre, std::string_view in,
                          const CompareOptions& o) {
  CandidateResult c;
  c.tyre = tyre;
  c.fit = check_fit(vehicle, own, tyre, o.diameter_tolerance_pct);
  for (double* x : {&c.rrc_80, &c.rr_power_80_w, &c.value, &c.range_km}) take(in, *x);
  take(in, c.simulated);
  take(in, c.trace);
  take(in, c.overcharge);
  take(in, c.error);
  return c;
}

// The file a tyre came from, as one path whatever way it was named (shipped name, relative or absolute path).
std::string same_file_key(const std::string& source) {
  std::error_code ec;
  const auto p = std::filesystem::weakly_canonical(source, ec);
  return ec ? source : p.string();
}

}  // namespace

std::vector<TyreSpec> without_duplicate_files(const Vehicle& vehicle, const std::vector<TyreSpec>& candidates,
                                              std::vector<std::string>& left_out) {
  std::vector<TyreSpec> kept;
  std::set<std::string> seen;
  const std::string own = vehicle.front_tyre ? same_file_key(vehicle.front_tyre->source) : std::string();
  if (!own.empty()) seen.insert(own);
  for (const auto& t : candidates) {
    if (t.source.empty() || t.source == "command line" || seen.insert(same_file_key(t.source)).second) {
      kept.push_back(t);
      continue;
    }
    left_out.push_back(t.source + (same_file_key(t.source) == own ? " is the car's own tyre, ranked as (own)" : " is already a candidate"));
  }
  return kept;
}

Comparison compare_tyres(const Vehicle& vehicle, const std::vector<TyreSpec>& candidates, const DriveCycle& cycle,
                         const CompareOptions& o) {
  if (!vehicle.front_tyre) {
    throw InputError(vehicle.source, "the car has no tyres of its own (coast-down road load): nothing to compare with");
  }
  require_distance(cycle);
  require_one_tyre_set(vehicle, "compare");
  const TyreSpec& own = *vehicle.front_tyre;
  Comparison cmp;
  cmp.vehicle = vehicle.name;
  cmp.cycle = cycle.name;
  cmp.unit = energy_unit(vehicle);
  cmp.shows_range = cmp.unit == "kwh_per_10km";

  // Case 0 is the car's own tyre, case k the k-th candidate.
  const VehicleModel base = VehicleModel::assemble(vehicle);
  const double wheel_load_n = check_fit(vehicle, own, own, o.diameter_tolerance_pct).wheel_load_n;
  cmp.wheel_load_n = wheel_load_n;
  auto tyre_of = [&](std::size_t k) -> const TyreSpec& { return k == 0 ? own : candidates[k - 1]; };
  const auto results = map_cases(
      o.map_cases, candidates.size() + 1, o.threads,
      [&](std::size_t k) { return simulate_candidate(vehicle, base, tyre_of(k), cycle, wheel_load_n, o); }, {});

  CandidateResult own_result = evaluated(vehicle, own, own, results[0], o);
  if (!own_result.simulated) throw InputError(vehicle.source, "cannot run the car on its own tyre: " + own_result.error);
  own_result.is_own = true;
  cmp.own_value = own_result.value;
  cmp.own_range_km = own_result.range_km;

  std::vector<CandidateResult> all{own_result};
  for (std::size_t k = 1; k <= candidates.size(); ++k) all.push_back(evaluated(vehicle, own, tyre_of(k), results[k], o));
  for (auto& c : all) {
    c.diff_pct = (c.value / cmp.own_value - 1.0) * 100.0;
    c.range_change_km = c.range_km - cmp.own_range_km;
    // The car's own tyre is the reference of every difference, but it is ranked only if it fits as a candidate
    // must: an own tyre overloaded at its pressure was ranked beside the tyres that fit while a candidate that
    // carried more was not (outside testing, session 20).
    const bool rankable = c.simulated && c.fit.fits;
    // A tyre the model has no solution for at the car's load says so, beside any fit check it fails (the reason
    // named only the capacity and diameter, and its figures read NaN: session 22's outside testing).
    if (!c.simulated) {
      c.fit.reason = (c.fit.fits ? "does not fit: " : c.fit.reason + "; ") + c.error;
      c.fit.fits = false;
    }
    (rankable ? cmp.ranked : cmp.unfit).push_back(c);
  }
  std::stable_sort(cmp.ranked.begin(), cmp.ranked.end(),
                   [](const CandidateResult& a, const CandidateResult& b) { return a.value < b.value; });
  return cmp;
}

}  // namespace rollsim::selection
