// `rollsim sensitivity`: elasticities of RR power and of a car's energy or fuel per tyre parameter.
#include <algorithm>
#include <cmath>
#include <iostream>
#include <memory>
#include <string>

#include "commands.hpp"
#include "rollsim/common/units.hpp"
#include "rollsim/report/table.hpp"
#include "rollsim/selection/common.hpp"
#include "rollsim/selection/front_end.hpp"
#include "rollsim/selection/sensitivity.hpp"
#include "selection_cli.hpp"

namespace rollsim::cli {
namespace {

struct SensitivityOptionsText {
  std::string tyre, vehicle, cycle, load_n, speed_kmh = "80";  // cycle: empty for nedc
  bool json = false;
};

std::string value_text(const selection::SensitivityRow& r) {
  const selection::ParameterValue v = selection::parameter_value_in_file_units(r);
  return fixed(v.value, v.decimals) + " " + v.unit;
}

void run_sensitivity(const SensitivityOptionsText& o) {
  if (o.tyre.empty() && o.vehicle.empty()) throw InputError("--tyre", "missing: give a tyre and/or --vehicle");
  if (!o.cycle.empty() && o.vehicle.empty()) throw InputError("--cycle", "needs --vehicle: a tyre alone drives no cycle");
  const double speed_mps =
      units::kmh_to_mps(parse_option_number(o.speed_kmh, "--speed-kmh", Range::open_low(0.0, 500.0)));
  std::optional<Vehicle> vehicle;
  if (!o.vehicle.empty()) vehicle = load_vehicle_file(resolve_data_file(o.vehicle, "vehicles", ".yaml", "--vehicle"));
  if (vehicle) warn_if_coastdown(*vehicle, "the car's energy and fuel elasticities");
  std::optional<TyreSpec> tyre;
  if (!o.tyre.empty()) tyre = load_tyre_file(resolve_data_file(o.tyre, "tyres", ".yaml", "--tyre"));
  std::optional<double> load_n;
  if (!o.load_n.empty()) load_n = parse_option_number(o.load_n, "--load-n", Range::open_low(0.0, 1e6));
  const DriveCycle cycle = vehicle ? load_cycle_noted(o.cycle.empty() ? "nedc" : o.cycle, "--cycle") : DriveCycle{};
  const selection::Sensitivity s = selection::sensitivity_of(vehicle, tyre, cycle, load_n, speed_mps);

  if (o.json) {
    std::cout << selection::sensitivity_json(s).str() << "\n";
    for (const auto& w : selection::sensitivity_warnings(s)) std::cerr << "warning: " << w << "\n";
    return;
  }
  std::cout << "Sensitivity of tyre " << s.tyre << " at " << fixed(s.load_n, 0) << " N, "
            << fixed(units::mps_to_kmh(s.speed_mps), 0) << " km/h (RR power " << fixed(s.rr_power_w, 1)
            << " W)";
  if (vehicle) {
    std::cout << "; " << s.vehicle << " on " << s.cycle << ": " << fixed(s.energy, 4) << " "
              << selection::energy_unit_label(s.energy_unit);
  }
  std::cout << "\nElasticities: % change of the output per % change of the parameter (central differences +-"
            << format_value(s.relative_step * 100) << " %)\n";
  std::vector<std::string> h{"parameter", "value", "RR power", "RRC"};
  if (vehicle) h.push_back(s.energy_unit == "kwh_per_10km" ? "car energy" : "car fuel");
  report::TextTable t(h);
  t.set_left_aligned(0);
  for (const auto& r : s.rows) {
    std::vector<std::string> cells{r.name, value_text(r), fixed(r.power_elasticity, 3),
                                   fixed(r.rrc_elasticity, 3)};
    if (vehicle) cells.push_back(fixed(*r.energy_elasticity, 4) + (r.energy_smooth ? "" : " *"));
    t.add_row(cells);
  }
  std::cout << t.render();
  std::cout << "Matters most for RR power: " << s.dominant_power;
  if (vehicle) std::cout << "; for the car's " << (s.energy_unit == "kwh_per_10km" ? "energy" : "fuel") << ": " << s.dominant_energy;
  std::cout << "\n";
  if (vehicle) {
    std::cout << "(car: load = test mass, all wheel loads scaled together; diameter also changes the gearing)\n";
    // The car runs at its own wheel loads whatever --load-n says, which the load row did not tell (session 24).
    const AxleWheelLoads w = wheel_loads(vehicle->body, 0.0);
    const double car_n = std::max(w.front_n, w.rear_n);
    if (std::abs(s.load_n / car_n - 1.0) > 0.005)
      std::cout << "(the car column is at the car's own wheel loads, heaviest " << fixed(car_n, 0) << " N; the tyre columns at "
                << fixed(s.load_n, 0) << " N)\n";
  }
  for (const auto& w : selection::sensitivity_warnings(s)) std::cout << "WARNING: " << w << "\n";
}

}  // namespace

void register_sensitivity_command(CLI::App& app) {
  auto o = std::make_shared<SensitivityOptionsText>();
  CLI::App* sub = app.add_subcommand("sensitivity", "Elasticities of RR power and of a car's energy/fuel per tyre parameter");
  sub->add_option("--tyre", o->tyre, "Tyre file or shipped name (default: the car's own tyre)")->type_name("FILE");
  sub->add_option("--vehicle", o->vehicle, "Also the car's energy/fuel elasticities on --cycle")->type_name("FILE");
  sub->add_option("--cycle", o->cycle, "Drive cycle (default nedc)")->type_name("CYCLE");
  sub->add_option("--load-n", o->load_n, "Normal load per tyre [N] (default: the car's heaviest wheel load, or 80 % of "
                                         "the tyre's maximum load)")
      ->type_name("N");
  sub->add_option("--speed-kmh", o->speed_kmh, "Speed for the RR power elasticities [km/h] (default 80)")->type_name("KMH");
  sub->add_flag("--json", o->json, "One JSON object");
  sub->callback([o] { run_sensitivity(*o); });
}

}  // namespace rollsim::cli
