// Sweeps of tyre parameters: the tyre model point by point, or the car on a cycle on every core.
#include "rollsim/selection/sweep.hpp"


#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <sstream>
#include <utility>

#include "rollsim/common/error.hpp"
#include "rollsim/common/parallel.hpp"
#include "rollsim/common/units.hpp"
#include "rollsim/common/yaml_reader.hpp"
#include "rollsim/report/simulation_report.hpp"
#include "rollsim/report/table.hpp"
#include "rollsim/selection/common.hpp"
#include "rollsim/tyre/tyre_request.hpp"

namespace rollsim::selection {

std::optional<SweepParam> parse_sweep_param(const std::string& t) {
  if (t == "pressure") return SweepParam::Pressure;
  if (t == "diameter") return SweepParam::Diameter;
  if (t == "width") return SweepParam::Width;
  if (t == "load") return SweepParam::Load;
  if (t == "load-pct") return SweepParam::LoadPct;
  if (t == "speed") return SweepParam::Speed;
  return std::nullopt;
}

std::string sweep_param_key(SweepParam p) {
  switch (p) {
    case SweepParam::Pressure: return "pressure";
    case SweepParam::Diameter: return "diameter";
    case SweepParam::Width: return "width";
    case SweepParam::Load: return "load";
    case SweepParam::LoadPct: return "load-pct";
    case SweepParam::Speed: return "speed";
  }
  return "";
}

std::string sweep_param_unit(SweepParam p) {
  switch (p) {
    case SweepParam::Pressure: return "bar";
    case SweepParam::Diameter: return "mm";
    case SweepParam::Width: return "mm";
    case SweepParam::Load: return "N";
    case SweepParam::LoadPct: return "pct";
    case SweepParam::Speed: return "kmh";
  }
  return "";
}

namespace {

// The largest value a tyre file or `rollsim tyre` accepts for each quantity, in the sweep's units.
double sweep_param_max(SweepParam p) {
  switch (p) {
    case SweepParam::Pressure: return 20.0;     // pressure_bar, --pressure-bar
    case SweepParam::Diameter: return 3000.0;   // outer_radius_m 1.5
    case SweepParam::Width: return 1000.0;      // section_width_m 1.0
    case SweepParam::Load: return 1e6;          // --load-n
    case SweepParam::LoadPct: return 300.0;     // --load-pct
    case SweepParam::Speed: return 500.0;       // --speed-kmh
  }
  return 0.0;
}

}  // namespace

std::vector<double> SweepAxis::values() const {
  std::vector<double> v;
  for (int i = 0; i < steps; ++i) {
    const double x = i + 1 == steps ? to : from + (to - from) * i / (steps - 1);
    // To 12 significant digits, the grid the user asked for: 1.9 + 0.2 x 1 is 2.0999999999999996, which the CSV
    // printed as the swept value (session 21).
    char text[32];
    std::snprintf(text, sizeof text, "%.12g", x);
    v.push_back(std::strtod(text, nullptr));
  }
  return v;
}

void check_axis(const SweepAxis& a, const std::string& option) {
  if (a.steps < 2) throw InputError(option, "--steps " + std::to_string(a.steps) + " is not allowed: must be >= 2");
  if (!std::isfinite(a.from) || !std::isfinite(a.to)) throw InputError(option, "--from/--to must be finite numbers");
  if (a.from == a.to) {
    throw InputError(option, "empty range: --from " + format_value(a.from) + " equals --to " + format_value(a.to));
  }
  if (a.from > a.to) {
    throw InputError(option, "reversed range: --from " + format_value(a.from) + " is above --to " +
                                 format_value(a.to) + " (sweeps run upwards; swap them)");
  }
  // Lower limits of each quantity's physical meaning; upper ones those a tyre file and `rollsim tyre` take, within
  // which the model's own domain is found as we go. A speed of 0 is a valid point (RRC 0); every other quantity
  // must be positive.
  const bool open = a.param != SweepParam::Speed;
  if (open ? !(a.from > 0.0) : !(a.from >= 0.0)) {
    throw InputError(option, "--from " + format_value(a.from) + " " + sweep_param_unit(a.param) + " is not allowed: " +
                                 sweep_param_key(a.param) + (open ? " must be > 0" : " must be >= 0"));
  }
  const double most = sweep_param_max(a.param);
  if (a.to > most) {
    throw InputError(option, "--to " + format_value(a.to) + " " + sweep_param_unit(a.param) + " is not allowed: " +
                                 sweep_param_key(a.param) + " must be <= " + format_value(most) + " (as a tyre file or "
                                 "rollsim tyre takes it)" +
                                 (a.param == SweepParam::Pressure  // 150-300 typed in kPa (session 20)
                                      ? unit_slip_hint(a.to, Range::closed(1.0, 10.0), "bar", {{"kPa", 0.01}, {"psi", 6894.757e-5}})
                                      : std::string()));
  }
}

TyreSpec with_parameter(const TyreSpec& tyre, SweepParam p, double value) {
  TyreSpec t = tyre;
  switch (p) {
    case SweepParam::Pressure: t.state.pressure_pa = units::bar_to_pa(value); break;
    case SweepParam::Diameter: {
      TyreGeometry g = t.state.geometry;
      g.outer_radius_m = value * units::kMPerMm / 2.0;
      t.state = with_geometry(t.state, g);
      break;
    }
    case SweepParam::Width: {
      TyreGeometry g = t.state.geometry;
      g.section_width_m = value * units::kMPerMm;
      t.state = with_geometry(t.state, g);
      break;
    }
    default: break;
  }
  return t;
}

namespace {

// The grid's points in output order (first axis outer, last axis fastest), checked against the limit before
// anything is allocated: a grid is the product of its axes' steps, and 10^6 x 10^6 would not fit in memory.
std::vector<std::vector<double>> grid(const std::vector<SweepAxis>& axes, std::size_t max_points, const char* what) {
  std::size_t n = 1;
  std::string sizes;
  for (const auto& a : axes) {
    const auto steps = static_cast<std::size_t>(std::max(a.steps, 1));
    n = n > max_points / steps ? max_points + 1 : n * steps;
    sizes += (sizes.empty() ? "" : " x ") + std::to_string(a.steps);
  }
  if (n > max_points) {
    throw InputError("--steps", sizes + " points is more than the " + std::to_string(max_points) + " allowed for " + what +
                                    "; use fewer --steps or a narrower --from/--to");
  }
  std::vector<std::vector<double>> pts{{}};
  for (const auto& a : axes) {
    std::vector<std::vector<double>> next;
    next.reserve(pts.size() * static_cast<std::size_t>(a.steps));
    const auto values = a.values();
    for (const auto& p : pts) {
      for (double v : values) {
        auto q = p;
        q.push_back(v);
        next.push_back(std::move(q));
      }
    }
    pts = std::move(next);
  }
  return pts;
}

std::string describe_point(const std::vector<SweepAxis>& axes, const std::vector<double>& values) {
  std::string s;
  for (std::size_t i = 0; i < axes.size(); ++i) {
    s += (i ? ", " : "") + sweep_param_key(axes[i].param) + " = " + format_value(values[i]) + " " +
         sweep_param_unit(axes[i].param);
  }
  return s;
}

// The tyre and operating point of one grid point.
struct PointSetup {
  TyreSpec tyre;
  double load_n = 0.0;
  double speed_kmh = 0.0;
};

double default_load_n(const TyreSpec& tyre, const SweepOptions& o) {
  if (o.load_n) return *o.load_n;
  return 0.8 * tyre.max_load_n;
}

PointSetup setup(const TyreSpec& tyre, const SweepOptions& o, const std::vector<double>& values) {
  PointSetup s{tyre, default_load_n(tyre, o), o.speed_kmh};
  for (std::size_t i = 0; i < o.axes.size(); ++i) {
    const SweepParam p = o.axes[i].param;
    if (p == SweepParam::Load) s.load_n = values[i];
    else if (p == SweepParam::LoadPct) s.load_n = values[i] / 100.0 * tyre.max_load_n;
    else if (p == SweepParam::Speed) s.speed_kmh = values[i];
    else s.tyre = with_parameter(s.tyre, p, values[i]);
  }
  return s;
}

void check_options(const TyreSpec& tyre, const SweepOptions& o) {
  if (o.axes.empty() || o.axes.size() > 2) throw InputError("--param", "give one or two parameters to sweep");
  if (o.axes.size() == 2 && o.axes[0].param == o.axes[1].param) {
    throw InputError("--param " + sweep_param_key(o.axes[1].param), "the same parameter cannot be swept twice");
  }
  bool load_swept = false;
  for (std::size_t i = 0; i < o.axes.size(); ++i) {
    const SweepParam p = o.axes[i].param;
    if (p == SweepParam::Load || p == SweepParam::LoadPct) {
      if (load_swept) throw InputError("--param", "load and load-pct cannot both be swept");
      load_swept = true;
    }
    if (p == SweepParam::Pressure) {
      check_pressure_plausible(o.axes[i].from, tyre.size, "--param pressure --from");
      check_pressure_plausible(o.axes[i].to, tyre.size, "--param pressure --to");
    }
    // In mm, the tyre file's ranges for a road tyre: a width of 0.165 (metres) ran a 0.165 mm tyre, +17 % energy,
    // where the pressure's unit slips were already refused (session 24's outside testing).
    if (p == SweepParam::Width || p == SweepParam::Diameter) {
      const bool width = p == SweepParam::Width;
      const Range road_tyre_mm = width ? Range::closed(kRoadTyreWidthMin_m * 1e3, kRoadTyreWidthMax_m * 1e3)
                                       : Range::closed(kRoadTyreDiameterMin_m * 1e3, kRoadTyreDiameterMax_m * 1e3);
      const std::string key = "--param " + sweep_param_key(p);
      for (const auto& [v, end] : {std::pair{o.axes[i].from, " --from"}, std::pair{o.axes[i].to, " --to"}})
        check_physical(v, road_tyre_mm, "mm", "no road tyre measures that", {{"m", 1e3}, {"cm", 10.0}, {"inches", 25.4}},
                       key + end);
    }
    if (p == SweepParam::LoadPct && !(tyre.max_load_n > 0.0)) {
      throw InputError("--param load-pct", "the tyre's maximum load is unknown (no load index): sweep 'load' in N");
    }
  }
  if (!load_swept && !o.load_n && !(tyre.max_load_n > 0.0)) {
    throw InputError("--load-n", "missing: the tyre's maximum load is unknown, so the default 80 % of it cannot be "
                                 "used; give --load-n N");
  }
}

// Points outside the model's domain are left out and counted, the first one said. A sweep stopped at its first
// such point until session 22, which is right only for an axis that leaves the domain as it rises (load): a pressure,
// diameter or width range leaves it as it falls, so a range starting at 1 bar wrote nothing ("no valid point") and a
// pressure x load grid lost every row after the corner where 1 bar met the heaviest load.
struct OutsideDomain {
  std::size_t count = 0;
  std::string first;
  void add(const std::vector<SweepAxis>& axes, const std::vector<double>& at, const std::string& why) {
    if (count++ == 0) first = describe_point(axes, at) + ": " + why;
  }
  std::optional<std::string> message(std::size_t planned) const {
    if (count == 0) return std::nullopt;
    return std::to_string(count) + " of " + std::to_string(planned) + " points are outside the model's domain and were "
           "left out; the first, at " + first;
  }
};

}  // namespace

SweepResult sweep_tyre(const TyreSpec& tyre, const SweepOptions& o) {
  check_options(tyre, o);
  SweepResult r;
  r.axes = o.axes;
  r.max_load_n = tyre.max_load_n;
  const auto pts = grid(o.axes, kMaxTyreSweepPoints, "a tyre sweep");
  r.planned_points = pts.size();
  r.points.reserve(pts.size());
  OutsideDomain outside;
  for (const auto& values : pts) {
    const PointSetup s = setup(tyre, o, values);
    try {
      SweepPoint p;
      p.values = values;
      p.load_n = s.load_n;
      p.speed_kmh = s.speed_kmh;
      p.rr = evaluate_rolling_resistance(s.tyre.state, s.load_n, units::kmh_to_mps(s.speed_kmh));
      r.points.push_back(p);
    } catch (const ModelDomainError& e) {
      outside.add(o.axes, values, e.what());
    }
    if (o.progress) o.progress(r.points.size() + outside.count, pts.size());
  }
  r.outside_domain = outside.message(pts.size());
  return r;
}

SweepResult sweep_vehicle(const Vehicle& vehicle, const TyreSpec& tyre, const DriveCycle& cycle,
                          const SweepOptions& given) {
  // The tyre's own columns at the car's heavier static wheel load, as compare and sensitivity take it, unless a
  // load is given: beside the car's figure, a tyre at another load would be another operating point.
  SweepOptions o = given;
  if (!o.load_n) {
    const AxleWheelLoads w = wheel_loads(vehicle.body, 0.0);
    o.load_n = std::max(w.front_n, w.rear_n);
  }
  check_options(tyre, o);
  require_distance(cycle);
  for (const auto& a : o.axes) {
    if (a.param != SweepParam::Pressure && a.param != SweepParam::Diameter && a.param != SweepParam::Width) {
      throw InputError("--param " + sweep_param_key(a.param),
                       "not allowed with --vehicle: the car's wheel loads and speeds come from the car and the "
                       "cycle; sweep pressure, diameter or width");
    }
  }
  SweepResult r;
  r.axes = o.axes;
  r.vehicle = true;
  r.max_load_n = tyre.max_load_n;
  r.energy_unit = energy_unit(vehicle);
  const auto pts = grid(o.axes, kMaxVehicleSweepPoints, "a sweep with a car (one simulation per point)");
  r.planned_points = pts.size();

  // The car is assembled once; each point makes only its tyre-dependent parts (VehicleModel::with_tyres_of).
  const VehicleModel base = VehicleModel::assemble(vehicle);
  // Each point's result travels as bytes (it may be computed on another MPI rank) and keeps its index, so the
  // output is in grid order whatever order the points finish in.
  const auto body = [&](std::size_t i) {
    const PointSetup ps = setup(tyre, o, pts[i]);
    SweepPoint p;
    std::string error;
    try {
      p.rr = evaluate_rolling_resistance(ps.tyre.state, ps.load_n, units::kmh_to_mps(ps.speed_kmh));
      Vehicle v = vehicle;
      fit_tyres(v, ps.tyre);
      const EnergyFigure e = run_model(VehicleModel::with_tyres_of(base, v), cycle, o.replay);
      p.energy = e.value;
      p.trace = e.trace;
      p.overcharge = e.overcharge;
    } catch (const std::exception& e) {
      error = e.what();
    }
    std::string bytes;
    put(bytes, p.rr);
    put(bytes, p.energy);
    put(bytes, p.trace);
    put(bytes, p.overcharge);
    put(bytes, error);
    return bytes;
  };
  const auto results = map_cases(o.map_cases, pts.size(), o.threads, body, o.progress);
  OutsideDomain outside;
  for (std::size_t i = 0; i < pts.size(); ++i) {
    const PointSetup ps = setup(tyre, o, pts[i]);
    SweepPoint p{pts[i], ps.load_n, ps.speed_kmh, {}, 0.0, {}};
    std::string error;
    std::string_view in = results[i];
    take(in, p.rr);
    take(in, p.energy);
    take(in, p.trace);
    take(in, p.overcharge);
    take(in, error);
    if (!error.empty()) {
      outside.add(o.axes, pts[i], error);
      continue;
    }
    r.points.push_back(std::move(p));
  }
  r.outside_domain = outside.message(pts.size());
  return r;
}

std::vector<std::pair<std::string, double>> sweep_point_columns(const SweepResult& r, const SweepPoint& p) {
  // A load or speed axis is the evaluated load or speed itself (load-pct is not: its column is the share).
  auto column = [](SweepParam a) {
    return a == SweepParam::Load ? std::string("load_n") : a == SweepParam::LoadPct ? std::string("load_pct")
                                                                                     : sweep_param_key(a) + "_" + sweep_param_unit(a);
  };
  std::vector<std::pair<std::string, double>> out;
  bool load_axis = false, speed_axis = false;
  for (std::size_t i = 0; i < r.axes.size(); ++i) {
    out.emplace_back(column(r.axes[i].param), p.values[i]);
    load_axis = load_axis || r.axes[i].param == SweepParam::Load;
    speed_axis = speed_axis || r.axes[i].param == SweepParam::Speed;
  }
  if (!load_axis) out.emplace_back("load_n", p.load_n);
  if (!speed_axis) out.emplace_back("speed_kmh", p.speed_kmh);
  return out;
}

std::vector<std::string> sweep_warnings(const SweepResult& r) {
  std::size_t over = 0, overcharged = 0, behind = 0;
  double heaviest_n = 0.0;
  std::string first_overcharge;
  TraceFollowing worst;
  for (const auto& p : r.points) {
    over += r.max_load_n > 0.0 && p.load_n > r.max_load_n ? 1 : 0;
    heaviest_n = std::max(heaviest_n, p.load_n);
    if (!p.overcharge.empty() && overcharged++ == 0) first_overcharge = p.overcharge;
    behind += p.trace.followed ? 0 : 1;
    worst.max_deficit_mps = std::max(worst.max_deficit_mps, p.trace.max_deficit_mps);
  }
  const std::string of = " of " + std::to_string(r.points.size()) + " points ";
  std::vector<std::string> out;
  // A load typed in kg (session 24's outside testing: `--load-n 400` swept an RRC of 0.032 without a word).
  double lightest_n = heaviest_n;
  for (const auto& p : r.points) lightest_n = std::min(lightest_n, p.load_n);
  if (std::string kg = load_in_kg_hint(lightest_n, r.max_load_n); !kg.empty()) out.push_back(std::move(kg));
  if (over > 0) {
    out.push_back("at " + std::to_string(over) + of + "the load (up to " + fixed(heaviest_n, 0) +
                  " N) is above the tyre's rated maximum " + fixed(r.max_load_n, 0) +
                  " N; results there are outside the tyre's rating");
  }
  if (overcharged > 0) {
    out.push_back("at " + std::to_string(overcharged) + of + "the battery charged past full; at the first: " +
                  first_overcharge);
  }
  if (behind > 0) out.push_back("at " + std::to_string(behind) + of + "(followed_trace no): " + report::shortfall_caveat(worst));
  return out;
}

std::string sweep_csv(const SweepResult& r) {
  std::ostringstream out;
  SweepPoint names_only;  // the header needs no point: a sweep with no valid point still has one
  names_only.values.resize(r.axes.size());
  for (const auto& [name, value] : sweep_point_columns(r, names_only)) out << name << ",";
  out << "rrc,rr_force_n,rr_power_w,deflection_m";
  if (r.vehicle) out << "," << r.energy_unit << ",followed_trace";
  out << "\n";
  for (const auto& p : r.points) {
    // Axis values as the user gave them; a derived load or speed (the car's wheel load) to the table's precision.
    const auto columns = sweep_point_columns(r, p);
    for (std::size_t i = 0; i < columns.size(); ++i)
      out << (i < r.axes.size() ? format_value(columns[i].second) : significant(columns[i].second, 7)) << ",";
    out << fixed(p.rr.rrc, 7) << "," << fixed(p.rr.rr_force_n, 4) << "," << fixed(p.rr.rr_power_w, 3) << ","
        << fixed(p.rr.deflection_m, 6);
    if (r.vehicle) out << "," << fixed(p.energy, 5) << "," << (p.trace.followed ? "yes" : "no");
    out << "\n";
  }
  return out.str();
}

}  // namespace rollsim::selection
