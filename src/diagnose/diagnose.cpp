// Diagnosis: the orchestrator. Each stage is a function of what it needs returning a plain result (pipeline.hpp):
// windows -> replay and lag -> signatures -> calibration with priors -> location -> noise floor -> selection ->
// unexplained -> adequacy -> output.
#include "rollsim/diagnose/diagnose.hpp"

#include <algorithm>
#include <cmath>
#include <optional>

#include "pipeline.hpp"
#include "rollsim/common/error.hpp"
#include "rollsim/common/units.hpp"
#include "rollsim/cycle/elevation.hpp"
#include "rollsim/cycle/speed_resolution.hpp"

namespace rollsim {
namespace {

// What the replay takes from the fuel channel about the engine: its switched-off runs and its start state.
void note_engine_state(const DriveCycle& c, const Recording& r, const EngineStartState& start, bool to_infer,
                       const DiagnoseOptions& opt, std::vector<std::string>& notes) {
  if (!r.fuel_rate_m3ps) return;
  int runs = 0;
  double off_s = 0.0;
  for (std::size_t i = 0; i + 1 < c.time_s.size(); ++i) {
    if (!c.engine_off_at(i)) continue;
    if (i == 0 || !c.engine_off_at(i - 1)) ++runs;
    off_s += c.time_s[i + 1] - c.time_s[i];
  }
  const std::string how =
      start.inferred ? " (inferred: its first minutes of running burn " + fixed(100.0 * start.early_excess, 1) + " % [" +
                           fixed(100.0 * start.early_excess_ci_low, 1) + ", " + fixed(100.0 * start.early_excess_ci_high, 1) +
                           "] more fuel than the warm model, relative to its later running" +
                           (start.idle_inferred ? ", and its early idling " + fixed(100.0 * start.idle_excess, 1) + " % [" +
                                                      fixed(100.0 * start.idle_excess_ci_low, 1) + ", " +
                                                      fixed(100.0 * start.idle_excess_ci_high, 1) + "] more than its later idling"
                                                : std::string()) +
                           "; hot only where " + (start.idle_inferred ? "either interval ends" : "that interval ends") +
                           " under " + fixed(100.0 * opt.engine_start_min_cold_excess, 0) + " %)"
      : to_infer ? " (too little running to infer it from its first " + fixed(opt.engine_start_early_s, 0) +
                       " s against its running after " + fixed(opt.engine_start_late_s, 0) + " s: taken cold)"
                 : " (set)";
  notes.push_back(r.source + ": engine " + (c.engine_hot_start ? "hot" : "cold (at ambient)") + " at the start" + how + "; " +
                  (runs == 0 ? std::string("never switched off")
                             : "switched off " + std::to_string(runs) + " times for " + fixed(off_s, 0) +
                                   " s in all (standing with zero fuel flow): no fuel there, and a cold engine cools"));
}

// The rms over the moving samples of per-sample values (draws of a grade's error), 0 without any.
double moving_rms(const Recording& r, const std::vector<std::vector<double>>& draws) {
  double ss = 0.0;
  std::size_t count = 0;
  for (const auto& d : draws)
    for (std::size_t i = 0; i < d.size() && i < r.speed_mps.size(); ++i)
      if (r.speed_mps[i] > 0.0) ss += d[i] * d[i], ++count;
  return count > 0 ? std::sqrt(ss / static_cast<double>(count)) : 0.0;
}

// The recording's grade is derived from its elevation (not given, and not withheld).
bool grade_from_recorded_elevation(const Recording& r) { return !r.grade && r.elevation_m.has_value(); }

// The replay's cycle of a recording, from its speed as replayed (`speed_mps`: a staircase undone) and, where its
// grade comes from its elevation, that grade (`elevation_grade`), each read once by the caller.
DriveCycle cycle_from(const Recording& r, double engine_off_min_s, EngineStart start, std::vector<double> speed_mps,
                      const std::vector<double>* elevation_grade) {
  DriveCycle c;
  if (r.latitude_deg && r.longitude_deg) c.heading_rad = heading_from_gps(*r.latitude_deg, *r.longitude_deg);
  c.engine_hot_start = start == EngineStart::hot;
  if (r.fuel_rate_m3ps && engine_off_min_s > 0.0) {
    std::vector<bool> off = engine_off_samples(r, engine_off_min_s);
    // A segment is off when it starts in a run and the run goes on past it (the run's last sample restarts).
    for (std::size_t i = 0; i + 1 < off.size(); ++i) off[i] = off[i] && off[i + 1];
    if (!off.empty()) off.back() = false;
    c.set_engine_off(std::move(off));
  }
  c.name = r.source;
  c.source = r.source;
  // Time from the start of the recording: effects that decay from the start of a trip read it.
  c.time_s = r.time_s;
  for (double& t : c.time_s) t -= r.time_s.front();
  c.speed_mps = std::move(speed_mps);
  if (r.grade) {
    // A recorded grade is read at each instant, and the replay holds a sample's grade over its segment to the next:
    // the segment's mean is the two ends' (the instant's lagged the road by half a sample: session 26's outside testing).
    c.grade = *r.grade;
    for (std::size_t i = 0; i + 1 < c.grade.size(); ++i) c.grade[i] = 0.5 * ((*r.grade)[i] + (*r.grade)[i + 1]);
  } else if (elevation_grade) c.grade = *elevation_grade;
  else c.grade.assign(r.time_s.size(), 0.0);
  // Quantised to 0.05 % (under 0.3 N per 100 kg of grade force error): the simulator prepares the tyre model once
  // per distinct grade, which otherwise is once per sample and 90 % of a hilly recording's diagnosis.
  for (double& g : c.grade) g = 0.0005 * std::round(g / 0.0005);
  return c;
}

// The replay's cycle of each recording, what its speed and elevation channels are said to be, and the Monte Carlo
// draws of its elevation-derived grade's errors (`grade_draws`, one entry per recording) for the noise floor.
std::vector<DriveCycle> cycles_of(const std::vector<Recording>& recordings, const DiagnoseOptions& opt,
                                  std::vector<std::string>& notes, diag::GradeNoiseDraws& grade_draws) {
  grade_draws.assign(recordings.size(), {});
  std::vector<DriveCycle> cycles;
  for (std::size_t k = 0; k < recordings.size(); ++k) {
    const Recording& r = recordings[k];
    const EngineStart start = k < opt.engine_start.size() ? opt.engine_start[k] : EngineStart::infer;
    // The speed and the elevation are read once, for the cycle and for what is said of them (each had been read
    // twice: in cycle_of_recording and again here).
    const SpeedResolution res = read_speed_resolution(r.time_s, r.speed_mps);
    std::optional<ElevationGrade> read;
    if (grade_from_recorded_elevation(r)) read = grade_from_elevation(r.time_s, r.speed_mps, *r.elevation_m);
    cycles.push_back(cycle_from(r, opt.engine_off_min_s, start, res.speed_mps, read ? &read->grade : nullptr));
    if (res.smoothed)
      notes.push_back(r.source + ": speed on a " + fixed(units::mps_to_kmh(res.quantum_mps), 3) + " km/h lattice, one step per "
                      "sample a " + fixed(res.step_accel_mps2, 2) + " m/s^2 acceleration the car did not make: the replay "
                      "follows a quadratic fitted over " + std::to_string(2 * res.half_window + 1) +
                      " samples about each (standstills kept)");
    if (read) {
      grade_draws[k] = grade_noise_draws(r.time_s, r.speed_mps, *r.elevation_m, read->noise_sd_m,
                                         diag::kGradeNoiseDraws, 0x9e3779b9u + static_cast<unsigned>(k), read->drift_sd_m,
                                         read->drift_time_s);
      const double grade_rms = moving_rms(r, grade_draws[k]);
      notes.push_back(r.source + ": grade from recorded elevation (" + std::to_string(read->rejected_steps) +
                      " elevation steps rejected as glitches, Savitzky-Golay slope over 300 m; white noise of " +
                      fixed(read->noise_sd_m, 2) + " m per reading about the road" +
                      (read->drift_sd_m > 0.0
                           ? " and a drift of " + fixed(read->drift_sd_m, 2) + " m correlated over " +
                                 fixed(read->drift_time_s, 0) + " s (from its standstills)"
                           : std::string()) +
                      ", " + fixed(100.0 * grade_rms, 2) +
                      " % of grade rms after the filter, carried into the noise floor; the uphill and downhill regimes "
                      "are read on this grade, so its errors put a residual of their own there)");
      // A drifting altitude (noise correlated over tens of seconds) looks like road: its rate is read off the
      // standstills and carried as a random walk, and where they show it well beyond the white noise it is said. On
      // session 26's outside tester's UDDS and WLTC nulls the wander was 0.95-1.17 x the white noise for white noise,
      // 1 m steps and glitches, and 1.89-3.0 x for AR(1) and random-walk drifts of 2-5 m; with 200 readings standing,
      // 1.5 is some ten of white noise's sds. A route without standstills (HWFET) cannot show it.
      if (read->standing_s >= ElevationGrade::kMinStandingForDrift_s &&
          read->standing_wander_m > 1.5 * read->noise_sd_m + 0.2)
        notes.push_back("warning: " + r.source + ": the recorded elevation wanders " + fixed(read->standing_wander_m, 1) +
                        " m rms while the car stands (" + fixed(read->standing_s, 0) + " s of standstills of 20 s or more), "
                        "against " + fixed(read->noise_sd_m, 2) + " m of white noise: an altitude drifting over tens of "
                        "seconds, which the grade's filter takes for road. It is carried into the noise floor as the "
                        "standstills show it; where the GPS drifts otherwise while driving it is not, so read "
                        "grade, mass and unexplained findings, and the uphill and downhill residuals, with that in mind");
    }
  }
  return cycles;
}

// A bearing taken into [0, 360) deg.

// The bearing's profile interval in words ("": none), its ends taken back to 0-360 deg.
std::string bearing_interval_text(const Finding& f) {
  for (const auto& p : f.parameters) {
    if (p.name != "wind_from_deg" || !p.profiled) continue;
    if (p.ci_low_open && p.ci_high_open) return "; its bearing is not determined within a half circle";
    return "; 95 % profile interval " + fixed(units::wrap_deg(p.ci_low), 0) + (p.ci_low_open ? " or beyond" : "") + " to " +
           fixed(units::wrap_deg(p.ci_high), 0) + (p.ci_high_open ? " or beyond" : "") + " deg clockwise";
  }
  return "";
}

// A steady wind is a head- or tailwind only relative to the heading: with it recorded, the wind's speed and bearing;
// without it, a headwind along the trace, said so.
void describe_wind(const std::vector<DriveCycle>& cycles, std::vector<Finding>& findings, std::vector<std::string>& notes) {
  const bool heading = diag::headings_known(cycles);
  if (!heading) notes.push_back("wind_heading not tested: the route's heading is unknown (no latitude and longitude recorded)");
  for (Finding& f : findings) {
    if (f.effect == "wind" && !heading)
      f.description += std::string(f.description.empty() ? "" : "; ") +
                       "the route's heading is unknown (no latitude and longitude recorded): a headwind along the trace, "
                       "not a wind's speed and direction";
    if (f.effect == "wind_heading" && f.fitted.count("wind_speed_mps") && f.fitted.count("wind_from_deg")) {
      // Candidates and the bearing's profile cover half the compass with a signed speed: report the wind blowing
      // from where it blows, its bearing in [0, 360) and its profile interval turned with it (unwrapped: its ends may
      // pass 0 or 360 deg).
      const bool reverse = f.fitted.at("wind_speed_mps") < 0.0;
      const double from = f.fitted.at("wind_from_deg") + (reverse ? 180.0 : 0.0);
      const double turn = units::wrap_deg(from) - f.fitted.at("wind_from_deg");
      if (reverse) f.fitted["wind_speed_mps"] = -f.fitted.at("wind_speed_mps");
      f.fitted["wind_from_deg"] += turn;
      for (auto& p : f.parameters) {
        if (p.name == "wind_speed_mps" && reverse) {
          const double low = -p.ci_high;
          p.ci_high = -p.ci_low, p.ci_low = low, p.value = -p.value;
        } else if (p.name == "wind_from_deg") {
          p.value += turn, p.ci_low += turn, p.ci_high += turn;
        }
      }
      f.description += std::string(f.description.empty() ? "" : "; ") + "a steady wind of " +
                       fixed(f.fitted.at("wind_speed_mps"), 1) + " m/s from " + fixed(f.fitted.at("wind_from_deg"), 0) +
                       " deg (clockwise from north, profiled in 1 deg steps" + bearing_interval_text(f) +
                       "), its headwind turning with the recorded heading";
    }
  }
}

// Each fuel-rate recording's start: as set, or inferred from its first minutes against the warm model's replay (which
// no start state changes), before any engine signature is run.
void set_engine_starts(std::vector<DriveCycle>& cycles, const std::vector<Recording>& recordings, const diag::Observations& o,
                       const diag::Variant& base, const DiagnoseOptions& opt, Diagnosis& out) {
  for (std::size_t k = 0; k < recordings.size(); ++k) {
    if (!recordings[k].fuel_rate_m3ps) continue;
    EngineStartState s;
    const EngineStart set = k < opt.engine_start.size() ? opt.engine_start[k] : EngineStart::infer;
    if (set == EngineStart::infer && o.channel == ChannelKind::fuel_rate) {
      s = diag::infer_engine_start(o.measured_w[k], base.power_w[k], o.dt_s[k], cycles[k], opt);
    } else {
      s.start = set == EngineStart::hot ? EngineStart::hot : EngineStart::cold;
    }
    s.recording = recordings[k].source;
    cycles[k].engine_hot_start = s.start == EngineStart::hot;
    note_engine_state(cycles[k], recordings[k], s, set == EngineStart::infer, opt, out.notes);
    out.engine_starts.push_back(s);
  }
  // The detection limits had read "cold_fuel_excess 192 (beyond its physical bounds)" on every hot start (session
  // 28's outside tester): a hot engine does not warm up, so its shape is not run (shapes_of).
  if (o.channel == ChannelKind::fuel_rate && !out.engine_starts.empty() &&
      std::all_of(cycles.begin(), cycles.end(), [](const DriveCycle& c) { return c.engine_hot_start; }))
    out.notes.push_back("engine_warmup not tested: every recording's engine started hot (" +
                        std::string(std::any_of(out.engine_starts.begin(), out.engine_starts.end(),
                                                [](const EngineStartState& e) { return e.inferred; })
                                        ? "inferred or set" : "set") +
                        "), and a hot engine does not warm up");
}

// A logger integrates its channel over each sample's interval (the replay's segment means) or reads it at the
// sample's instant (the replay's point values). The two differ by about half a sample wherever the power changes:
// the speed terms shift but the acceleration, constant over a replay segment, does not, so no lag turns one into the
// other, and reading one as the other leaves a residual in hard traction and braking (a tyre_slip-like shape). The
// data choose, but only decisively: interval means (the replay's integrated energy) unless the instant fits with a
// squared residual 5 % smaller, each at its best scale within the calibration's box. With a fractional lag the two
// readings nearly coincide, and a bare minimum picked the instant on 2 of 200 interval-mean nulls (1.0009 and
// 1.013 x), each then naming tyre_slip; a 1 Hz instantaneous logger fits 2.7 x better. A state of charge counts what
// left the cells: a mean.
void choose_channel_sampling(diag::Replayer& rp, const diag::Observations& o, double scale_bound, diag::Variant& base,
                             diag::LagEstimate& lag, Diagnosis& out) {
  diag::ChannelPowers both = rp.both_samplings({});
  lag = diag::estimate_lag(both.interval_mean, o);
  if (o.channel == ChannelKind::soc) {
    base.power_w = std::move(both.interval_mean);
    return;
  }
  // The choice is made as it was tuned (200 interval-mean nulls): each reading's lag by linear interpolation. Read
  // within their segments here, instants fitted interval-mean recordings with a concealed regen cap 1.06-1.10 x better.
  const diag::LagEstimate point_lag = diag::estimate_lag(both.instantaneous, o);
  constexpr double kDecisiveSseRatio = 1.05;
  // Compared at each reading's best scale within the calibration's box: a logger 3 % off in scale adds the same misfit
  // to both and had hidden a 1 Hz instantaneous logger's better fit (ratio 0.996 unscaled; session 23's outside
  // testing). Not a free scale, nor an offset: a concealed effect then let the wrong reading fit better.
  const double mean_sse = diag::scaled_lag_sse(both.interval_mean, nullptr, o, lag.samples, scale_bound);
  const double point_sse = diag::scaled_lag_sse(both.instantaneous, nullptr, o, point_lag.samples, scale_bound);
  base.power_w = std::move(both.interval_mean);
  const bool instantaneous = point_sse * kDecisiveSseRatio < mean_sse;
  out.channel_sampling = instantaneous ? "instantaneous" : "interval_mean";
  // Interval-mean SSE over the instant's: above 1 the instant fits better (chosen only beyond the decisive 1.05).
  out.channel_sampling_sse_ratio = mean_sse / std::max(point_sse, 1e-300);
  if (!instantaneous) return;
  rp.point_values = true;
  // Chosen instants are then read within their segments: a fractional lag puts an instant between a segment's start
  // and its end at its own acceleration, not between two samples' point values (session 20's outside check: a 1 Hz
  // instantaneous logger with a 0.3-0.9 s lag had its lag read as whole samples and effects named on 13 of 20 nulls).
  // The ends are replayed only now that they are needed (point_values set: the replay records them).
  rp.sample({}, base);
  lag = diag::estimate_lag(base.power_w, o, &base.end_w);
}

void report_calibration(const diag::Calibration& c, const diag::Observations& o, const diag::LagEstimate& lag, Diagnosis& out) {
  const Eigen::VectorXd& k = c.model.fit.coef;
  out.channel_scale = k[0];
  out.rrc_level_change = 0.1 * k[1] / k[0];
  out.drag_change = 0.1 * k[2] / k[0];
  out.channel_scale_prior_low = 1.0 - c.prior_scale_bound;
  out.channel_scale_prior_high = 1.0 + c.prior_scale_bound;
  out.channel_scale_free = c.free_coef[0];
  out.rrc_level_change_free = 0.1 * c.free_coef[1] / c.free_coef[0];
  out.drag_change_free = 0.1 * c.free_coef[2] / c.free_coef[0];
  out.calibration_delta_bic_leaving_prior = c.dbic_leave;
  out.calibration_outside_prior = c.outside_prior;
  out.calibration_beyond_prior = c.beyond;
  out.scale_absorbed_energy_pct = 100.0 * c.absorbed_j / std::max(1e-9, std::abs(o.measured_j.sum()));
  out.lag1_autocorrelation = diag::lag1_autocorrelation(Eigen::VectorXd(o.measured_j - c.model.x * k));
  out.effective_windows = c.model.n_eff;
  out.heldout_rmse_calibrated_j = diag::rmse(c.model.heldout, o.measured_j);
  out.heldout_energy_error_pct_calibrated = diag::energy_error_pct(c.model.heldout, o.measured_j);
  out.lag_samples = static_cast<int>(std::lround(lag.samples));
  out.lag_s = lag.seconds;
  out.lag_ci_low_s = lag.low_s;
  out.lag_ci_high_s = lag.high_s;
  out.lag_estimated = lag.estimated;
}

// The path the GPS fixes trace [m], a fix that jumps farther than the car could go since the last one skipped (a
// glitch must not make a unit slip of the speed channel).
double gps_track_m(const Recording& r) {
  const auto& lat = *r.latitude_deg;
  const auto& lon = *r.longitude_deg;
  const double north_m_per_deg = units::kEarthRadius_m * units::deg_to_rad(1.0);
  double track_m = 0.0;
  std::size_t last = 0;
  for (std::size_t i = 1; i < r.time_s.size() && i < lat.size() && i < lon.size(); ++i) {
    const double east_m_per_deg = north_m_per_deg * std::cos(units::deg_to_rad(lat[last]));
    const double step_m = std::hypot((lat[i] - lat[last]) * north_m_per_deg, (lon[i] - lon[last]) * east_m_per_deg);
    const double reach_m = 3.0 * std::max(r.speed_mps[i], r.speed_mps[last]) * (r.time_s[i] - r.time_s[last]) + 50.0;
    if (!std::isfinite(step_m) || step_m > reach_m) continue;  // a glitch: measure from the last good fix
    if (r.time_s[i] - r.time_s[i - 1] > kReportedGap_s) {  // a gap: unrecorded, as the speed's distance leaves it out
      last = i;
      continue;
    }
    track_m += step_m;
    last = i;
  }
  return track_m;
}

// A recording against the model by a factor no physics a road car leaves out explains, or a speed channel whose
// distance is not the GPS track's, is said before any finding is read as physics: these are units and mappings. The
// band is 0.6-1.67: the real recordings read 0.79-1.16, and speed in mph read as km/h gave an EV 0.57 with no word
// (a band of 0.5-2 then; session 25's outside testing).
std::vector<std::string> unit_slip_warnings(const std::vector<Recording>& recordings, double raw_error_pct) {
  std::vector<std::string> out;
  const double ratio = 1.0 + raw_error_pct / 100.0;
  constexpr double kLowestPhysicalRatio = 0.6;
  if (!(ratio > kLowestPhysicalRatio && ratio < 1.0 / kLowestPhysicalRatio)) {
    out.push_back("warning: the model's energy is " + fixed(ratio, 2) + " x the recording's (uncalibrated error " +
                  fixed(raw_error_pct, 1) + " %), beyond what missing physics explains: check the units and the mapping "
                  "of the speed and energy channels (--column, --scale) before reading the findings as physics");
  }
  for (const auto& r : recordings) {
    if (!r.latitude_deg || !r.longitude_deg) continue;
    const double speed_m = r.distance_m();
    const double gps_m = gps_track_m(r);
    if (!(gps_m > 1000.0 && speed_m > 0.0)) continue;
    const double k = gps_m / speed_m;
    if (k > 0.7 && k < 1.0 / 0.7) continue;
    out.push_back("warning: " + r.source + ": the speed channel covers " + fixed(speed_m / 1e3, 2) + " km and the GPS track " +
                  fixed(gps_m / 1e3, 2) + " km (x" + fixed(k, 2) + "; km/h read as m/s is x3.6, mph as km/h x1.61): is the "
                  "speed in the unit its mapping says?");
  }
  return out;
}

}  // namespace

std::vector<bool> engine_off_samples(const Recording& r, double min_s) {
  const std::size_t n = r.time_s.size();
  std::vector<bool> off(n, false);
  if (!r.fuel_rate_m3ps || !(min_s > 0.0)) return off;
  const auto& fuel = *r.fuel_rate_m3ps;
  std::size_t i = 0;
  while (i < n) {
    // No flow: zero, or a meter's zero offset below it.
    if (!(r.speed_mps[i] == 0.0 && fuel[i] <= 0.0)) {
      ++i;
      continue;
    }
    std::size_t j = i;
    while (j + 1 < n && r.speed_mps[j + 1] == 0.0 && fuel[j + 1] <= 0.0) ++j;
    if (r.time_s[j] - r.time_s[i] >= min_s)
      for (std::size_t k = i; k <= j; ++k) off[k] = true;
    i = j + 1;
  }
  return off;
}

std::vector<double> heading_from_gps(const std::vector<double>& latitude_deg, const std::vector<double>& longitude_deg,
                                     double baseline_m) {
  const std::size_t n = std::min(latitude_deg.size(), longitude_deg.size());
  std::vector<double> heading(n, 0.0);
  if (n == 0) return heading;
  const double east_m_per_deg = units::kEarthRadius_m * std::cos(units::deg_to_rad(latitude_deg.front())) * units::deg_to_rad(1.0);
  const double north_m_per_deg = units::kEarthRadius_m * units::deg_to_rad(1.0);
  auto east = [&](std::size_t i) { return (longitude_deg[i] - longitude_deg.front()) * east_m_per_deg; };
  auto north = [&](std::size_t i) { return (latitude_deg[i] - latitude_deg.front()) * north_m_per_deg; };
  std::size_t j = 0;
  bool any = false;
  for (std::size_t i = 0; i < n; ++i) {
    j = std::max(j, i + 1);
    while (j < n && std::hypot(east(j) - east(i), north(j) - north(i)) < baseline_m) ++j;
    if (j < n) {
      heading[i] = std::atan2(east(j) - east(i), north(j) - north(i));
      any = true;
    } else {
      heading[i] = i > 0 ? heading[i - 1] : 0.0;
    }
  }
  if (!any) return {};
  return heading;
}

DriveCycle cycle_of_recording(const Recording& r, double engine_off_min_s, EngineStart start) {
  // A staircase speed (a coarse channel sampled fast) replayed as it is fakes accelerations of a step per sample.
  std::vector<double> speed = read_speed_resolution(r.time_s, r.speed_mps).speed_mps;
  if (r.grade || !r.elevation_m) return cycle_from(r, engine_off_min_s, start, std::move(speed), nullptr);
  const ElevationGrade read = grade_from_elevation(r.time_s, r.speed_mps, *r.elevation_m);
  return cycle_from(r, engine_off_min_s, start, std::move(speed), &read.grade);
}

Diagnosis diagnose(const Vehicle& vehicle, const std::vector<Recording>& recordings, const DiagnoseOptions& opt) {
  using namespace diag;
  if (recordings.empty()) throw InputError("--recording", "at least one recording is needed");
  // Held out by recording, a copy would be predicted from itself and the held-out score would mean nothing.
  for (std::size_t j = 1; j < recordings.size(); ++j) {
    for (std::size_t i = 0; i < j; ++i) {
      const Recording& a = recordings[i];
      const Recording& b = recordings[j];
      if (a.time_s == b.time_s && a.speed_mps == b.speed_mps && a.battery_power_w == b.battery_power_w &&
          a.battery_current_a == b.battery_current_a && a.soc_fraction == b.soc_fraction &&
          a.fuel_rate_m3ps == b.fuel_rate_m3ps && a.ambient_temp_k == b.ambient_temp_k) {
        throw InputError(b.source, "holds the same samples (time, speed, energy channel) as " + a.source +
                                                   "; give each recording once: held out by recording, a copy would be "
                                                   "scored against itself");
      }
    }
  }
  Diagnosis out;
  GradeNoiseDraws grade_draws;
  std::vector<DriveCycle> cycles = cycles_of(recordings, opt, out.notes, grade_draws);
  const Observations obs = build_windows(vehicle, recordings, opt.window_s, opt, out.notes);
  out.channel = to_string(obs.channel);
  out.windows = static_cast<int>(obs.n());
  out.window_s = obs.window_s;
  const EffectContext ctx = effect_context(vehicle);
  const AmbientSetting amb = ambient_setting(recordings, obs.channel, opt, out.notes);
  Replayer rp{vehicle, cycles, {}, obs.channel == ChannelKind::soc, opt.threads};
  // Air density follows the recorded ambient (rho ~ 1 / T at one pressure, the vehicle's taken at 20 degC): known
  // physics of the replay where ambient_rrc is tested, not left for it to absorb.
  if (amb.testable && opt.air_density_from_ambient) {
    for (double t : amb.ambient_k) rp.per_recording.push_back(drag_scale(293.15 / t - 1.0, ctx.rho_cda_kg_per_m));
    out.notes.push_back("air density per recording from its recorded ambient (reference 20 degC)");
  }
  Variant base;
  LagEstimate lag;
  choose_channel_sampling(rp, obs, opt.priors.scale_bound(obs.channel), base, lag, out);
  base.window_j = window_energies(base, obs, lag.samples);
  out.raw_trip_energy_error_pct = energy_error_pct(base.window_j, obs.measured_j);
  for (auto& w : unit_slip_warnings(recordings, out.raw_trip_energy_error_pct)) out.notes.push_back(std::move(w));
  set_engine_starts(cycles, recordings, obs, base, opt, out);
  const Signatures sig = compute_signatures(rp, obs, base, lag.samples, amb, ctx, opt);
  const Calibration cal = calibrate(obs, sig.base, sig.rrc, sig.drag, opt.priors, opt.bic_threshold);
  report_calibration(cal, obs, lag, out);
  SelectionContext sc{rp, obs, sig.base, lag.samples, ctx, amb, recordings, opt, {}};
  out.located = locate_regimes(obs, recordings, cycles, sig, cal.model.fit.coef, lag.samples, &sc.standing);
  const NoiseFloor floor = calibrated_noise_floor(obs, recordings, sig, cal, lag.samples, ctx.mass_kg, grade_draws, opt);
  const Adequacy before = test_adequacy(obs, recordings, per_recording_residual(cal.model, obs, recordings.size()), floor, opt);
  out.noise_floor_j = std::sqrt(floor.window_variance_j2());
  out.residual_to_noise_ratio = before.ratio, out.residual_to_noise_z = before.z, out.adequacy_scale_s = before.scale_s;

  Model m = cal.model;
  std::vector<EffectId> chosen;
  out.findings = select_effects(sc, sig.candidates, m, chosen);
  describe_wind(cycles, out.findings, out.notes);
  out.detection_limits = detection_limits(sig.candidates, chosen, m, opt);
  if (sc.opt.infer_road_profile) {
    if (auto f = infer_road_profile(sc, cycles, sig, out.findings, chosen, floor, m, out.notes)) {
      out.findings.push_back(std::move(*f));
      // The detection limits are the profile's residual's: they had been read from the hills' own residual (aux_load
      // 6.5-10 kW, wind 167-262 m/s behind 25 m hills; session 27's outside tester). The catalogue is not searched
      // again behind the profile: the linearised profile leaves shapes that a second search named (rr_speed 0.17
      // beside a 400 W load, test DetectionLimitsBehindWithheldHillsAreTheirProfilesResiduals); what it leaves goes to
      // the unexplained basis below.
      chosen.push_back(EffectId::road_profile);  // the profile's column, so that each later column keeps its effect
      out.detection_limits = detection_limits(sig.candidates, chosen, m, opt);
    }
  }
  if (auto f = describe_unexplained(sc, cycles, sig.basis, m)) out.findings.push_back(std::move(*f));
  const Adequacy after = test_adequacy(obs, recordings, per_recording_residual(m, obs, recordings.size()), floor, opt);
  out.final_residual_to_noise_ratio = after.ratio, out.final_residual_to_noise_z = after.z;
  // Never nothing_missing above the noise floor, nor behind a calibration held at its prior's bound.
  if (after.inadequate || (cal.outside_prior && out.findings.empty())) {
    const bool from_elevation = std::any_of(recordings.begin(), recordings.end(), grade_from_recorded_elevation);
    Finding f = adequacy_finding(after, floor, obs, recordings, out.located, from_elevation);
    if (cal.at_bound) f.description += (after.inadequate ? "; " : "") + calibration_outside_prior_text(cal, obs, sig.candidates);
    out.findings.push_back(std::move(f));
  } else if (cal.at_bound) {
    // Beyond the bound with findings, they take what the calibration would have absorbed (the note said "not
    // significantly beyond it" beside a Delta BIC the data was sure of). With findings, the calibration is said as
    // it reads beside them: the note had said "no catalogue effect alone explains that energy" beside an aux_load
    // found at its true 300 W (session 24's outside testing).
    const bool found = !out.findings.empty();
    out.notes.push_back((cal.outside_prior ? "calibration beyond its prior's bound before the findings: "
                                           : "calibration at its prior's bound, not significantly beyond it: ") +
                        // Within its prior, what "could explain it" or "the model lacks" would contradict the
                        // verdict beside it (session 28's outside tester read both on one nothing_missing).
                        calibration_outside_prior_text(cal, obs, sig.candidates, !found && cal.outside_prior) +
                        (found ? "; beside the findings it is as the calibration line says" : ""));
  }
  if (!out.findings.empty()) {
    const Eigen::VectorXd& k = m.fit.coef;
    out.channel_scale_with_findings = k[0];
    out.rrc_level_change_with_findings = 0.1 * k[1] / k[0];
    out.drag_change_with_findings = 0.1 * k[2] / k[0];
  }
  out.verdict = out.findings.empty() ? "nothing_missing"
                : out.findings.front().confounded_with.empty() ? "missing_physics" : "confounded";
  out.series = window_series(obs, recordings, sig.base.window_j, cal.model.x * cal.model.fit.coef, m.x * m.fit.coef);
  return out;
}

}  // namespace rollsim
