// Elasticities of RR power (from explain_tyre) and of a car's energy or fuel (forward simulations at +-1 %).
#include "rollsim/selection/sensitivity.hpp"

#include <cmath>

#include "rollsim/common/error.hpp"
#include "rollsim/common/units.hpp"
#include "rollsim/selection/common.hpp"

namespace rollsim::selection {

namespace {

std::string dominant(const std::vector<SensitivityRow>& rows, bool energy) {
  const SensitivityRow* best = nullptr;
  double best_abs = -1.0;
  for (const auto& r : rows) {
    const double e = std::abs(energy ? r.energy_elasticity.value_or(0.0) : r.power_elasticity);
    if (e > best_abs) best_abs = e, best = &r;
  }
  return best ? best->name : "";
}

}  // namespace

bool elasticities_agree(double at_step, double at_double_step) {
  constexpr double kScatter = 2e-3, kCurvature = 0.1;
  return std::abs(at_step - at_double_step) <= kScatter + kCurvature * std::abs(at_step);
}

ParameterValue parameter_value_in_file_units(const SensitivityRow& r) {
  switch (r.parameter) {
    case TyreParameter::OuterDiameter: return {r.key + "_mm", r.value_si * 1e3, "mm", 1};
    case TyreParameter::SectionWidth: return {r.key + "_mm", r.value_si * 1e3, "mm", 1};
    case TyreParameter::Pressure: return {r.key + "_bar", units::pa_to_bar(r.value_si), "bar", 2};
    case TyreParameter::Load: return {r.key + "_n", r.value_si, "N", 0};
    case TyreParameter::Speed: return {r.key + "_kmh", units::mps_to_kmh(r.value_si), "km/h", 1};
  }
  return {};
}

Sensitivity tyre_sensitivity(const TyreSpec& tyre, double load_n, double speed_mps, double h) {
  const TyreExplanation x = explain_tyre(tyre.state, load_n, speed_mps, h);
  Sensitivity s;
  s.tyre = tyre.name;
  s.max_load_n = tyre.max_load_n;
  s.load_n = load_n;
  s.speed_mps = speed_mps;
  s.relative_step = h;
  s.rr_power_w = x.at_point.rr_power_w;
  for (const auto& p : x.parameters) {
    if (p.parameter == TyreParameter::Speed) continue;  // a car's speeds are the cycle's, not a tyre choice
    s.rows.push_back({p.parameter, p.name, p.key, p.value_si, p.rrc_elasticity, p.power_elasticity, std::nullopt});
  }
  s.dominant_power = dominant(s.rows, false);
  return s;
}

Sensitivity vehicle_sensitivity(const Vehicle& vehicle, const TyreSpec& tyre, const DriveCycle& cycle, double load_n,
                                double speed_mps, double h) {
  Sensitivity s = tyre_sensitivity(tyre, load_n, speed_mps, h);
  s.vehicle = vehicle.name;
  s.cycle = cycle.name;
  s.energy_unit = energy_unit(vehicle);
  Vehicle base = vehicle;
  fit_tyres(base, tyre);
  s.vehicle_warnings = check_tyre_loads(base, "--tyre '" + tyre.source + "'", false);
  const EnergyFigure at_base = run_forward(base, cycle);
  s.energy = at_base.value;
  s.followed_trace = at_base.trace.followed;
  for (auto& row : s.rows) {
    double y[4];
    const double f[4] = {1.0 + h, 1.0 - h, 1.0 + 2.0 * h, 1.0 - 2.0 * h};
    for (int k = 0; k < 4; ++k) {
      Vehicle v = vehicle;
      TyreSpec t = tyre;
      switch (row.parameter) {
        case TyreParameter::OuterDiameter:
        case TyreParameter::SectionWidth: {
          TyreGeometry g = t.state.geometry;
          (row.parameter == TyreParameter::OuterDiameter ? g.outer_radius_m : g.section_width_m) *= f[k];
          t.state = with_geometry(t.state, g);
          break;
        }
        case TyreParameter::Pressure: t.state.pressure_pa *= f[k]; break;
        case TyreParameter::Load: v.body.test_mass_kg *= f[k]; break;  // every wheel load scales with mass
        case TyreParameter::Speed: break;
      }
      fit_tyres(v, t);
      const EnergyFigure e = run_forward(v, cycle);
      y[k] = e.value;
      s.followed_trace = s.followed_trace && e.trace.followed;
    }
    // d ln y / d ln x by central differences in ln x, consistent with explain_tyre.
    row.energy_elasticity = std::log(y[0] / y[1]) / std::log(f[0] / f[1]);
    row.energy_elasticity_double_step = std::log(y[2] / y[3]) / std::log(f[2] / f[3]);
    row.energy_smooth = elasticities_agree(*row.energy_elasticity, *row.energy_elasticity_double_step);
  }
  s.dominant_energy = dominant(s.rows, true);
  return s;
}

}  // namespace rollsim::selection
