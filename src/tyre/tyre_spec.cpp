#include "rollsim/tyre/tyre_spec.hpp"

#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <filesystem>
#include <initializer_list>
#include <string>
#include <utility>
#include <vector>

#include "rollsim/common/error.hpp"
#include "rollsim/common/text.hpp"
#include "rollsim/common/format.hpp"
#include "rollsim/common/units.hpp"
#include "rollsim/common/yaml_reader.hpp"

namespace rollsim {
namespace {

// ETRTO / ISO 4000-1 load-index table: maximum load per tyre [kg] at the reference pressure, indices 0..150.
// Typed from the published standard table (the values are rounded, hence not an exact geometric series).
constexpr int kFirstLoadIndex = 0;
constexpr std::array<double, 151> kLoadIndexKg = {
    45,   46.2, 47.5, 48.7, 50,   51.5, 53,   54.5, 56,   58,    // 0-9
    60,   61.5, 63,   65,   67,   69,   71,   73,   75,   77.5,  // 10-19
    80,   82.5, 85,   87.5, 90,   92.5, 95,   97.5, 100,  103,   // 20-29
    106,  109,  112,  115,  118,  121,  125,  128,  132,  136,   // 30-39
    140,  145,  150,  155,  160,  165,  170,  175,  180,  185,   // 40-49
    190,  195,  200,  206,  212,  218,  224,  230,  236,  243,   // 50-59
    250,  257,  265,  272,  280,  290,  300,  307,  315,  325,   // 60-69
    335,  345,  355,  365,  375,  387,  400,  412,  425,  437,   // 70-79
    450,  462,  475,  487,  500,  515,  530,  545,  560,  580,   // 80-89
    600,  615,  630,  650,  670,  690,  710,  730,  750,  775,   // 90-99
    800,  825,  850,  875,  900,  925,  950,  975,  1000, 1030,  // 100-109
    1060, 1090, 1120, 1150, 1180, 1215, 1250, 1285, 1320, 1360,  // 110-119
    1400, 1450, 1500, 1550, 1600, 1650, 1700, 1750, 1800, 1850,  // 120-129
    1900, 1950, 2000, 2060, 2120, 2180, 2240, 2300, 2360, 2430,  // 130-139
    2500, 2575, 2650, 2725, 2800, 2900, 3000, 3075, 3150, 3250,  // 140-149
    3350};                                                       // 150
constexpr int kLastLoadIndex = kFirstLoadIndex + static_cast<int>(kLoadIndexKg.size()) - 1;

// Speed symbols of ISO 4000-1 / ETRTO and the speed each rates a tyre for (A1..A8 are for special vehicles and accepted
// too); Z ("above 240 km/h") has no figure of its own.
constexpr std::pair<const char*, double> kRatedKmh[] = {
    {"A1", 5},  {"A2", 10}, {"A3", 15}, {"A4", 20}, {"A5", 25}, {"A6", 30}, {"A7", 35}, {"A8", 40},
    {"B", 50},  {"C", 60},  {"D", 65},  {"E", 70},  {"F", 80},  {"G", 90},  {"J", 100}, {"K", 110},
    {"L", 120}, {"M", 130}, {"N", 140}, {"P", 150}, {"Q", 160}, {"R", 170}, {"S", 180}, {"T", 190},
    {"U", 200}, {"H", 210}, {"V", 240}, {"W", 270}, {"Y", 300}};

std::optional<double> rated_kmh(const std::string& upper_symbol) {
  for (const auto& [name, kmh] : kRatedKmh)
    if (upper_symbol == name) return kmh;
  return std::nullopt;
}

bool is_speed_symbol(const std::string& s) { return s == "Z" || rated_kmh(s).has_value(); }

std::string upper(std::string s) {
  for (auto& c : s) c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
  return s;
}

// A small cursor over the upper-cased designation; each read either consumes what it matched or nothing.
struct Cursor {
  const std::string& s;
  std::size_t i = 0;
  void skip_spaces() {
    while (i < s.size() && (s[i] == ' ' || s[i] == '\t')) ++i;
  }
  bool done() const { return i >= s.size(); }
  bool eat(const std::string& lit) {
    if (s.compare(i, lit.size(), lit) == 0) {
      i += lit.size();
      return true;
    }
    return false;
  }
  std::string digits() {
    const std::size_t start = i;
    while (i < s.size() && std::isdigit(static_cast<unsigned char>(s[i]))) ++i;
    return s.substr(start, i - start);
  }
  std::string number() {  // digits with an optional decimal part ("16.5" LT rims)
    const std::size_t start = i;
    std::string d = digits();
    if (!d.empty() && i + 1 < s.size() && s[i] == '.' && std::isdigit(static_cast<unsigned char>(s[i + 1]))) {
      ++i;
      digits();
    }
    return s.substr(start, i - start);
  }
  std::string word() {  // a run of letters and digits up to the next space
    const std::size_t start = i;
    while (i < s.size() && s[i] != ' ' && s[i] != '\t') ++i;
    return s.substr(start, i - start);
  }
};

// YamlMap's optional readers treat a missing key as present (they return a default YAML::Node, which counts as
// defined), so every optional key is asked through has() first and only marked as known when absent.
std::optional<double> opt_number(YamlMap& y, const std::string& key, Range range) {
  if (!y.has(key)) {
    y.accept(key);
    return std::nullopt;
  }
  return y.optional_number(key, range);
}
std::optional<std::string> opt_string(YamlMap& y, const std::string& key) {
  if (!y.has(key)) {
    y.accept(key);
    return std::nullopt;
  }
  return y.optional_string(key);
}
std::optional<YamlMap> opt_map(YamlMap& y, const std::string& key) {
  if (!y.has(key)) {
    y.accept(key);
    return std::nullopt;
  }
  return y.optional_map(key);
}

// Rejects unknown keys before anything is read, so a misspelt key ("presure_bar") is reported as such rather
// than as the required key it was meant to be.
void reject_unknown_keys(const YamlMap& y, std::initializer_list<const char*> allowed) {
  for (const auto& kv : y.node()) {
    const std::string key = kv.first.as<std::string>();
    bool known = false;
    for (const char* a : allowed) known = known || key == a;
    if (!known) {
      std::string list;
      for (const char* a : allowed) list += (list.empty() ? "" : ", ") + std::string(a);
      throw InputError(y.where(key), "unknown key (misspelt?); allowed here: " + list);
    }
  }
}

TyreModelKind model_kind(const std::string& text, const std::string& where) {
  if (text == "thesis") return TyreModelKind::Thesis;
  if (text == "hysteresis") return TyreModelKind::Hysteresis;
  throw InputError(where, "'" + text + "' is not a model: allowed thesis (the default), hysteresis");
}

// The `model` mapping: `kind` and the constants of that kind. Rhyne's stiffness constants serve both kinds
// (the hysteresis model scales its loss with the deflection they give).
void read_model_map(YamlMap& m, TyreState& state) {
  const char* kThesisOnly[] = {"viscous_damping_ns_per_m", "coulomb_damping_n", "rotational_drag_kg_per_m2", "elements"};
  const char* kHysteresisOnly[] = {"reference_pressure_bar", "reference_load_n", "rrc_ref", "deflection_exponent",
                                   "load_exponent", "frequency_slope_per_hz", "speed_loss_rrc_per_hz2",
                                   "speed_loss_load_exponent"};
  reject_unknown_keys(m, {"kind", "viscous_damping_ns_per_m", "coulomb_damping_n", "rotational_drag_kg_per_m2",
                          "stiffness_pressure_coeff", "stiffness_offset_kgf_per_mm", "elements",
                          "reference_pressure_bar", "reference_load_n", "rrc_ref", "deflection_exponent",
                          "load_exponent", "frequency_slope_per_hz", "speed_loss_rrc_per_hz2",
                          "speed_loss_load_exponent"});
  if (auto kind = opt_string(m, "kind")) state.model = model_kind(*kind, m.where("kind"));
  const bool thesis = state.model == TyreModelKind::Thesis;
  auto reject_other_kind = [&](const char* k) {
    if (m.has(k)) {
      throw InputError(m.where(k), std::string("only for kind ") + (thesis ? "hysteresis" : "thesis") +
                                       "; this model is " + (thesis ? "thesis (the default)" : "hysteresis"));
    }
  };
  if (thesis) {
    for (const char* k : kHysteresisOnly) reject_other_kind(k);
  } else {
    for (const char* k : kThesisOnly) reject_other_kind(k);
  }
  auto& k = state.constants;
  // The stiffness is bounded against the thesis' own (check_stiffness_constants). Each damping is bounded where it
  // alone gives a passenger tyre at 4 kN an RRC of about 0.04 (Coulomb, at any speed), 0.006 (viscous) or 0.013
  // (rotational drag) at 130 km/h, beyond any road tyre's: 5.5, 40 and 11 times the thesis' values. Unbounded,
  // 1e300 printed negative RRCs and a CVODE failure (session 25).
  k.stiffness_pressure_coeff = opt_number(m, "stiffness_pressure_coeff", Range::positive()).value_or(k.stiffness_pressure_coeff);
  k.stiffness_offset_kgf_per_mm =
      opt_number(m, "stiffness_offset_kgf_per_mm", Range::non_negative()).value_or(k.stiffness_offset_kgf_per_mm);
  if (thesis) {
    k.viscous_damping_ns_per_m = opt_number(m, "viscous_damping_ns_per_m", Range::closed(0.0, 20.0)).value_or(k.viscous_damping_ns_per_m);
    k.coulomb_damping_n = opt_number(m, "coulomb_damping_n", Range::closed(0.0, 1000.0)).value_or(k.coulomb_damping_n);
    k.rotational_drag_kg_per_m2 =
        opt_number(m, "rotational_drag_kg_per_m2", Range::closed(0.0, 0.04)).value_or(k.rotational_drag_kg_per_m2);
    if (auto n = opt_number(m, "elements", Range::closed(2, 1e6))) {
      if (*n != std::floor(*n) || static_cast<long>(*n) % 2 != 0) {
        throw InputError(m.where("elements"), format_value(*n) + " is not allowed: must be an even whole number >= 2");
      }
      k.elements = static_cast<int>(*n);
    }
  } else {
    auto& h = state.hysteresis;
    if (!m.has("rrc_ref")) {
      throw InputError(m.where("rrc_ref"), "required key is missing for kind hysteresis (the tyre's RRC level at the "
                                           "reference point; 'rollsim tyre fit' writes it)");
    }
    h.rrc_ref = m.number("rrc_ref", Range::closed(0.001, 0.05));
    h.reference_pressure_pa =
        units::bar_to_pa(opt_number(m, "reference_pressure_bar", Range::closed(0.5, 6.0)).value_or(units::pa_to_bar(h.reference_pressure_pa)));
    h.reference_load_n = opt_number(m, "reference_load_n", Range::open_low(0.0, 1e5)).value_or(h.reference_load_n);
    h.deflection_exponent = opt_number(m, "deflection_exponent", Range::closed(0, 5)).value_or(h.deflection_exponent);
    h.load_exponent = opt_number(m, "load_exponent", Range::closed(-5, 5)).value_or(h.load_exponent);
    h.frequency_slope_per_hz = opt_number(m, "frequency_slope_per_hz", Range::closed(0, 1)).value_or(h.frequency_slope_per_hz);
    h.speed_loss_rrc_per_hz2 =
        opt_number(m, "speed_loss_rrc_per_hz2", Range::closed(0, 1e-3)).value_or(h.speed_loss_rrc_per_hz2);
    h.speed_loss_load_exponent =
        opt_number(m, "speed_loss_load_exponent", Range::closed(-5, 5)).value_or(h.speed_loss_load_exponent);
  }
  m.finish();
}

// Inflation a tyre of the size's class can run at (ETRTO / ISO): passenger tyres about 1.5-3.5 bar (a temporary
// spare 4.2), light-truck up to about 6.5 (load range F), truck and bus up to 9-10. The bounds are wider than these
// and only catch a value in another unit: 0.25 typed in MPa, 19 typed in psi.
struct PressureClass {
  const char* name;
  double max_bar;
  const char* usual;
};

PressureClass pressure_class(const std::optional<TyreSize>& size) {
  const bool half_inch_rim = size && std::fmod(std::round(size->rim_diameter_m / units::kMPerInch * 10.0), 10.0) == 5.0;
  if (size && size->prefix == SizePrefix::light_truck) return {"a light-truck (LT) tyre", 8.0, "about 3-6.5 bar"};
  if (half_inch_rim) return {"a tyre on a truck rim (17.5, 19.5, 22.5 in)", 10.0, "about 6-9 bar"};
  if (size && size->commercial) return {"a van tyre (C2)", 8.0, "about 3.5-5.5 bar"};
  if (size) return {"a passenger tyre", 5.0, "about 1.5-3.5 bar, a temporary spare 4.2"};
  return {"a road vehicle's tyre", 10.0, "passenger 1.5-3.5 bar, light truck up to 6.5, truck up to 9-10"};
}

constexpr double kMinPlausibleBar = 1.0;  // below, a road tyre is flat: the sidewall carries the car
constexpr double kPaPerPsi = 6894.757;

constexpr double kKgPerLb = 0.45359237;

// An explicit max_load_kg against the load index of the size: the index is the tyre's rating, so a value more than
// half again above or below it is another unit (newtons, pounds, tonnes), not another rating.
void check_rating_against_index(double max_kg, const TyreSize& size, const std::string& where) {
  const double index_kg = *load_index_max_load_kg(*size.load_index);
  const double lo = index_kg / 1.5, hi = index_kg * 1.5;
  if (max_kg >= lo && max_kg <= hi) return;
  throw InputError(where, format_value(max_kg) + " kg is not allowed for '" + size.designation + "', whose load index " +
                              std::to_string(*size.load_index) + " rates it " + format_value(index_kg) + " kg: must be in [" +
                              significant(lo, 4) + ", " + significant(hi, 4) + "] kg" +
                              unit_slip_hint(max_kg, Range::closed(lo, hi), "kg", {{"N", 1.0 / units::kStandardGravity_mps2}, {"lb", kKgPerLb}, {"t", 1e3}}));
}

// Stiffness constants given in a file must leave the tyre within 8 times as stiff or as soft as the thesis' constants
// make it (at the file's pressure): those deflect a tyre 15-25 % of its section height at its rating, as tyres do;
// 8 times stiffer is under 3 %, a run-flat's sidewall included, and 8 times softer is past the rim. Unbounded, 1e300
// read as a rigid wheel, 0.17 kg/t, and simulated 19 % less energy than the tyre (session 25). The bounds hold whether
// or not the file rates a load.
void check_stiffness_constants(const TyreState& state, const std::string& where) {
  TyreState thesis = state;
  thesis.constants.stiffness_pressure_coeff = TyreModelConstants{}.stiffness_pressure_coeff;
  thesis.constants.stiffness_offset_kgf_per_mm = TyreModelConstants{}.stiffness_offset_kgf_per_mm;
  const double kz = vertical_stiffness_n_per_m(state), kz_thesis = vertical_stiffness_n_per_m(thesis);
  constexpr double kMaxRatio = 8.0;
  if (kz <= kMaxRatio * kz_thesis && kz * kMaxRatio >= kz_thesis) return;
  throw InputError(where, "the stiffness constants make the tyre " + significant(kz / kz_thesis, 3) + " times as stiff as the thesis' constants do (" +
                              significant(kz / 1e3, 4) + " against " + significant(kz_thesis / 1e3, 4) + " N/mm at " +
                              significant(units::pa_to_bar(state.pressure_pa), 3) + " bar), where those deflect a tyre about 15-25 % of its "
                              "section height at its rating: allowed " + significant(1.0 / kMaxRatio, 3) + " to " + significant(kMaxRatio, 2) + " times");
}

// At its rated load a tyre deflects about 15-25 % of its section height (the shipped tyres 9-26 %, at 2.5 bar or
// their own pressure if higher, as ETRTO rates standard-load tyres); half of it is beyond any tyre's rating. Without
// a rim the height is bounded by the outer radius less the smallest rim's (8 in).
void check_rated_deflection(const TyreSpec& spec, const std::string& where, bool given_in_kg) {
  TyreState rated = spec.state;
  rated.pressure_pa = std::max(rated.pressure_pa, units::bar_to_pa(2.5));
  const auto& g = rated.geometry;
  const double height_m = g.rim_radius_m > 0.0 ? g.outer_radius_m - g.rim_radius_m : std::max(g.outer_radius_m - 4.0 * units::kMPerInch, g.outer_radius_m / 2.0);
  const double kz = vertical_stiffness_n_per_m(rated);
  const double deflection_m = spec.max_load_n / kz;
  if (!(deflection_m > 0.5 * height_m)) return;
  const double max_kg = spec.max_load_n / units::kStandardGravity_mps2, allowed_kg = 0.5 * height_m * kz / units::kStandardGravity_mps2;
  throw InputError(where, "a rated load of " + format_value(std::round(max_kg)) + " kg would deflect the tyre by " + fixed(deflection_m * 1e3, 1) +
                              " mm at " + significant(units::pa_to_bar(rated.pressure_pa), 3) + " bar, " + fixed(100.0 * deflection_m / height_m, 0) +
                              " % of its section height (" + fixed(height_m * 1e3, 0) + " mm); tyres deflect about 15-25 % at their rating: " +
                              "allowed at most 50 %, a rating below " + significant(allowed_kg, 4) + " kg" +
                              (given_in_kg ? unit_slip_hint(max_kg, Range::closed(0.0, allowed_kg), "kg", {{"N", 1.0 / units::kStandardGravity_mps2}, {"lb", kKgPerLb}}) : ""));
}

const char* kFormat =
    "expected a size designation like '205/55 R16 91V' ([P|LT]width/aspect [Z]R rim [load index][speed symbol] "
    "[XL|Reinforced])";

}  // namespace

namespace {
// The class's plausible inflation in the unit it was given (`per_bar` of them to a bar), said in that unit.
void check_pressure_in(double value, double per_bar, const std::string& unit, const std::string& lead,
                       std::initializer_list<UnitSlip> slips, const std::optional<TyreSize>& size, const std::string& where) {
  const PressureClass c = pressure_class(size);
  const double lo = per_bar * kMinPlausibleBar, hi = per_bar * c.max_bar;
  if (value >= lo && value <= hi) return;
  const std::string of = size ? " ('" + size->designation + "')" : "";
  throw InputError(where, lead + format_value(value) + " " + unit + " is not allowed for " + c.name + of + ": must be in [" +
                              format_value(lo) + ", " + format_value(hi) + "] " + unit + " (such tyres run at " + c.usual + ")" +
                              unit_slip_hint(value, Range::closed(lo, hi), unit, slips));
}
}  // namespace

void check_pressure_plausible(double bar, const std::optional<TyreSize>& size, const std::string& where) {
  check_pressure_in(bar, 1.0, "bar", "", {{"MPa", 10.0}, {"psi", kPaPerPsi / 1e5}, {"kPa", 0.01}, {"Pa", 1e-5}}, size, where);
}

void check_pressure_plausible_kpa(double kpa, const std::optional<TyreSize>& size, const std::string& where) {
  check_pressure_in(kpa, 100.0, "kPa", "pressure ", {{"bar", 100.0}, {"MPa", 1e3}, {"psi", kPaPerPsi / 1e3}}, size, where);
}

double iso28580_passenger_pressure_pa(const TyreSize& size) { return size.extra_load ? 250e3 : 210e3; }

std::optional<double> load_index_max_load_kg(int load_index) {
  if (load_index < kFirstLoadIndex || load_index > kLastLoadIndex) return std::nullopt;
  return kLoadIndexKg[static_cast<std::size_t>(load_index - kFirstLoadIndex)];
}

std::optional<double> speed_symbol_max_mps(const std::string& symbol) {
  const auto kmh = rated_kmh(upper(symbol));
  return kmh ? std::optional(units::kmh_to_mps(*kmh)) : std::nullopt;
}

std::string speed_rating_warning(const TyreSpec& tyre, double speed_mps, const std::string& what) {
  if (!tyre.size || !tyre.size->speed_symbol) return "";
  const auto rated_mps = speed_symbol_max_mps(*tyre.size->speed_symbol);
  if (!rated_mps || speed_mps <= *rated_mps * (1.0 + 1e-9)) return "";
  return what + " reaches " + fixed(units::mps_to_kmh(speed_mps), 1) + " km/h, above the speed rating of tyre '" + tyre.name + "', " +
         *tyre.size->speed_symbol + " (" + format_value(std::round(units::mps_to_kmh(*rated_mps))) +
         " km/h): the model runs there, but the tyre is not built for it";
}

TyreSize parse_tyre_size(const std::string& designation, const std::string& where) {
  const std::string text = upper(designation);
  const std::string quoted = "'" + designation + "'";
  auto fail = [&](const std::string& why) -> TyreSize {
    throw InputError(where, quoted + " does not parse: " + why + "; " + kFormat);
  };

  TyreSize out;
  out.designation = designation;
  Cursor c{text};
  c.skip_spaces();
  if (c.eat("LT")) {
    out.prefix = SizePrefix::light_truck;
  } else if (c.eat("P")) {
    out.prefix = SizePrefix::passenger;
  }
  const std::string width = c.digits();
  if (width.size() != 3) return fail("section width must be 3 digits in mm");
  if (!c.eat("/")) return fail("missing '/aspect ratio' after the width");
  const std::string aspect = c.digits();
  if (aspect.size() != 2) return fail("aspect ratio must be 2 digits in percent");
  c.skip_spaces();
  // Construction: R radial, ZR radial rated above 240 km/h. The model is for radial tyres only.
  if (!c.eat("ZR") && !c.eat("R")) {
    return fail("construction must be R or ZR (radial; the model is for radial tyres)");
  }
  c.skip_spaces();
  const std::string rim = c.number();
  if (rim.empty()) return fail("missing rim diameter in inches");
  if (rim.size() > 5) return fail("rim diameter " + rim.substr(0, 8) + "... in is outside 8..30 in");
  // "R16C": a commercial (van) tyre. Read as a speed symbol it had been refused as "more than one speed symbol".
  if (c.i < text.size() && text[c.i] == 'C' &&
      (c.i + 1 == text.size() || text[c.i + 1] == ' ' || text[c.i + 1] == '\t' || text[c.i + 1] == '('))
    ++c.i, out.commercial = true;

  out.section_width_m = std::stod(width) * units::kMPerMm;
  out.aspect_ratio = std::stod(aspect) / 100.0;
  out.rim_diameter_m = std::stod(rim) * units::kMPerInch;
  if (out.section_width_m < 0.100 || out.section_width_m > 0.400)
    return fail("section width " + width + " mm is outside 100..400 mm");
  if (out.aspect_ratio < 0.20 || out.aspect_ratio > 0.95)
    return fail("aspect ratio " + aspect + " is outside 20..95 %");
  if (std::stod(rim) < 8.0 || std::stod(rim) > 30.0) return fail("rim diameter " + rim + " in is outside 8..30 in");
  out.outer_radius_m = out.rim_diameter_m / 2.0 + out.section_width_m * out.aspect_ratio;
  out.commercial = out.commercial || out.prefix == SizePrefix::light_truck ||
                   std::fmod(std::round(std::stod(rim) * 10.0), 10.0) == 5.0;  // truck rims: 17.5, 19.5, 22.5 in

  // Service description and suffixes, in any spacing: "91V", "(94Y)", "121/118S", "V", "XL", "Reinforced".
  while (true) {
    c.skip_spaces();
    if (c.done()) break;
    std::string tok = c.word();
    if (tok == "XL" || tok == "REINFORCED" || tok == "RF" || tok == "EXTRA") {
      out.extra_load = true;
      if (tok == "EXTRA") {
        c.skip_spaces();
        if (c.word() != "LOAD") return fail("'Extra' must be followed by 'Load'");
      }
      continue;
    }
    if (tok.size() >= 2 && tok.front() == '(' && tok.back() == ')') tok = tok.substr(1, tok.size() - 2);
    Cursor t{tok};
    const std::string li = t.digits();
    if (!li.empty()) {
      if (out.load_index) return fail("more than one load index");
      if (li.size() > 3) return fail("load index '" + li + "' has too many digits");
      const int index = std::stoi(li);
      if (t.eat("/")) {  // dual rating "121/118" (LT, van, truck): single-wheel first, dual-wheel second; we use single
        if (t.digits().empty()) return fail("a load pair must look like 121/118");
        out.commercial = true;
      }
      if (!load_index_max_load_kg(index)) {
        throw InputError(where, quoted + ": load index " + li + " is outside the ETRTO/ISO table; allowed: " +
                                    std::to_string(kFirstLoadIndex) + ".." + std::to_string(kLastLoadIndex));
      }
      out.load_index = index;
    }
    const std::string sym = tok.substr(t.i);
    if (!sym.empty()) {
      if (!is_speed_symbol(sym)) return fail("'" + sym + "' is not a speed symbol (L..Y, e.g. H, V, W) nor XL");
      if (out.speed_symbol) return fail("more than one speed symbol");
      out.speed_symbol = sym;
    }
  }
  return out;
}

TyreSpec load_tyre_file(const std::string& path) { return load_tyre(YamlMap::load_file(path)); }

TyreSpec load_tyre_text(const std::string& text, const std::string& name) {
  return load_tyre(YamlMap::load_text(text, name));
}

TyreSpec load_tyre(YamlMap y) {
  const std::string path = y.file();
  reject_unknown_keys(y, {"name", "description", "source", "size", "outer_radius_m", "section_width_m",
                          "rim_diameter_in", "rim_radius_m", "outer_diameter_mm", "pressure_bar", "max_load_kg",
                          "load_index", "model"});
  TyreSpec spec;
  spec.source = path;
  spec.name = display_name(opt_string(y, "name").value_or(std::filesystem::path(path).stem().string()));
  spec.description = opt_string(y, "description").value_or("");
  spec.reference = opt_string(y, "source").value_or("");

  const auto size_text = opt_string(y, "size");
  // Any positive number reaches the plausibility checks below, which name the unit a value may have been typed in.
  const auto radius = opt_number(y, "outer_radius_m", Range::positive());
  const auto width = opt_number(y, "section_width_m", Range::positive());
  const auto rim_in = opt_number(y, "rim_diameter_in", Range::open_low(0.0, 60.0));
  const auto rim_r = opt_number(y, "rim_radius_m", Range::non_negative());
  const auto measured_d_mm = opt_number(y, "outer_diameter_mm", Range::positive());
  auto& g = spec.state.geometry;

  if (size_text) {
    for (const char* k : {"outer_radius_m", "section_width_m", "rim_diameter_in", "rim_radius_m"}) {
      if (y.has(k)) {
        throw InputError(y.where(k), "not allowed together with 'size' (the designation gives the geometry; use "
                                     "outer_diameter_mm to override the outer diameter with a measured one)");
      }
    }
    spec.size = parse_tyre_size(*size_text, y.where("size"));
    g.outer_radius_m = spec.size->outer_radius_m;
    g.section_width_m = spec.size->section_width_m;
    g.rim_radius_m = spec.size->rim_diameter_m / 2.0;
  } else {
    if (!radius && !measured_d_mm) {
      throw InputError(y.where("size"), "missing: give 'size' (e.g. \"175/70 R14 84T\") or 'outer_radius_m' "
                                        "(or 'outer_diameter_mm') and 'section_width_m'");
    }
    if (!width) throw InputError(y.where("section_width_m"), "required key is missing (needed when 'size' is not given)");
    if (radius && measured_d_mm) {
      throw InputError(y.where("outer_diameter_mm"), "not allowed together with 'outer_radius_m': give one of them");
    }
    if (rim_in && rim_r) throw InputError(y.where("rim_radius_m"), "not allowed together with 'rim_diameter_in'");
    g.outer_radius_m = radius ? *radius : 0.0;
    g.section_width_m = *width;
    if (rim_in) g.rim_radius_m = *rim_in * units::kMPerInch / 2.0;
    if (rim_r) g.rim_radius_m = *rim_r;
  }
  // A road tyre's geometry, from a quadricycle's 12-inch wheel to a lorry's 22.5-inch one: a value outside was typed in
  // another unit (outer_diameter_mm: 0.61 was blamed on load_index, as "98745 % of its section height": session 23).
  constexpr double kMmPerIn = 25.4;
  const std::string no_tyre = "no road tyre measures that";
  if (radius)
    check_physical(*radius, Range::closed(kRoadTyreDiameterMin_m / 2.0, kRoadTyreDiameterMax_m / 2.0), "m", no_tyre,
                   {{"mm", 1e-3}, {"cm", 1e-2}, {"inches", kMmPerIn * 1e-3}}, y.where("outer_radius_m"));
  if (measured_d_mm)
    check_physical(*measured_d_mm, Range::closed(kRoadTyreDiameterMin_m * 1e3, kRoadTyreDiameterMax_m * 1e3), "mm", no_tyre,
                   {{"m", 1e3}, {"cm", 10.0}, {"inches", kMmPerIn}}, y.where("outer_diameter_mm"));
  if (width)
    check_physical(*width, Range::closed(kRoadTyreWidthMin_m, kRoadTyreWidthMax_m), "m", no_tyre,
                   {{"mm", 1e-3}, {"cm", 1e-2}, {"inches", kMmPerIn * 1e-3}}, y.where("section_width_m"));
  if (measured_d_mm) g.outer_radius_m = *measured_d_mm * units::kMPerMm / 2.0;
  if (!(g.rim_radius_m < g.outer_radius_m)) {
    const std::string key = rim_in ? "rim_diameter_in" : rim_r ? "rim_radius_m" : "outer_diameter_mm";
    throw InputError(y.where(key), "rim radius " + format_value(g.rim_radius_m) + " m is not below the outer radius " +
                                       format_value(g.outer_radius_m) + " m: the rim must be inside the tyre");
  }

  // Any positive number reaches the plausibility check, which knows the tyre's class and the units a value may
  // have been typed in: 210 (kPa) met a bare "(0, 20]" before (session 20).
  const double pressure_bar = y.number("pressure_bar", Range::finite());  // the tyre class's range: below
  check_pressure_plausible(pressure_bar, spec.size, y.where("pressure_bar"));
  spec.state.pressure_pa = units::bar_to_pa(pressure_bar);

  const auto max_kg = opt_number(y, "max_load_kg", Range::open_low(0.0, 20000.0));
  const auto li = opt_number(y, "load_index", Range::closed(kFirstLoadIndex, kLastLoadIndex));
  if (max_kg && li) throw InputError(y.where("load_index"), "not allowed together with 'max_load_kg': give one of them");
  if (li && *li != std::floor(*li)) {
    throw InputError(y.where("load_index"), format_value(*li) + " is not allowed: must be a whole number");
  }
  // An explicit rating in the file wins over the designation's load index.
  if (max_kg) {
    spec.max_load_n = *max_kg * units::kStandardGravity_mps2;
  } else if (li) {
    spec.max_load_n = *load_index_max_load_kg(static_cast<int>(*li)) * units::kStandardGravity_mps2;
  } else if (spec.size && spec.size->load_index) {
    spec.max_load_n = *load_index_max_load_kg(*spec.size->load_index) * units::kStandardGravity_mps2;
  }

  if (max_kg && spec.size && spec.size->load_index) check_rating_against_index(*max_kg, *spec.size, y.where("max_load_kg"));
  // The same rating as a load index: 120 on a '195/65 R15 91H' (1400 kg against 615) ran at 1.8 times the tyre's real
  // rating, where max_load_kg: 1400 is refused (session 23's outside testing).
  if (li && spec.size && spec.size->load_index && static_cast<int>(*li) != *spec.size->load_index) {
    const double kg = *load_index_max_load_kg(static_cast<int>(*li)), index_kg = *load_index_max_load_kg(*spec.size->load_index);
    if (kg < index_kg / 1.5 || kg > index_kg * 1.5)
      throw InputError(y.where("load_index"), format_value(*li) + " (" + format_value(kg) + " kg) is not allowed for '" + spec.size->designation +
                                                  "', whose load index " + std::to_string(*spec.size->load_index) + " rates it " +
                                                  format_value(index_kg) + " kg: an index must rate it within [" + significant(index_kg / 1.5, 4) +
                                                  ", " + significant(index_kg * 1.5, 4) + "] kg");
  }
  std::string stiffness_where;
  if (y.has("model") && y.node()["model"].IsScalar()) {
    spec.state.model = model_kind(y.string("model"), y.where("model"));
    if (spec.state.model == TyreModelKind::Hysteresis) {
      throw InputError(y.where("model"), "kind hysteresis needs the tyre's constants, at least its level: write "
                                         "'model:' as a mapping with 'kind: hysteresis' and 'rrc_ref' ('rollsim tyre "
                                         "fit' writes such files)");
    }
  } else if (auto m = opt_map(y, "model")) {
    read_model_map(*m, spec.state);
    for (const char* k : {"stiffness_pressure_coeff", "stiffness_offset_kgf_per_mm"})
      if (stiffness_where.empty() && m->has(k)) stiffness_where = m->where(k);
  }
  if (!stiffness_where.empty()) check_stiffness_constants(spec.state, stiffness_where);
  if (spec.max_load_n > 0.0) {
    const std::string rating_key = max_kg ? "max_load_kg" : li ? "load_index" : "size";
    check_rated_deflection(spec, y.where(rating_key), max_kg.has_value());
  }
  y.finish();
  return spec;
}

}  // namespace rollsim
