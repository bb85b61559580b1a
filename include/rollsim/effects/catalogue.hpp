// Catalogue of physical effects beyond the base model (tyre warm-up, auxiliary load, wind, ...), each an Effect.
#pragma once

#include <functional>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "rollsim/common/yaml_reader.hpp"
#include "rollsim/effects/effect.hpp"

namespace rollsim {

/// The implemented effects. Adding one: its module and its one registry row in catalogue.cpp.
enum class EffectId {
  tyre_warmup,
  aux_load,
  wind,
  mass,
  rr_speed,
  ambient_rrc,
  rotational_inertia,
  battery_resistance,
  tyre_slip,
  regen_limit,
  engine_warmup,
  road_grade,
  road_profile,
  wind_heading,
  hvac_ambient,
};

/// What an effect needs to know about the car it is fitted to (set from the vehicle description).
struct EffectContext {
  double mass_kg = 0.0;            ///< test mass (the mass effect's rolling share is scaled from it)
  double rho_cda_kg_per_m = 0.0;   ///< air density x drag area (2 x coast-down C for coast-down vehicles)
  double pack_voltage_v = 0.0;     ///< the traction battery's open-circuit voltage; 0 without a battery
};

/// One parameter of a catalogue effect, with its unit, neutral value and allowed (physical) bounds.
struct EffectParameterInfo {
  std::string name;        ///< YAML key, e.g. "cold_rrc_excess"
  std::string unit;        ///< "1", "W", "m/s", "kg", "J/K", ...
  double neutral = 0.0;    ///< value at which the effect is off (or, for shape parameters, its default)
  double nominal = 0.0;    ///< literature-typical size (used for signatures)
  double min = 0.0;
  double max = 0.0;
  bool amplitude = false;  ///< the effect's size (fitted linearly); otherwise a shape parameter
};

using EffectParameters = std::map<std::string, double>;
using EffectFactory = std::function<std::shared_ptr<const Effect>(const EffectParameters&, const EffectContext&)>;

/// One registry row: metadata and factory together.
struct EffectInfo {
  EffectId id{};
  std::string name;         ///< identifier in files and reports, e.g. "tyre_warmup"
  std::string description;
  std::vector<EffectParameterInfo> parameters;
  /// What a signature of this effect's shape with the physically impossible sign describes (the amplitude's
  /// bounds carry the sign: a warm-up makes the start costlier, a load draws power, a payload adds mass).
  std::string opposite_sign;
  EffectFactory make;       ///< from a complete, checked parameter set
  const EffectParameterInfo& amplitude() const;
};

/// The implemented effects, in a stable order (the enum's).
const std::vector<EffectInfo>& effect_catalogue();
/// Catalogue identifiers the issue lists that have no module yet (documented in docs/diagnose.md).
const std::vector<std::string>& effects_not_implemented();
const EffectInfo& effect_info(EffectId id);
const EffectInfo& effect_info(const std::string& name);  ///< throws InputError for an unknown name
const std::string& to_string(EffectId id);

/// An effect as a vehicle description states it: which one and its parameters, checked against the registry's
/// bounds. The model (an Effect) is built from it only when a simulation is assembled, against that car's context,
/// so a description can be copied, changed and written back without holding simulator objects.
struct EffectSpec {
  EffectId id{};
  EffectParameters parameters;  ///< complete: every registry parameter, defaults filled in
};

/// Checks `given` against the registry row of `id` and fills in the neutral (or default) value of each missing
/// parameter; throws InputError on an unknown parameter or a value out of bounds.
EffectSpec effect_spec(EffectId id, const EffectParameters& given);

/// Builds one effect model from a spec, for the car described by `context`.
std::shared_ptr<const Effect> make_effect(const EffectSpec& spec, const EffectContext& context);
/// Same, checking the parameters first (effect_spec).
std::shared_ptr<const Effect> make_effect(EffectId id, const EffectParameters& params, const EffectContext& context);
std::shared_ptr<const Effect> make_effect(const std::string& name, const EffectParameters& params,
                                          const EffectContext& context);

/// Reads a vehicle file's `effects:` block ({id: {param: value}}), strictly.
std::vector<EffectSpec> load_effects(YamlMap effects);

/// The `effects:` block text (YAML, two-space indented under `effects:`) for these effects.
std::string effects_yaml(const std::vector<std::pair<std::string, EffectParameters>>& effects);

}  // namespace rollsim
