// Elasticities of RR power (from explain_tyre) and of a car's energy or fuel (forward simulations at +-1 %).
#include "rollsim/selection/sensitivity.hpp"

#include <cmath>

#include "rollsim/common/error.hpp"
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

Sensitivity tyre_sensitivity(const TyreSpec& tyre, double load_n, double speed_mps, double h) {
  const TyreExplanation x = explain_tyre(tyre.state, load_n, speed_mps, h);
  Sensitivity s;
  s.tyre = tyre.name;
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
  const EnergyFigure at_base = run_forward(base, cycle);
  s.energy = at_base.value;
  s.followed_trace = at_base.trace.followed;
  for (auto& row : s.rows) {
    double y[2];
    const double f[2] = {1.0 + h, 1.0 - h};
    for (int k = 0; k < 2; ++k) {
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
  }
  s.dominant_energy = dominant(s.rows, true);
  return s;
}

}  // namespace rollsim::selection
