// A tyre as a user asks for it (file, size or geometry; load; speeds), built, evaluated and written as JSON.
#pragma once

#include <string>
#include <utility>

#include "rollsim/common/error.hpp"
#include "rollsim/common/json.hpp"
#include "rollsim/tyre/tyre_model.hpp"
#include "rollsim/tyre/tyre_spec.hpp"

namespace rollsim {

/// What `rollsim tyre` and the Python `rollsim.tyre()` are given. Numbers stay text until checked here, so that
/// both front ends name a bad value alike (by its option, e.g. "--pressure-bar"). Empty means not given.
struct TyreRequest {
  std::string file;  ///< tyre file or shipped name
  std::string file_text;  ///< or a tyre file's YAML (or JSON) text, e.g. a Python dict of its keys
  std::string size;  ///< designation, e.g. "175/70 R14 84T"
  std::string outer_radius_m, width_m, pressure_bar, load_n, load_pct;
};

/// The load one tyre carries and the option or rule that set it (for error messages).
struct TyreLoadChoice {
  double load_n = 0.0;
  std::string where;
};

/// The tyre from a file, a designation, or explicit geometry; pressure_bar overrides a file's pressure.
TyreSpec build_requested_tyre(const TyreRequest& request);

/// load_n, or load_pct of the tyre's maximum load (default 80 %).
TyreLoadChoice choose_requested_load(const TyreRequest& request, const TyreSpec& spec);

/// "load N is P % of the tyre's rated M N; is it in kg?" for a load under 15 % of the rating (no car loads a tyre
/// this lightly: an empty quadricycle's is ~25 %); empty otherwise or when the rating is unknown.
std::string load_in_kg_hint(double load_n, double max_load_n);

/// What a user should hear of the load asked for, or "": above the tyre's rating (outside it), or under 15 % of it
/// (a load typed in kg: --load-n 400 ran at 8 % of a 4903 N rating and read an RRC 3.6 times too high, unwarned:
/// session 23's outside testing). The figures carry the decimals that tell them apart.
std::string requested_load_warning(const TyreSpec& spec, const TyreLoadChoice& load);

/// One speed [km/h] given as text, checked to [0, 500] (named "--speed-kmh").
double parse_requested_speed_kmh(const std::string& text);

/// Runs `f`; a model domain error (no origin) becomes an InputError naming the tyre, load and pressure given.
template <typename F>
auto named_tyre_request(const TyreRequest& request, const TyreSpec& spec, const TyreLoadChoice& load, F&& f) {
  try {
    return std::forward<F>(f)();
  } catch (const ModelDomainError& e) {
    std::string where = spec.source + " at " + load.where;
    if (!request.pressure_bar.empty()) where += ", --pressure-bar " + request.pressure_bar;
    throw InputError(where, e.what());
  }
}

/// One operating point as `rollsim tyre --json` writes it (tyre, geometry, load, speed, RRC and its parts).
JsonObject tyre_point_json(const TyreSpec& spec, double load_n, double speed_kmh, const RollingResistance& r);

}  // namespace rollsim
