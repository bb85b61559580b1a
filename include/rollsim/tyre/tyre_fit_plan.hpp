// What a user has for one tyre (points, a label, a J2452 set) turned into a fit request; the CLI and Python share it.
#pragma once

#include <optional>
#include <ostream>
#include <string>
#include <vector>

#include "rollsim/tyre/j2452.hpp"
#include "rollsim/tyre/tyre_fit.hpp"

namespace rollsim {

/// What a user has for one tyre, typed. Each `*_where` names the input in errors (an option, a keyword).
struct TyreFitInputs {
  TyreSize size;
  std::vector<RrcPoint> points;                ///< measured points, each naming where it came from
  std::optional<std::string> label_class;      ///< EU label class A-E (C1)
  std::string label_where = "label";
  std::optional<J2452Set> j2452;               ///< sampled on the evaluation grid, flat-road corrected
  std::string j2452_where = "j2452";
  std::optional<double> drum_radius_m;         ///< of the J2452 test; default kJ2452DrumRadius_m
  std::string drum_where = "drum_radius_m";
  std::optional<double> uncertainty_pct;       ///< a point's relative scatter when no degrees of freedom remain
  std::string uncertainty_where = "rrc_uncertainty_pct";
  std::vector<HysteresisParam> free;           ///< empty: what the points determine
  std::vector<std::string> notes;              ///< what reading the inputs left to say; the plan's warnings carry it
};

/// The fit to run and what a report needs beside it.
struct TyreFitPlan {
  TyreState start;                ///< the size's geometry
  FitRequest request;
  std::optional<LabelBand> band;  ///< the label's RRC band
  std::optional<RrcPoint> iso;    ///< the ISO 28580 point where the band applies
  std::vector<std::string> warnings;  ///< what is allowed but said (a point loaded past the size's rating)
};

/// A label alone is one point at ISO 28580 conditions at the band's geometric middle, with the band as its
/// uncertainty (its 95 % interval is 95 % of the band's log width); with points, the band only checks the fit. Throws InputError for
/// a label class outside A-E, a label on a size without load index, a drum radius outside (0.1, 10) m or an
/// uncertainty outside (0, 50] %.
TyreFitPlan plan_tyre_fit(const TyreFitInputs& in);

/// The fitted tyre against the label's band, which is on ISO 28580's 2.0 m drum: the model's flat-road RRC at the
/// ISO point, the same on the drum (flat / drum_to_flat), and whether the band holds it.
struct LabelCheck {
  double flat_rrc = 0.0, drum_rrc = 0.0, drum_to_flat = 1.0;
  bool inside = false;
};
std::optional<LabelCheck> label_check(const TyreFit& fit, const TyreFitPlan& plan);

/// The constants named by `keys` (hysteresis_param_key), with the level always among them (the tyre's own).
/// Throws InputError(where, ...) naming a key that is not a constant and the allowed ones.
std::vector<HysteresisParam> free_params_from_keys(const std::vector<std::string>& keys, const std::string& where);

/// The inflation pressure a fitted tyre file is written at [Pa]: `pressure_bar` (0.5-6 bar) or, without it, ISO
/// 28580's for the size (210 kPa, 250 kPa for extra load). Throws InputError(where, ...) outside the range.
double fitted_file_pressure_pa(const TyreSize& size, std::optional<double> pressure_bar, const std::string& where);

/// The fitted tyre file's text (write_fitted_tyre_yaml), read back as every command reads a tyre file: a fit whose
/// constants no tyre file may hold (the points asked for a deflection exponent of 8, or ran the level to 2e-9 chasing
/// a speed rise the model cannot give) throws InputError("tyre fit", ...) naming the key, its value and the range,
/// so that no file is written that rollsim then refuses (session 22's outside testing).
std::string fitted_tyre_file_text(const FittedTyreFile& file, const TyreFit& fit);

/// The fit as JSON lines: one object for the fit ("kind": "fit", with the label's band and the model at its ISO
/// point when a label was given), one per constant ("param": free with its 95 % interval, or held), one per
/// measured point ("residual"). Files' units: kPa, km/h, percent.
void write_tyre_fit_json(std::ostream& out, const TyreFit& fit, const TyreFitPlan& plan);

}  // namespace rollsim
