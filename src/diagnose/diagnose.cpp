// Diagnosis: kinematic replay, window energies, calibration, effect signatures, selection by BIC, held-out scoring.
#include "rollsim/diagnose/diagnose.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <atomic>
#include <cmath>
#include <fstream>
#include <map>
#include <mutex>
#include <optional>
#include <sstream>
#include <thread>
#include <tuple>

#include "rollsim/common/error.hpp"
#include "rollsim/cycle/drive_cycle.hpp"
#include "rollsim/diagnose/elevation.hpp"
#include "rollsim/sim/simulation.hpp"

namespace rollsim {
namespace {

// Calibration signature of the aero (C) term: a force k * 0.5 rho CdA v^2 (k = fractional change).
class DragScale final : public Effect {
 public:
  DragScale(double k, double rho_cda) : k_(k), half_rho_cda_(0.5 * rho_cda) {}
  std::string id() const override { return "calibration_drag"; }
  double extra_resistance_n(const EffectInputs& in, const double*) const override {
    const double v = std::max(in.speed_mps, 0.0);
    return k_ * half_rho_cda_ * v * v;
  }

 private:
  double k_, half_rho_cda_;
};

// Calibration signature of the RRC level: a constant factor on rolling resistance.
class RrcLevel final : public Effect {
 public:
  explicit RrcLevel(double k) : k_(k) {}
  std::string id() const override { return "calibration_rrc"; }
  double rolling_resistance_factor(const EffectInputs&, const double*) const override { return 1.0 + k_; }

 private:
  double k_;
};

// Basis of the unexplained-residual description (not a catalogue effect): a force of one shape, per unit
// amplitude, optionally decaying from the start of the trip. Run through the simulator so that the powertrain's
// efficiency, regen and fuel cut weigh it as they would weigh a real force.
enum class ForceShape { constant, speed, speed_squared, positive_accel };
class SignatureForce final : public Effect {
 public:
  SignatureForce(ForceShape shape, double decay_s) : shape_(shape), decay_s_(decay_s) {}
  std::string id() const override { return "signature_force"; }
  double extra_resistance_n(const EffectInputs& in, const double*) const override {
    constexpr double kV100 = 100.0 / 3.6;
    const double v = std::max(in.speed_mps, 0.0);
    double f = 0.0;
    switch (shape_) {
      case ForceShape::constant: f = v > 0.1 ? 1.0 : 0.0; break;  // 1 N while moving
      case ForceShape::speed: f = v / kV100; break;               // 1 N at 100 km/h
      case ForceShape::speed_squared: f = (v / kV100) * (v / kV100); break;
      case ForceShape::positive_accel: f = std::max(in.accel_mps2, 0.0); break;  // 1 kg x a
    }
    return decay_s_ > 0.0 ? f * std::exp(-in.time_s / decay_s_) : f;
  }

 private:
  ForceShape shape_;
  double decay_s_;
};

EffectContext context_of(const Vehicle& v) {
  EffectContext c;
  c.mass_kg = v.body.test_mass_kg;
  c.rho_cda_kg_per_m = v.coastdown ? 2.0 * v.coastdown->c_n_s2_per_m2
                                   : v.body.air_density_kg_per_m3 * v.body.drag_coefficient * v.body.frontal_area_m2;
  return c;
}


// Measured power per sample [W] in the energy domain of the simulation (battery terminals or fuel chemical).
// SOC is handled per window (a difference), so it returns an empty vector and sets `soc` instead.
std::vector<double> measured_power_w(const Vehicle& v, const Recording& r, std::string& channel) {
  if (r.battery_power_w) {
    channel = "battery_power";
    return *r.battery_power_w;
  }
  if (r.battery_voltage_v && r.battery_current_a) {
    channel = "battery_voltage_x_current";
    std::vector<double> p(r.time_s.size());
    for (std::size_t i = 0; i < p.size(); ++i) p[i] = (*r.battery_voltage_v)[i] * (*r.battery_current_a)[i];
    return p;
  }
  if (r.fuel_rate_m3ps) {
    const auto* cp = std::get_if<CombustionPowertrainParams>(&v.powertrain);
    if (!cp) throw InputError(r.source, "fuel rate recorded but the vehicle is electric");
    channel = "fuel_rate";
    std::vector<double> p(r.time_s.size());
    const double j_per_m3 = cp->fuel.density_kg_per_m3 * cp->fuel.lower_heating_value_j_per_kg;
    for (std::size_t i = 0; i < p.size(); ++i) p[i] = (*r.fuel_rate_m3ps)[i] * j_per_m3;
    return p;
  }
  channel = "soc";
  return {};
}

// The simulated counterpart of the measured channel: fuel power, battery terminal power, or, for a state of charge
// (which counts what leaves the cells), terminal power plus the cells' internal loss.
// Segment means, as the replay integrates them: summed as mean x dt they are `simulate`'s energy on the same trace.
double sim_power_w(const TracePoint& t, bool electric, double fuel_j_per_m3, bool cells) {
  if (!electric) return t.segment_fuel_rate_m3_per_s * fuel_j_per_m3;
  return cells ? t.segment_battery_power_w + t.segment_battery_loss_w : t.segment_battery_power_w;
}

struct Window {
  std::size_t rec = 0, begin = 0, end = 0;  // sample range [begin, end]
};

// Everything the fit needs, per sample and per window, for one model variant.
struct Variant {
  std::vector<std::vector<double>> power_w;  // per recording, per segment start
  Eigen::VectorXd window_j;
};

struct Data {
  std::vector<Window> windows;
  std::vector<std::vector<double>> dt_s;  // per recording, per segment
  Eigen::VectorXd measured_j;
  std::vector<std::vector<double>> measured_w;  // empty for SOC
  std::string channel;
  int lag_samples = 0;  // measured channel lags the simulation by this many samples (calibration)
  // Known per-recording physics in every variant (nullptr: none): air density at the recorded ambient.
  std::vector<std::shared_ptr<const Effect>> per_recording;
};

// Simulated channel power per sample for one model variant (the base model plus `extra` effects).
std::vector<std::vector<double>> simulate_power(const Vehicle& vehicle, const std::vector<DriveCycle>& cycles,
                                                const std::vector<std::shared_ptr<const Effect>>& extra, bool cells,
                                                const std::vector<std::shared_ptr<const Effect>>& per_recording) {
  VehicleModel model = VehicleModel::assemble(vehicle);
  for (const auto& e : extra) model.effects.push_back(e);
  const bool electric = vehicle.is_electric();
  double fuel_j_per_m3 = 0.0;
  if (const auto* cp = std::get_if<CombustionPowertrainParams>(&vehicle.powertrain))
    fuel_j_per_m3 = cp->fuel.density_kg_per_m3 * cp->fuel.lower_heating_value_j_per_kg;
  SimulationOptions so;
  so.record_trace = true;
  std::vector<std::vector<double>> out;
  for (std::size_t ci = 0; ci < cycles.size(); ++ci) {
    const auto& c = cycles[ci];
    const bool own = ci < per_recording.size() && per_recording[ci];
    if (own) model.effects.push_back(per_recording[ci]);
    const SimulationResult r = simulate_replay(model, c, so);
    if (own) model.effects.pop_back();
    std::vector<double> p(r.trace.size());
    for (std::size_t i = 0; i < p.size(); ++i) p[i] = sim_power_w(r.trace[i], electric, fuel_j_per_m3, cells);
    out.push_back(std::move(p));
  }
  return out;
}

// Window energies of per-sample powers, the simulation shifted by the channel lag.
Eigen::VectorXd window_energies(const std::vector<std::vector<double>>& power_w, const Data& d) {
  Eigen::VectorXd e(static_cast<Eigen::Index>(d.windows.size()));
  const auto lag = static_cast<std::size_t>(d.lag_samples);
  for (std::size_t w = 0; w < d.windows.size(); ++w) {
    const auto& win = d.windows[w];
    double sum = 0.0;
    for (std::size_t i = win.begin; i < win.end; ++i) sum += power_w[win.rec][i >= lag ? i - lag : 0] * d.dt_s[win.rec][i];
    e[static_cast<Eigen::Index>(w)] = sum;
  }
  return e;
}

// Many model variants: independent replays, so they run in parallel (each thread assembles its own model).
std::vector<Variant> run_variants(const Vehicle& vehicle, const std::vector<DriveCycle>& cycles, const Data& d,
                                  const std::vector<std::vector<std::shared_ptr<const Effect>>>& extras, unsigned threads) {
  std::vector<Variant> out(extras.size());
  std::atomic<std::size_t> next{0};
  std::exception_ptr failure;
  std::mutex failure_mutex;
  auto work = [&] {
    for (std::size_t k = next++; k < extras.size(); k = next++) {
      try {
        out[k].power_w = simulate_power(vehicle, cycles, extras[k], d.channel == "soc", d.per_recording);
        out[k].window_j = window_energies(out[k].power_w, d);
      } catch (...) {
        const std::lock_guard<std::mutex> lock(failure_mutex);
        if (!failure) failure = std::current_exception();
      }
    }
  };
  const unsigned n = std::max(1u, std::min<unsigned>(threads ? threads : std::thread::hardware_concurrency(),
                                                     static_cast<unsigned>(extras.size())));
  std::vector<std::thread> pool;
  for (unsigned t = 1; t < n; ++t) pool.emplace_back(work);
  work();
  for (auto& t : pool) t.join();
  if (failure) std::rethrow_exception(failure);
  return out;
}

struct Fit {
  Eigen::VectorXd coef;
  Eigen::MatrixXd cov;  // unscaled (X'X)^-1 sigma^2
  double rss = 0.0;
};

// Gaussian priors on calibration coefficients, as extra rows (ridge towards 0): weight = noise sd / prior sd.
struct Prior {
  std::vector<std::pair<Eigen::Index, double>> rows;  // column, weight
};

void augment(const Eigen::MatrixXd& x, const Eigen::VectorXd& y, const Prior& p, Eigen::MatrixXd& xa, Eigen::VectorXd& ya) {
  const auto np = static_cast<Eigen::Index>(p.rows.size());
  xa = Eigen::MatrixXd::Zero(x.rows() + np, x.cols());
  ya = Eigen::VectorXd::Zero(x.rows() + np);
  xa.topRows(x.rows()) = x;
  ya.head(x.rows()) = y;
  for (Eigen::Index k = 0; k < np; ++k) xa(x.rows() + k, p.rows[static_cast<std::size_t>(k)].first) = p.rows[static_cast<std::size_t>(k)].second;
}

Fit least_squares(const Eigen::MatrixXd& x, const Eigen::VectorXd& y, const Prior& prior = {}) {
  Fit f;
  Eigen::MatrixXd xa;
  Eigen::VectorXd ya;
  augment(x, y, prior, xa, ya);
  f.coef = xa.colPivHouseholderQr().solve(ya);
  const Eigen::VectorXd r = y - x * f.coef;
  f.rss = r.squaredNorm();
  const double dof = std::max<double>(1.0, static_cast<double>(x.rows() - x.cols()));
  f.cov = (xa.transpose() * xa).completeOrthogonalDecomposition().pseudoInverse() * (f.rss / dof);
  return f;
}

double lag1_autocorrelation(const Eigen::VectorXd& r) {
  if (r.size() < 3) return 0.0;
  const double mean = r.mean();
  double num = 0.0, den = 0.0;
  for (Eigen::Index i = 0; i < r.size(); ++i) {
    den += (r[i] - mean) * (r[i] - mean);
    if (i > 0) num += (r[i] - mean) * (r[i - 1] - mean);
  }
  return den > 0.0 ? num / den : 0.0;
}

// Out-of-fold prediction: each window predicted by a fit on the other folds (alternating blocks of windows within
// one recording, or whole recordings when several are given).
Eigen::VectorXd heldout_prediction(const Eigen::MatrixXd& x, const Eigen::VectorXd& y, const std::vector<int>& fold_of,
                                   const Prior& prior) {
  const Eigen::Index n = x.rows();
  Eigen::VectorXd pred(n);
  const int folds = 1 + *std::max_element(fold_of.begin(), fold_of.end());
  for (int fold = 0; fold < folds; ++fold) {
    std::vector<Eigen::Index> train, test;
    for (Eigen::Index i = 0; i < n; ++i) (fold_of[static_cast<std::size_t>(i)] == fold ? test : train).push_back(i);
    if (train.empty()) train = test;
    Eigen::MatrixXd xt(static_cast<Eigen::Index>(train.size()), x.cols());
    Eigen::VectorXd yt(static_cast<Eigen::Index>(train.size()));
    for (std::size_t k = 0; k < train.size(); ++k) {
      xt.row(static_cast<Eigen::Index>(k)) = x.row(train[k]);
      yt[static_cast<Eigen::Index>(k)] = y[train[k]];
    }
    const Eigen::VectorXd c = least_squares(xt, yt, prior).coef;
    for (Eigen::Index i : test) pred[i] = x.row(i).dot(c);
  }
  return pred;
}

double rmse(const Eigen::VectorXd& a, const Eigen::VectorXd& b) {
  return std::sqrt((a - b).squaredNorm() / static_cast<double>(std::max<Eigen::Index>(1, a.size())));
}
double energy_error_pct(const Eigen::VectorXd& pred, const Eigen::VectorXd& meas) {
  return 100.0 * (pred.sum() - meas.sum()) / std::max(1e-9, std::abs(meas.sum()));
}

Eigen::MatrixXd hcat(const Eigen::MatrixXd& a, const Eigen::VectorXd& b) {
  Eigen::MatrixXd m(a.rows(), a.cols() + 1);
  m << a, b;
  return m;
}

// A candidate: a catalogue effect with its shape parameters fixed (hidden-state effects: one per time constant).
struct Candidate {
  std::string id;
  std::string label;
  EffectParameters shape;
  double nominal = 0.0;
  std::string amplitude_name, amplitude_unit;
  double amp_min = 0.0, amp_max = 0.0;
  Eigen::VectorXd signature;  // window energy per unit amplitude
  bool across_trips = false;  // ambient_rrc: a per-recording level, derived from the RRC-level variant (no own run)
};

std::string num(double v) {
  std::ostringstream os;
  os.precision(6);
  os << v;
  return os.str();
}

// Median of the non-zero steps of a quantised signal (its quantum), 0 if it never changes.
double quantum_of(const std::vector<double>& x) {
  std::vector<double> steps;
  for (std::size_t i = 1; i < x.size(); ++i)
    if (x[i] != x[i - 1]) steps.push_back(std::abs(x[i] - x[i - 1]));
  if (steps.empty()) return 0.0;
  std::nth_element(steps.begin(), steps.begin() + static_cast<std::ptrdiff_t>(steps.size() / 2), steps.end());
  return steps[steps.size() / 2];
}

std::string fixed(double v, int digits) {
  std::ostringstream os;
  os.setf(std::ios::fixed);
  os.precision(digits);
  os << v;
  return os.str();
}

// Time-constant parameters profiled when their effect is found: effect, parameter, grid range.
struct TimeParameter {
  const char* effect;
  const char* parameter;
  double low, high;
};
constexpr TimeParameter kTimeParameters[] = {
    {"tyre_warmup", "heat_capacity_j_per_k", 10000.0, 320000.0},   // tau ~ C / h: ~3-60 min at 20-50 W/K
    {"engine_warmup", "heat_capacity_j_per_k", 25000.0, 800000.0},  // oil, block and coolant of small to large engines
};
// The unexplained basis' decay grid [s]: from 2.5 min to 80 min (the basis' own 300-2400 s lie on it).
constexpr double kDecayGridLowS = 150.0, kDecayGridHighS = 4800.0;

// low, low 2^(1/k), ... up to high (and `also`, the value already chosen, merged in), ascending.
std::vector<double> log_grid(double low, double high, int per_octave, double also) {
  std::vector<double> g;
  const int k = std::max(1, per_octave);
  for (int i = 0;; ++i) {
    const double v = low * std::pow(2.0, static_cast<double>(i) / k);
    if (v > high * (1.0 + 1e-9)) break;
    g.push_back(std::abs(v - also) <= 1e-9 * also ? also : v);  // the chosen value itself where it lies on the grid
  }
  if (std::find(g.begin(), g.end(), also) == g.end()) g.push_back(also);
  std::sort(g.begin(), g.end());
  return g;
}

// A basis shape of the unexplained-residual description.
struct BasisShape {
  enum Kind { force, power } kind = force;
  ForceShape shape = ForceShape::constant;
  double decay_s = 0.0;  // 0: no decay
  Eigen::VectorXd signature;
};

}  // namespace

namespace {

// Mean residual of each regime (in `order`, those with two values or more) with a 95 % normal interval whose
// variance is inflated for AR(1) correlation of the values (lag-1 autocorrelation `rho`, clamped to [0, 0.99]).
void append_regime_means(const std::vector<std::string>& order, const std::map<std::string, std::vector<double>>& vals,
                         double rho, std::vector<RegimeResidual>& out) {
  const double rs = std::clamp(rho, 0.0, 0.99);
  const double factor = (1.0 + rs) / (1.0 - rs);
  for (const auto& name : order) {
    const auto it = vals.find(name);
    if (it == vals.end() || it->second.size() < 2) continue;
    const auto& v = it->second;
    double mean = 0.0, var = 0.0;
    for (double e : v) mean += e;
    mean /= static_cast<double>(v.size());
    for (double e : v) var += (e - mean) * (e - mean);
    var /= static_cast<double>(v.size() - 1);
    const double half = 1.96 * std::sqrt(var * factor / static_cast<double>(v.size()));
    out.push_back({name, static_cast<int>(v.size()), mean, mean - half, mean + half});
  }
}

}  // namespace

ProfileInterval profile_likelihood_interval(const std::vector<double>& grid, const std::vector<double>& rss, double n_eff,
                                            double critical) {
  if (grid.empty() || grid.size() != rss.size()) throw InputError("profile", "grid and RSS must be non-empty and of one length");
  for (std::size_t i = 0; i < grid.size(); ++i) {
    if (!(grid[i] > 0.0) || (i > 0 && !(grid[i] > grid[i - 1]))) throw InputError("profile", "grid must be positive and ascending");
    if (!(rss[i] > 0.0)) throw InputError("profile", "RSS must be positive");
  }
  ProfileInterval p;
  p.best = static_cast<std::size_t>(std::min_element(rss.begin(), rss.end()) - rss.begin());
  p.value = grid[p.best];
  auto stat = [&](std::size_t i) { return n_eff * std::log(rss[i] / rss[p.best]); };
  // Where the statistic crosses `critical` between grid points i (inside) and o (outside), in log(parameter).
  auto crossing = [&](std::size_t i, std::size_t o) {
    const double si = stat(i), so = stat(o);
    const double f = so > si ? (critical - si) / (so - si) : 0.0;
    return std::exp(std::log(grid[i]) + f * (std::log(grid[o]) - std::log(grid[i])));
  };
  std::size_t lo = p.best, hi = p.best;
  while (lo > 0 && stat(lo - 1) < critical) --lo;
  while (hi + 1 < grid.size() && stat(hi + 1) < critical) ++hi;
  p.low_open = lo == 0;
  p.high_open = hi + 1 == grid.size();
  p.low = p.low_open ? grid.front() : crossing(lo, lo - 1);
  p.high = p.high_open ? grid.back() : crossing(hi, hi + 1);
  return p;
}

DriveCycle cycle_of_recording(const Recording& r) {
  DriveCycle c;
  c.name = r.source;
  c.source = r.source;
  // Time from the start of the recording: effects that decay from the start of a trip read it.
  c.time_s = r.time_s;
  for (double& t : c.time_s) t -= r.time_s.front();
  c.speed_mps = r.speed_mps;
  if (r.grade) c.grade = *r.grade;
  else if (r.elevation_m) c.grade = grade_from_elevation(r.time_s, r.speed_mps, *r.elevation_m).grade;
  else c.grade.assign(r.time_s.size(), 0.0);
  // Quantised to 0.05 % (under 0.3 N per 100 kg of grade force error): the simulator prepares the tyre model once
  // per distinct grade, which otherwise is once per sample and 90 % of a hilly recording's diagnosis.
  for (double& g : c.grade) g = 0.0005 * std::round(g / 0.0005);
  return c;
}

std::string separating_test(const std::string& a, const std::string& b) {
  // Each pair's confusion (docs/diagnose.md) and the experiment that breaks it: a variable that moves one
  // signature and not the other.
  static const std::vector<std::tuple<std::string, std::string, std::string>> kTests{
      {"mass", "rotational_inertia", "drive a route with grade, or weigh the car: mass also loads the grade and the tyres, inertia only acceleration"},
      {"mass", "rr_speed", "weigh the car, or compare an uphill and a downhill run at the same speed"},
      {"mass", "road_grade", "drive the route in both directions: a grade changes sign, a mass error does not"},
      {"aux_load", "rr_speed", "log a long standstill with the car switched on: an auxiliary load draws power at zero speed, rolling resistance does not"},
      {"aux_load", "tyre_warmup", "log a standstill early and late in the trip: an auxiliary load draws at standstill, a tyre warms only while rolling"},
      {"wind", "rr_speed", "drive the same road in both directions: a headwind reverses, rolling resistance does not"},
      {"wind", "mass", "drive the same road in both directions, or at two steady speeds: wind grows with speed squared, mass with acceleration"},
      {"tyre_warmup", "engine_warmup", "idle the cold car for ten minutes before driving: an engine warms idling, a tyre only rolling"},
      {"tyre_warmup", "ambient_rrc", "repeat the trip with a warm start: a warm-up decays within the trip, an ambient effect stays"},
      {"battery_resistance", "tyre_slip", "compare hard accelerations at low and high speed: battery loss follows current squared, slip loss also grows with speed"},
      {"regen_limit", "rotational_inertia", "brake at different strengths from the same speed: a regen limit shows only above its power, inertia in every braking"},
      {"road_grade", "rr_speed", "drive the route in both directions, or record elevation: grade reverses with direction"},
  };
  for (const auto& [x, y, text] : kTests) {
    if ((a == x && b == y) || (a == y && b == x)) return text;
  }
  return "vary the conditions that move one signature and not the other (speed, acceleration, grade, time since start, "
         "direction of travel) in a second recording";
}

Diagnosis diagnose(const Vehicle& vehicle, const std::vector<Recording>& recordings, const DiagnoseOptions& opt) {
  if (recordings.empty()) throw InputError("--recording", "at least one recording is needed");
  Diagnosis out;
  Data d;
  std::vector<DriveCycle> cycles;
  double soc_capacity_j = 0.0;
  if (const auto* ep = std::get_if<ElectricPowertrainParams>(&vehicle.powertrain)) soc_capacity_j = ep->battery.usable_capacity_j;
  for (const Recording& r : recordings) {
    cycles.push_back(cycle_of_recording(r));
    if (!r.grade && r.elevation_m) {
      const ElevationGrade eg = grade_from_elevation(r.time_s, r.speed_mps, *r.elevation_m);
      out.notes.push_back(r.source + ": grade from recorded elevation (" + std::to_string(eg.rejected_steps) +
                          " elevation steps rejected as glitches, Savitzky-Golay slope over 300 m)");
    }
  }
  // SOC: lengthen the windows until the quantisation error is small against a window's energy.
  double window_s = opt.window_s;
  {
    std::string ch;
    measured_power_w(vehicle, recordings.front(), ch);
    if (ch == "soc" && soc_capacity_j > 0.0) {
      double q = 0.0, drop_j = 0.0, duration = 0.0;
      for (const auto& r : recordings) {
        q = std::max(q, quantum_of(*r.soc_fraction));
        drop_j += (r.soc_fraction->front() - r.soc_fraction->back()) * soc_capacity_j;
        duration += r.duration_s();
      }
      const double mean_power_w = drop_j / std::max(1.0, duration);
      if (q > 0.0 && mean_power_w > 0.0) {
        const double needed = q * soc_capacity_j / std::sqrt(6.0) / (opt.soc_quantisation_fraction * mean_power_w);
        window_s = std::max(window_s, std::ceil(needed / 10.0) * 10.0);
      }
      out.notes.push_back("SOC quantum " + fixed(100.0 * q, 3) + " % (" + fixed(q * soc_capacity_j / 1e3, 1) +
                          " kJ), mean power " + fixed(mean_power_w, 0) + " W: windows of " + fixed(window_s, 0) + " s");
    }
  }
  out.window_s = window_s;
  std::vector<double> meas;
  for (std::size_t ri = 0; ri < recordings.size(); ++ri) {
    const Recording& r = recordings[ri];
    std::string ch;
    d.measured_w.push_back(measured_power_w(vehicle, r, ch));
    if (!d.channel.empty() && d.channel != ch) throw InputError(r.source, "all recordings must carry the same energy channel");
    d.channel = ch;
    std::vector<double> dt(r.time_s.size() - 1);
    for (std::size_t i = 0; i + 1 < r.time_s.size(); ++i) dt[i] = r.time_s[i + 1] - r.time_s[i];
    d.dt_s.push_back(dt);
    std::size_t begin = 0;
    for (std::size_t i = 1; i < r.time_s.size(); ++i) {
      if (r.time_s[i] - r.time_s[begin] >= window_s || i + 1 == r.time_s.size()) {
        if (r.time_s[i] - r.time_s[begin] >= 0.5 * window_s) {
          d.windows.push_back({ri, begin, i});
          double e = 0.0;
          if (ch == "soc") {
            if (soc_capacity_j <= 0.0) throw InputError(r.source, "SOC recorded but the vehicle has no battery");
            e = ((*r.soc_fraction)[begin] - (*r.soc_fraction)[i]) * soc_capacity_j;
          } else {
            for (std::size_t k = begin; k < i; ++k) e += d.measured_w.back()[k] * dt[k];
          }
          meas.push_back(e);
        }
        begin = i;
      }
    }
  }
  const Eigen::Index n = static_cast<Eigen::Index>(d.windows.size());
  if (n < 8) throw InputError("--recording", "too short to diagnose: " + std::to_string(n) + " windows of " + num(window_s) + " s, need 8");
  d.measured_j = Eigen::Map<Eigen::VectorXd>(meas.data(), n);
  out.channel = d.channel;
  out.windows = static_cast<int>(n);
  // Held-out folds: whole recordings when several are given (the honest test of a model), else alternating blocks.
  std::vector<int> fold_of(static_cast<std::size_t>(n));
  for (Eigen::Index w = 0; w < n; ++w)
    fold_of[static_cast<std::size_t>(w)] = recordings.size() > 1 ? static_cast<int>(d.windows[static_cast<std::size_t>(w)].rec)
                                                                  : static_cast<int>((w / opt.block_windows) % 2);

  // Ambient temperature on RRC moves the RRC level from trip to trip, never within one: within one trip it is the
  // RRC level (a calibration quantity). It is a candidate only across recordings whose recorded ambients differ.
  std::vector<double> ambient_k;  // per recording: mean recorded ambient
  bool ambient_testable = false;
  if (recordings.size() < 2) {
    out.notes.push_back("ambient_rrc not tested: one recording (within one trip it is the RRC level, a calibration quantity)");
  } else if (!std::all_of(recordings.begin(), recordings.end(), [](const Recording& r) { return r.ambient_temp_k.has_value(); })) {
    out.notes.push_back("ambient_rrc not tested: not every recording has an ambient_temp_c column");
  } else {
    for (const auto& r : recordings) {
      double sum = 0.0;
      for (double t : *r.ambient_temp_k) sum += t;
      ambient_k.push_back(sum / static_cast<double>(std::max<std::size_t>(1, r.ambient_temp_k->size())));
    }
    const auto [lo, hi] = std::minmax_element(ambient_k.begin(), ambient_k.end());
    ambient_testable = *hi - *lo >= opt.ambient_min_spread_k;
    out.notes.push_back(ambient_testable
                            ? "ambient_rrc tested across " + std::to_string(recordings.size()) + " recordings at " +
                                  fixed(*lo - 273.15, 1) + " to " + fixed(*hi - 273.15, 1) + " degC (one shared RRC level)"
                            : "ambient_rrc not tested: recorded ambients span " + fixed(*hi - *lo, 1) + " K, under " +
                                  fixed(opt.ambient_min_spread_k, 1) + " K (the recordings are at the same ambient)");
  }
  // Reference: the recordings' mean ambient, so that the ambient signature is nearly orthogonal to the shared RRC
  // level (whose prior would otherwise push a level offset into the unpenalised ambient coefficient).
  double ambient_ref_k = 0.0;
  for (double t : ambient_k) ambient_ref_k += t / static_cast<double>(ambient_k.size());
  const EffectContext ctx = context_of(vehicle);
  // Air density follows the recorded ambient (rho ~ 1 / T at one pressure): across trips at different ambients it
  // moves the aero force by about 0.35 % per K, in the same direction as an RRC rising in the cold, so it is known
  // physics of the replay, not left for ambient_rrc to absorb. The vehicle's density (or coast-down) is taken at
  // 20 degC (the coast-down standards' reference). Only where ambient_rrc is tested: within one recording, or at one
  // ambient, it is a level that the aero calibration absorbs.
  if (ambient_testable && opt.air_density_from_ambient) {
    for (double t : ambient_k) d.per_recording.push_back(std::make_shared<DragScale>(293.15 / t - 1.0, ctx.rho_cda_kg_per_m));
    out.notes.push_back("air density per recording from its recorded ambient (reference 20 degC)");
  }
  Variant base;
  base.power_w = simulate_power(vehicle, cycles, {}, d.channel == "soc", d.per_recording);
  // Channel lag (calibration): the shift of the simulated power, 0-10 samples, that best matches the measured.
  if (d.channel != "soc") {
    double best = 1e300;
    for (int lag = 0; lag <= 10; ++lag) {
      double sse = 0.0;
      for (std::size_t ri = 0; ri < recordings.size(); ++ri) {
        const auto& p = base.power_w[ri];
        for (std::size_t i = static_cast<std::size_t>(lag); i < p.size(); ++i) {
          const double e = d.measured_w[ri][i] - p[i - static_cast<std::size_t>(lag)];
          sse += e * e;
        }
      }
      if (sse < best) {
        best = sse;
        d.lag_samples = lag;
      }
    }
  }
  base.window_j = window_energies(base.power_w, d);
  out.lag_samples = d.lag_samples;
  out.raw_trip_energy_error_pct = energy_error_pct(base.window_j, d.measured_j);

  // Every other variant (calibration, catalogue candidates, unexplained basis) in one parallel batch.
  std::vector<std::vector<std::shared_ptr<const Effect>>> extras;
  extras.push_back({std::make_shared<RrcLevel>(0.1)});
  extras.push_back({std::make_shared<DragScale>(0.1, ctx.rho_cda_kg_per_m)});
  std::vector<Candidate> cands;
  for (const auto& info : effect_catalogue()) {
    if (info.id == "ambient_rrc") {
      if (!ambient_testable) continue;
      const EffectParameterInfo& amp = info.parameters.front();  // rrc_change_per_k
      Candidate c;
      c.id = c.label = info.id;
      c.shape = {{"reference_temp_c", ambient_ref_k - 273.15}, {"ambient_temp_c", ambient_ref_k - 273.15}};
      c.nominal = amp.nominal;
      c.amplitude_name = amp.name;
      c.amplitude_unit = amp.unit;
      c.amp_min = amp.min;
      c.amp_max = amp.max;
      c.across_trips = true;
      cands.push_back(std::move(c));
      continue;
    }
    std::vector<EffectParameters> shapes{{}};
    if (info.id == "tyre_warmup") shapes = {{{"heat_capacity_j_per_k", 20000.0}}, {{"heat_capacity_j_per_k", 50000.0}}, {{"heat_capacity_j_per_k", 120000.0}}};
    // The engine's heat capacity is tested at its nominal value only, and profiled once the effect is found.
    if (info.id == "engine_warmup")
      for (const auto& p : info.parameters)
        if (p.name == "heat_capacity_j_per_k") shapes = {{{p.name, p.nominal}}};
    const EffectParameterInfo* amp = nullptr;
    for (const auto& p : info.parameters)
      if (p.amplitude) amp = &p;
    if (!amp) continue;
    for (const auto& shape : shapes) {
      Candidate c;
      c.id = info.id;
      c.shape = shape;
      c.nominal = amp->nominal;
      c.amplitude_name = amp->name;
      c.amplitude_unit = amp->unit;
      c.amp_min = amp->min;
      c.amp_max = amp->max;
      EffectParameters p = shape;
      p[amp->name] = amp->nominal;
      c.label = info.id;
      for (const auto& [k, v] : shape) c.label += " (" + k + " " + num(v) + ")";
      extras.push_back({make_effect(info.id, p, ctx)});
      cands.push_back(std::move(c));
    }
  }
  std::vector<BasisShape> basis;
  std::vector<double> decays{0.0};
  decays.insert(decays.end(), opt.unexplained_decay_s.begin(), opt.unexplained_decay_s.end());
  for (double tau : decays) {
    for (ForceShape fs : {ForceShape::constant, ForceShape::speed, ForceShape::speed_squared, ForceShape::positive_accel}) {
      basis.push_back({BasisShape::force, fs, tau, {}});
      extras.push_back({std::make_shared<SignatureForce>(fs, tau)});
    }
    basis.push_back({BasisShape::power, ForceShape::constant, tau, {}});  // computed directly below
  }
  // 1 W at the measured channel, optionally decaying from the start of each recording (no simulation needed).
  auto power_signature = [&](double decay_s) {
    Eigen::VectorXd sig(n);
    for (Eigen::Index w = 0; w < n; ++w) {
      const auto& win = d.windows[static_cast<std::size_t>(w)];
      double e = 0.0;
      for (std::size_t i = win.begin; i < win.end; ++i)
        e += (decay_s > 0.0 ? std::exp(-cycles[win.rec].time_s[i] / decay_s) : 1.0) * d.dt_s[win.rec][i];
      sig[w] = e;
    }
    return sig;
  };
  const std::vector<Variant> vars = run_variants(vehicle, cycles, d, extras, opt.threads);
  const Variant& rrc = vars[0];
  const Variant& drag = vars[1];
  {
    std::size_t k = 2;
    std::vector<Candidate> kept;
    for (auto& c : cands) {
      if (c.across_trips) {
        // RRC factor 1 + c (T_ref - T_r) on recording r: per unit c, (T_ref - T_r) times the RRC-level signature
        // (the variant is +10 % RRC; rolling energy is linear in the RRC factor to first order).
        c.signature.resize(n);
        for (Eigen::Index w = 0; w < n; ++w)
          c.signature[w] = (ambient_ref_k - ambient_k[d.windows[static_cast<std::size_t>(w)].rec]) *
                           (vars[0].window_j[w] - base.window_j[w]) / 0.1;
        kept.push_back(std::move(c));
        continue;
      }
      c.signature = (vars[k++].window_j - base.window_j) / c.nominal;
      if (c.signature.norm() > 0.0) kept.push_back(std::move(c));
    }
    cands = std::move(kept);
    for (auto& b : basis) {
      if (b.kind == BasisShape::force) {
        b.signature = vars[k++].window_j - base.window_j;
      } else {
        b.signature = power_signature(b.decay_s);
      }
    }
  }

  // Calibration: measured = s * sim + a * S_rrc + b * S_drag (RRC level and CdA as nuisances, per 10 %).
  Eigen::MatrixXd xc(n, 3);
  xc.col(0) = base.window_j;
  xc.col(1) = rrc.window_j - base.window_j;
  xc.col(2) = drag.window_j - base.window_j;
  // RRC level and aero C are known to within about +-15 % from the vehicle data (coast-down repeatability, tyre
  // spread): a prior at that width keeps short trips, where scale, RRC and C are nearly collinear, physical.
  Prior prior;
  {
    const Fit free = least_squares(xc, d.measured_j);
    const double noise_sd = std::sqrt(free.rss / std::max<double>(1.0, static_cast<double>(n - 3)));
    const double prior_sd = opt.calibration_prior_fraction / 0.1;  // coefficients are per 10 % change
    prior.rows = {{1, noise_sd / prior_sd}, {2, noise_sd / prior_sd}};
  }
  const Fit cal = least_squares(xc, d.measured_j, prior);
  out.channel_scale = cal.coef[0];
  out.rrc_level_change = 0.1 * cal.coef[1] / cal.coef[0];
  out.drag_change = 0.1 * cal.coef[2] / cal.coef[0];
  const Eigen::VectorXd cal_resid = d.measured_j - xc * cal.coef;
  out.lag1_autocorrelation = lag1_autocorrelation(cal_resid);
  const double rho = std::clamp(out.lag1_autocorrelation, 0.0, 0.95);
  const double n_eff = std::max(4.0, static_cast<double>(n) * (1.0 - rho) / (1.0 + rho));
  out.effective_windows = n_eff;
  const Eigen::VectorXd cal_pred = heldout_prediction(xc, d.measured_j, fold_of, prior);
  out.heldout_rmse_calibrated_j = rmse(cal_pred, d.measured_j);
  out.heldout_energy_error_pct_calibrated = energy_error_pct(cal_pred, d.measured_j);

  // Forward selection: add the candidate with the largest BIC gain while it passes the threshold and improves
  // the held-out fit; confounded if another candidate's cleaned signature is nearly collinear and also passes.
  Eigen::MatrixXd x = xc;
  double rss = cal.rss;
  Eigen::VectorXd coef_final = cal.coef;
  std::vector<std::string> chosen_ids;
  Eigen::VectorXd pred_before = cal_pred;
  auto cleaned = [&](const Eigen::MatrixXd& basis_m, const Eigen::VectorXd& s) {
    const Eigen::VectorXd c = basis_m.colPivHouseholderQr().solve(s);
    return Eigen::VectorXd(s - basis_m * c);
  };
  const double inflate = std::sqrt(static_cast<double>(n) / n_eff);  // autocorrelated windows carry less information
  // ambient_rrc's evidence lives in a few per-trip RRC levels, not in the windows: a trip's RRC level also moves with
  // tyre pressure and road surface (and its aero force with the weather), so windows alone would take any such
  // trip-to-trip scatter for an ambient law.
  // The trips' own RRC levels (model `xm` with the shared RRC column split per recording) are regressed on ambient
  // by generalised least squares with their covariance plus that scatter (opt.trip_rrc_scatter, fixed in advance);
  // returns the coefficient c [1/K], its standard error and the trips' Delta BIC (chi^2 - ln trips).
  struct TripLevel {
    double c = 0.0, se = 0.0, dbic = -1e300;
  };
  auto trip_level_ambient = [&](const Eigen::MatrixXd& xm) {
    TripLevel t;
    const auto nr = static_cast<Eigen::Index>(recordings.size());
    Eigen::MatrixXd xt = Eigen::MatrixXd::Zero(n, xm.cols() - 1 + nr);
    xt.col(0) = xm.col(0);
    for (Eigen::Index w = 0; w < n; ++w) xt(w, 1 + static_cast<Eigen::Index>(d.windows[static_cast<std::size_t>(w)].rec)) = xm(w, 1);
    xt.rightCols(xm.cols() - 2) = xm.rightCols(xm.cols() - 2);
    Prior pt;
    for (Eigen::Index r = 0; r < nr; ++r) pt.rows.push_back({1 + r, prior.rows[0].second});
    pt.rows.push_back({1 + nr, prior.rows[1].second});
    const Fit f = least_squares(xt, d.measured_j, pt);
    const double s = f.coef[0];
    if (!(std::abs(s) > 0.0)) return t;
    const double tau_coef = opt.trip_rrc_scatter * std::abs(s) / 0.1;  // coefficients are per 10 % RRC
    Eigen::MatrixXd v = f.cov.block(1, 1, nr, nr) * (inflate * inflate);
    v.diagonal().array() += tau_coef * tau_coef;
    // The day's unrecorded barometric pressure moves the trip's aero force; projected onto that trip's RRC level
    // (least squares of the aero signature on the RRC signature over the trip's windows), it is more scatter.
    for (Eigen::Index r = 0; r < nr; ++r) {
      double sa = 0.0, ss = 0.0;
      for (Eigen::Index w = 0; w < n; ++w) {
        if (static_cast<Eigen::Index>(d.windows[static_cast<std::size_t>(w)].rec) != r) continue;
        sa += xm(w, 2) * xm(w, 1);
        ss += xm(w, 1) * xm(w, 1);
      }
      const double air_coef = ss > 0.0 ? opt.trip_air_density_scatter * std::abs(s) / 0.1 * sa / ss : 0.0;
      v(r, r) += air_coef * air_coef;
    }
    Eigen::MatrixXd design(nr, 2);
    Eigen::VectorXd a(nr);
    for (Eigen::Index r = 0; r < nr; ++r) {
      design(r, 0) = 1.0;
      design(r, 1) = ambient_ref_k - ambient_k[static_cast<std::size_t>(r)];
      a[r] = f.coef[1 + r];
    }
    const Eigen::MatrixXd vinv = v.inverse();
    const Eigen::MatrixXd info = design.transpose() * vinv * design;
    const Eigen::MatrixXd cov = info.inverse();
    const Eigen::VectorXd beta = cov * design.transpose() * vinv * a;
    t.c = 0.1 * beta[1] / s;
    t.se = 0.1 * std::sqrt(std::max(0.0, cov(1, 1))) / std::abs(s);
    t.dbic = beta[1] * beta[1] / std::max(1e-300, cov(1, 1)) - std::log(static_cast<double>(nr));
    return t;
  };
  for (int round = 0; round < opt.max_effects; ++round) {
    struct Scored {
      std::size_t idx;
      double dbic;
      Fit fit;
      Eigen::VectorXd pred;
      double se_amplitude = 0.0;  // ambient_rrc: the trip-level standard error of c (else 0: the fit's own)
    };
    std::vector<Scored> passing;
    for (std::size_t k = 0; k < cands.size(); ++k) {
      if (std::find(chosen_ids.begin(), chosen_ids.end(), cands[k].id) != chosen_ids.end()) continue;
      const Eigen::MatrixXd xk = hcat(x, cands[k].signature);
      const Fit f = least_squares(xk, d.measured_j, prior);
      if (f.rss <= 0.0) continue;
      const double dbic = n_eff * std::log(rss / f.rss) - std::log(n_eff);
      const double amp = f.coef[f.coef.size() - 1] / f.coef[0];  // in the simulated channel's scale
      if (dbic < opt.bic_threshold || amp < cands[k].amp_min || amp > cands[k].amp_max) continue;
      double se_amplitude = 0.0;
      if (cands[k].across_trips) {
        // It must also pass the same threshold on the trips' RRC levels, against trip-to-trip scatter.
        const TripLevel t = trip_level_ambient(x);
        if (t.dbic < opt.bic_threshold) continue;
        se_amplitude = t.se;
      }
      Eigen::VectorXd pred = heldout_prediction(xk, d.measured_j, fold_of, prior);
      if (rmse(pred, d.measured_j) >= rmse(pred_before, d.measured_j)) continue;
      passing.push_back({k, dbic, f, pred, se_amplitude});
    }
    if (passing.empty()) break;
    std::sort(passing.begin(), passing.end(), [](const Scored& a, const Scored& b) { return a.dbic > b.dbic; });
    Scored best = passing.front();
    Candidate c = cands[best.idx];
    // A warm-up's heat capacity was chosen from a coarse grid: refine it on a log grid, profile the criterion
    // (RSS on the effective n) over it, adopt the grid's best if it also fits better held out, and keep the
    // profile's 95 % interval. Only for a found effect, so a recording with nothing to find costs nothing more.
    std::optional<ProfileInterval> profile;
    std::string profiled_name;
    for (const auto& tp : kTimeParameters) {
      if (c.id != tp.effect || !c.shape.count(tp.parameter)) continue;
      profiled_name = tp.parameter;
      const double selected = c.shape.at(tp.parameter);
      const std::vector<double> grid = log_grid(tp.low, tp.high, opt.profile_points_per_octave, selected);
      std::vector<std::vector<std::shared_ptr<const Effect>>> runs;
      for (double g : grid) {
        if (g == selected) continue;
        EffectParameters p = c.shape;
        p[tp.parameter] = g;
        p[c.amplitude_name] = c.nominal;
        runs.push_back({make_effect(c.id, p, ctx)});
      }
      const std::vector<Variant> pv = run_variants(vehicle, cycles, d, runs, opt.threads);
      std::vector<Eigen::VectorXd> sigs;
      std::vector<double> rss_grid;
      std::size_t k = 0;
      for (double g : grid) {
        sigs.push_back(g == selected ? c.signature : Eigen::VectorXd((pv[k++].window_j - base.window_j) / c.nominal));
        rss_grid.push_back(least_squares(hcat(x, sigs.back()), d.measured_j, prior).rss);
      }
      ProfileInterval pi = profile_likelihood_interval(grid, rss_grid, n_eff);
      if (grid[pi.best] != selected) {
        const Eigen::MatrixXd xk = hcat(x, sigs[pi.best]);
        const Fit f = least_squares(xk, d.measured_j, prior);
        const double amp = f.coef[f.coef.size() - 1] / f.coef[0];
        Eigen::VectorXd pred = heldout_prediction(xk, d.measured_j, fold_of, prior);
        if (amp >= c.amp_min && amp <= c.amp_max && rmse(pred, d.measured_j) < rmse(best.pred, d.measured_j)) {
          best.fit = f;
          best.dbic = n_eff * std::log(rss / f.rss) - std::log(n_eff);
          best.pred = pred;
          c.signature = sigs[pi.best];
          c.shape[tp.parameter] = grid[pi.best];
        }
      }
      // The value kept is the selection's when the profile's best did not also fit better held out: keep it inside.
      pi.value = c.shape.at(tp.parameter);
      pi.low = std::min(pi.low, pi.value);
      pi.high = std::max(pi.high, pi.value);
      profile = pi;
    }
    Finding fnd;
    fnd.effect = c.id;
    fnd.delta_bic = best.dbic;
    const Eigen::Index j = best.fit.coef.size() - 1;
    const double se = std::sqrt(std::max(0.0, best.fit.cov(j, j))) * inflate;
    // The signature is per unit amplitude of the measured channel's scale 1; divide by the channel scale.
    const double s = best.fit.coef[0];
    const double value = best.fit.coef[j] / s;
    // ambient_rrc: the wider of the windows' and the trips' intervals (a few trips carry its information).
    const double se_value = std::max(std::abs(se / s), best.se_amplitude);
    fnd.parameters.push_back({c.amplitude_name, c.amplitude_unit, value, value - 1.96 * se_value, value + 1.96 * se_value});
    fnd.fitted = c.shape;
    fnd.fitted[c.amplitude_name] = value;
    if (c.across_trips) {
      const auto [lo, hi] = std::minmax_element(ambient_k.begin(), ambient_k.end());
      fnd.description = "RRC level follows ambient temperature across the recordings (" + fixed(*lo - 273.15, 1) + " to " +
                        fixed(*hi - 273.15, 1) + " degC): " + fixed(100.0 * value, 2) + " % per K colder, referred to " +
                        fixed(ambient_ref_k - 273.15, 1) + " degC; the written vehicle is neutral at that reference, set "
                        "ambient_temp_c per trip";
    }
    for (const auto& [k, v] : c.shape) {
      for (const auto& pi : effect_info(c.id).parameters) {
        if (pi.name != k) continue;
        if (profile && k == profiled_name)
          fnd.parameters.push_back({k, pi.unit, v, profile->low, profile->high, true, profile->low_open, profile->high_open});
        else
          fnd.parameters.push_back({k, pi.unit, v, v, v});  // fixed, not fitted
      }
    }
    const Eigen::VectorXd sb = cleaned(x, c.signature);
    for (std::size_t q = 1; q < passing.size(); ++q) {
      const Candidate& o = cands[passing[q].idx];
      if (o.id == c.id) continue;
      const Eigen::VectorXd so = cleaned(x, o.signature);
      const double corr = sb.dot(so) / std::max(1e-300, sb.norm() * so.norm());
      if (std::abs(corr) > opt.collinear_corr &&
          std::find(fnd.confounded_with.begin(), fnd.confounded_with.end(), o.id) == fnd.confounded_with.end())
      {
        fnd.confounded_with.push_back(o.id);
        fnd.separating_tests.push_back(o.id + ": " + separating_test(c.id, o.id));
      }
    }
    fnd.heldout_rmse_before_j = rmse(pred_before, d.measured_j);
    fnd.heldout_rmse_after_j = rmse(best.pred, d.measured_j);
    fnd.heldout_energy_error_pct_before = energy_error_pct(pred_before, d.measured_j);
    fnd.heldout_lag1_autocorrelation_before = lag1_autocorrelation(Eigen::VectorXd(d.measured_j - pred_before));
    fnd.heldout_energy_error_pct_after = energy_error_pct(best.pred, d.measured_j);
    fnd.heldout_lag1_autocorrelation_after = lag1_autocorrelation(Eigen::VectorXd(d.measured_j - best.pred));
    x = hcat(x, c.signature);
    rss = best.fit.rss;
    coef_final = best.fit.coef;
    pred_before = best.pred;
    chosen_ids.push_back(c.id);
    out.findings.push_back(std::move(fnd));
  }

  // Detection limits: for each catalogue effect not found, the amplitude whose signature, cleaned of calibration
  // and of the effects found, would have cut the residual enough to pass the same BIC threshold:
  // n_eff ln(1 + c^2 |s|^2 / RSS) - ln n_eff = threshold.
  {
    const double factor = std::exp((opt.bic_threshold + std::log(n_eff)) / n_eff) - 1.0;
    std::map<std::string, DetectionLimit> best;
    for (const auto& c : cands) {
      if (std::find(chosen_ids.begin(), chosen_ids.end(), c.id) != chosen_ids.end()) continue;
      const double norm = cleaned(x, c.signature).norm();
      if (!(norm > 0.0)) continue;
      const double amp = std::sqrt(rss * factor) / norm / std::max(1e-12, std::abs(coef_final[0]));
      auto [it, inserted] = best.try_emplace(c.id, DetectionLimit{c.id, c.amplitude_name, c.amplitude_unit, amp, true});
      if (!inserted && amp < it->second.smallest_detectable) it->second.smallest_detectable = amp;
    }
    for (auto& [id, lim] : best) {
      for (const auto& c : cands) {
        if (c.id == id) lim.within_bounds = lim.smallest_detectable <= std::max(std::abs(c.amp_min), std::abs(c.amp_max));
      }
      out.detection_limits.push_back(lim);
    }
  }

  // Unexplained: what the catalogue left, if still significant by the same BIC threshold and held-out test,
  // described by the basis shape that explains most of it.
  {
    int best_k = -1;
    double best_dbic = opt.bic_threshold;
    Fit best_fit;
    Eigen::VectorXd best_pred;
    for (std::size_t k = 0; k < basis.size(); ++k) {
      if (basis[k].signature.norm() <= 0.0) continue;
      const Eigen::MatrixXd xk = hcat(x, basis[k].signature);
      const Fit f = least_squares(xk, d.measured_j, prior);
      if (f.rss <= 0.0) continue;
      const double dbic = n_eff * std::log(rss / f.rss) - std::log(n_eff);
      if (dbic <= best_dbic) continue;
      Eigen::VectorXd pred = heldout_prediction(xk, d.measured_j, fold_of, prior);
      if (rmse(pred, d.measured_j) >= rmse(pred_before, d.measured_j)) continue;
      best_k = static_cast<int>(k);
      best_dbic = dbic;
      best_fit = f;
      best_pred = pred;
    }
    if (best_k >= 0) {
      BasisShape b = basis[static_cast<std::size_t>(best_k)];
      // A decaying shape's time constant came from the basis' grid: refine and profile it as for the warm-ups.
      std::optional<ProfileInterval> profile;
      if (b.decay_s > 0.0) {
        const std::vector<double> grid = log_grid(kDecayGridLowS, kDecayGridHighS, opt.profile_points_per_octave, b.decay_s);
        std::vector<Eigen::VectorXd> sigs(grid.size());
        std::vector<std::vector<std::shared_ptr<const Effect>>> runs;
        std::vector<std::size_t> run_of;
        for (std::size_t g = 0; g < grid.size(); ++g) {
          const auto same = std::find_if(basis.begin(), basis.end(), [&](const BasisShape& o) {
            return o.kind == b.kind && o.shape == b.shape && o.decay_s == grid[g] && o.signature.size() == n;
          });
          if (same != basis.end()) sigs[g] = same->signature;
          else if (b.kind == BasisShape::power) sigs[g] = power_signature(grid[g]);
          else {
            runs.push_back({std::make_shared<SignatureForce>(b.shape, grid[g])});
            run_of.push_back(g);
          }
        }
        const std::vector<Variant> pv = run_variants(vehicle, cycles, d, runs, opt.threads);
        for (std::size_t r = 0; r < pv.size(); ++r) sigs[run_of[r]] = pv[r].window_j - base.window_j;
        std::vector<double> rss_grid;
        for (const auto& sg : sigs) rss_grid.push_back(least_squares(hcat(x, sg), d.measured_j, prior).rss);
        ProfileInterval pi = profile_likelihood_interval(grid, rss_grid, n_eff);
        if (grid[pi.best] != b.decay_s) {
          const Eigen::MatrixXd xk = hcat(x, sigs[pi.best]);
          const Fit f = least_squares(xk, d.measured_j, prior);
          Eigen::VectorXd pred = heldout_prediction(xk, d.measured_j, fold_of, prior);
          if (rmse(pred, d.measured_j) < rmse(best_pred, d.measured_j)) {
            best_fit = f;
            best_dbic = n_eff * std::log(rss / f.rss) - std::log(n_eff);
            best_pred = pred;
            b.decay_s = grid[pi.best];
            b.signature = sigs[pi.best];
          }
        }
        pi.value = b.decay_s;
        pi.low = std::min(pi.low, pi.value);
        pi.high = std::max(pi.high, pi.value);
        profile = pi;
      }
      Finding fnd;
      fnd.effect = "unexplained";
      fnd.delta_bic = best_dbic;
      const Eigen::Index j = best_fit.coef.size() - 1;
      const double s = best_fit.coef[0];
      const double value = best_fit.coef[j] / s;
      const double se = std::sqrt(std::max(0.0, best_fit.cov(j, j))) * inflate / std::abs(s);
      double vmax = 0.0;
      for (const auto& r : recordings)
        for (double v : r.speed_mps) vmax = std::max(vmax, v);
      const double vref_kmh = vmax > 90.0 / 3.6 ? 100.0 : 50.0;
      const double at_ref = [&] {
        const double u = vref_kmh / 100.0;
        return b.shape == ForceShape::speed ? u : b.shape == ForceShape::speed_squared ? u * u : 1.0;
      }();
      std::string what, size_text, name, unit;
      const double share_pct = 100.0 * best_fit.coef[j] * b.signature.sum() / std::max(1e-9, std::abs(d.measured_j.sum()));
      if (b.kind == BasisShape::power) {
        what = "a constant power at the " + d.channel + " channel";
        size_text = "about " + fixed(value, 0) + " W";
        name = "power";
        unit = "W";
      } else if (b.shape == ForceShape::positive_accel) {
        what = "a force proportional to acceleration, when accelerating only";
        size_text = "about " + fixed(value, 0) + " N at 1 m/s^2 (as if " + fixed(value, 0) + " kg more mass had to be accelerated but none came back in braking)";
        name = "force_per_positive_accel";
        unit = "N s^2/m";
      } else if (b.shape == ForceShape::constant) {
        what = "a constant force while moving";
        size_text = "about " + fixed(value, 0) + " N";
        name = "force";
        unit = "N";
      } else {
        what = b.shape == ForceShape::speed ? "a force proportional to speed" : "a force proportional to speed squared";
        size_text = "about " + fixed(value * at_ref, 0) + " N at " + fixed(vref_kmh, 0) + " km/h";
        name = "force_at_100kmh";
        unit = "N";
      }
      fnd.parameters.push_back({name, unit, value, value - 1.96 * se, value + 1.96 * se});
      std::string when;
      if (b.decay_s > 0.0) {
        fnd.parameters.push_back(
            {"decay_time_constant_s", "s", b.decay_s, profile->low, profile->high, true, profile->low_open, profile->high_open});
        // "Mostly in the first N minutes": when 80 % of the signature's energy has accrued (windows by end time).
        std::vector<std::pair<double, double>> by_end;
        for (Eigen::Index w = 0; w < n; ++w)
          by_end.push_back({d.windows[static_cast<std::size_t>(w)].end < cycles[d.windows[static_cast<std::size_t>(w)].rec].time_s.size()
                                ? cycles[d.windows[static_cast<std::size_t>(w)].rec].time_s[d.windows[static_cast<std::size_t>(w)].end]
                                : 0.0,
                            std::abs(b.signature[w])});
        std::sort(by_end.begin(), by_end.end());
        double total = 0.0, cum = 0.0, t80 = 0.0;
        for (const auto& p : by_end) total += p.second;
        for (const auto& p : by_end) {
          cum += p.second;
          t80 = p.first;
          if (cum >= 0.8 * total) break;
        }
        when = ", decaying from the start of the trip with a time constant of about " + fixed(b.decay_s / 60.0, 0) +
               " min: mostly (80 %) in the first " + fixed(std::ceil(t80 / 60.0), 0) + " min";
      }
      fnd.description = what + ", " + size_text + when + "; " + fixed(share_pct, 1) + " % of the measured energy, beside a channel scale of " +
                        fixed(s, 3);
      if (!vehicle.is_electric() && b.decay_s == 0.0)
        fnd.description += ". The combustion engine is a Willans line with no efficiency map: efficiency changing with "
                           "load and speed (enrichment at high load, pumping loss at low load) has no module to name, and shows up this way";
      fnd.heldout_rmse_before_j = rmse(pred_before, d.measured_j);
      fnd.heldout_rmse_after_j = rmse(best_pred, d.measured_j);
      fnd.heldout_energy_error_pct_before = energy_error_pct(pred_before, d.measured_j);
      fnd.heldout_lag1_autocorrelation_before = lag1_autocorrelation(Eigen::VectorXd(d.measured_j - pred_before));
      fnd.heldout_energy_error_pct_after = energy_error_pct(best_pred, d.measured_j);
      fnd.heldout_lag1_autocorrelation_after = lag1_autocorrelation(Eigen::VectorXd(d.measured_j - best_pred));
      x = hcat(x, b.signature);
      coef_final = best_fit.coef;
      out.findings.push_back(std::move(fnd));
    }
  }
  if (out.findings.empty()) out.verdict = "nothing_missing";
  else out.verdict = out.findings.front().confounded_with.empty() ? "missing_physics" : "confounded";

  // Per-window series for figures.
  {
    const Eigen::VectorXd calibrated = xc * cal.coef, fitted = x * coef_final;
    for (Eigen::Index w = 0; w < n; ++w) {
      const auto& win = d.windows[static_cast<std::size_t>(w)];
      const Recording& r = recordings[win.rec];
      DiagnosisWindow dw;
      dw.recording = static_cast<int>(win.rec);
      dw.start_s = r.time_s[win.begin] - r.time_s.front();
      dw.end_s = r.time_s[win.end] - r.time_s.front();
      double sv = 0.0, sa = 0.0, T = 0.0;
      for (std::size_t i = win.begin; i < win.end; ++i) {
        const double dt = d.dt_s[win.rec][i];
        sv += 0.5 * (r.speed_mps[i] + r.speed_mps[i + 1]) * dt;
        sa += std::max(0.0, r.speed_mps[i + 1] - r.speed_mps[i]);
        T += dt;
      }
      dw.mean_speed_mps = sv / std::max(1e-9, T);
      dw.mean_positive_accel_mps2 = sa / std::max(1e-9, T);
      dw.measured_j = d.measured_j[w];
      dw.simulated_j = base.window_j[w];
      dw.calibrated_j = calibrated[w];
      dw.fitted_j = fitted[w];
      out.series.push_back(dw);
    }
  }

  // Locate: per-sample residual of the calibrated model, by regime, with a normal interval on an effective n.
  if (d.channel != "soc") {
    const std::vector<std::string> order{"standing", "accelerating", "cruising", "braking", "speed 0-50 km/h",
                                         "speed 50-90 km/h", "speed >90 km/h", "first 10 min", "10-30 min", "after 30 min",
                                         "uphill (> 1 %)", "level", "downhill (< -1 %)"};
    std::map<std::string, std::vector<double>> vals;
    std::vector<double> all;
    for (std::size_t ri = 0; ri < recordings.size(); ++ri) {
      const Recording& r = recordings[ri];
      for (std::size_t i = 0; i + 1 < r.time_s.size(); ++i) {
        const std::size_t j = i >= static_cast<std::size_t>(d.lag_samples) ? i - static_cast<std::size_t>(d.lag_samples) : 0;
        const double sim = cal.coef[0] * base.power_w[ri][j] + cal.coef[1] * (rrc.power_w[ri][j] - base.power_w[ri][j]) +
                           cal.coef[2] * (drag.power_w[ri][j] - base.power_w[ri][j]);
        const double res = d.measured_w[ri][i] - sim;
        const double v = r.speed_mps[i], a = (r.speed_mps[i + 1] - v) / d.dt_s[ri][i];
        const double t = r.time_s[i] - r.time_s.front();
        all.push_back(res);
        vals[v < 0.3 ? "standing" : a > 0.3 ? "accelerating" : a < -0.3 ? "braking" : "cruising"].push_back(res);
        if (v >= 0.3) vals[v < 50 / 3.6 ? "speed 0-50 km/h" : v < 90 / 3.6 ? "speed 50-90 km/h" : "speed >90 km/h"].push_back(res);
        vals[t < 600 ? "first 10 min" : t < 1800 ? "10-30 min" : "after 30 min"].push_back(res);
        // Grade regimes only where the recording gave grade or elevation (the replay trace then carries it).
        if (r.grade || r.elevation_m) {
          const double g = cycles[ri].grade[i];
          if (v >= 0.3) vals[g > 0.01 ? "uphill (> 1 %)" : g < -0.01 ? "downhill (< -1 %)" : "level"].push_back(res);
        }
      }
    }
    Eigen::VectorXd allv = Eigen::Map<Eigen::VectorXd>(all.data(), static_cast<Eigen::Index>(all.size()));
    append_regime_means(order, vals, lag1_autocorrelation(allv), out.located);
  } else {
    // SOC gives energy per window, not power per sample: locate by window, each window in the regimes of its own
    // means (speed, grade, time since start). Mean residual power of the windows, with the same AR(1) inflation.
    const Eigen::VectorXd res_j = d.measured_j - xc * cal.coef;
    std::map<std::string, std::vector<double>> vals;
    const std::vector<std::string> order{"standing (window)", "speed 0-50 km/h (window)", "speed 50-90 km/h (window)",
                                         "speed >90 km/h (window)", "first 10 min (window)", "10-30 min (window)",
                                         "after 30 min (window)", "uphill > 1 % (window)", "level (window)",
                                         "downhill < -1 % (window)"};
    for (std::size_t w = 0; w < d.windows.size(); ++w) {
      const auto& win = d.windows[w];
      const DriveCycle& c = cycles[win.rec];
      const double duration_s = c.time_s[win.end] - c.time_s[win.begin];
      if (!(duration_s > 0.0)) continue;
      double distance_m = 0.0, rise = 0.0;
      for (std::size_t i = win.begin; i < win.end; ++i) {
        const double ds = 0.5 * (c.speed_mps[i] + c.speed_mps[i + 1]) * (c.time_s[i + 1] - c.time_s[i]);
        distance_m += ds;
        rise += c.grade[i] * ds;
      }
      const double v = distance_m / duration_s;
      const double p_w = res_j[static_cast<Eigen::Index>(w)] / duration_s;
      const double mid_s = 0.5 * (c.time_s[win.begin] + c.time_s[win.end]) - c.time_s.front();
      vals[v < 0.5 ? "standing (window)" : v < 50 / 3.6 ? "speed 0-50 km/h (window)"
                                         : v < 90 / 3.6 ? "speed 50-90 km/h (window)" : "speed >90 km/h (window)"].push_back(p_w);
      vals[mid_s < 600 ? "first 10 min (window)" : mid_s < 1800 ? "10-30 min (window)" : "after 30 min (window)"].push_back(p_w);
      const Recording& r = recordings[win.rec];
      if ((r.grade || r.elevation_m) && distance_m > 0.0) {
        const double g = rise / distance_m;
        vals[g > 0.01 ? "uphill > 1 % (window)" : g < -0.01 ? "downhill < -1 % (window)" : "level (window)"].push_back(p_w);
      }
    }
    append_regime_means(order, vals, lag1_autocorrelation(res_j), out.located);
  }
  return out;
}

namespace {
std::string json_escape(const std::string& s) {
  std::string o;
  for (char c : s) {
    if (c == '"' || c == '\\') o += '\\';
    if (c == '\n') { o += "\\n"; continue; }
    o += c;
  }
  return o;
}
}  // namespace

std::string diagnosis_json(const Diagnosis& d) {
  std::ostringstream os;
  os << "{\n  \"verdict\": \"" << d.verdict << "\",\n  \"channel\": \"" << d.channel << "\",\n";
  os << "  \"windows\": " << d.windows << ",\n  \"effective_windows\": " << num(d.effective_windows) << ",\n";
  os << "  \"calibration\": {\"channel_scale\": " << num(d.channel_scale) << ", \"rrc_level_change\": " << num(d.rrc_level_change)
     << ", \"drag_change\": " << num(d.drag_change) << "},\n";
  os << "  \"lag_samples\": " << d.lag_samples << ",\n";
  os << "  \"window_s\": " << num(d.window_s) << ",\n  \"notes\": [";
  for (std::size_t i = 0; i < d.notes.size(); ++i) os << (i ? ", " : "") << "\"" << json_escape(d.notes[i]) << "\"";
  os << "],\n";
  os << "  \"raw_trip_energy_error_pct\": " << num(d.raw_trip_energy_error_pct) << ",\n";
  os << "  \"heldout_rmse_calibrated\": " << num(d.heldout_rmse_calibrated_j) << ",\n";
  os << "  \"heldout_energy_error_pct_calibrated\": " << num(d.heldout_energy_error_pct_calibrated) << ",\n";
  os << "  \"findings\": [";
  for (std::size_t i = 0; i < d.findings.size(); ++i) {
    const auto& f = d.findings[i];
    os << (i ? "," : "") << "\n    {\"effect\": \"" << f.effect << "\", ";
    if (!f.description.empty()) os << "\"description\": \"" << json_escape(f.description) << "\", ";
    os << "\"parameters\": {";
    for (std::size_t k = 0; k < f.parameters.size(); ++k) {
      const auto& p = f.parameters[k];
      os << (k ? ", " : "") << "\"" << p.name << "\": {\"value\": " << num(p.value) << ", \"ci_low\": " << num(p.ci_low)
         << ", \"ci_high\": " << num(p.ci_high) << ", \"unit\": \"" << p.unit << "\"";
      if (p.profiled)
        os << ", \"interval\": \"profile\", \"ci_low_open\": " << (p.ci_low_open ? "true" : "false")
           << ", \"ci_high_open\": " << (p.ci_high_open ? "true" : "false");
      os << "}";
    }
    os << "}, \"confounded_with\": [";
    for (std::size_t k = 0; k < f.confounded_with.size(); ++k) os << (k ? ", " : "") << "\"" << f.confounded_with[k] << "\"";
    os << "], \"separating_tests\": [";
    for (std::size_t k = 0; k < f.separating_tests.size(); ++k)
      os << (k ? ", " : "") << "\"" << json_escape(f.separating_tests[k]) << "\"";
    os << "], \"delta_bic\": " << num(f.delta_bic) << ", \"heldout_rmse_before\": " << num(f.heldout_rmse_before_j)
       << ", \"heldout_rmse_after\": " << num(f.heldout_rmse_after_j)
       << ", \"heldout_energy_error_pct_before\": " << num(f.heldout_energy_error_pct_before)
       << ", \"heldout_energy_error_pct_after\": " << num(f.heldout_energy_error_pct_after)
       << ", \"heldout_lag1_autocorrelation_before\": " << num(f.heldout_lag1_autocorrelation_before)
       << ", \"heldout_lag1_autocorrelation_after\": " << num(f.heldout_lag1_autocorrelation_after) << "}";
  }
  os << (d.findings.empty() ? "" : "\n  ") << "],\n  \"located\": [";
  for (std::size_t i = 0; i < d.located.size(); ++i) {
    const auto& l = d.located[i];
    os << (i ? "," : "") << "\n    {\"regime\": \"" << l.regime << "\", \"samples\": " << l.samples << ", \"mean_residual_w\": "
       << num(l.mean_w) << ", \"ci_low_w\": " << num(l.ci_low_w) << ", \"ci_high_w\": " << num(l.ci_high_w) << "}";
  }
  os << (d.located.empty() ? "" : "\n  ") << "],\n  \"detection_limits\": [";
  for (std::size_t i = 0; i < d.detection_limits.size(); ++i) {
    const auto& l = d.detection_limits[i];
    os << (i ? "," : "") << "\n    {\"effect\": \"" << l.effect << "\", \"parameter\": \"" << l.parameter
       << "\", \"smallest_detectable\": " << num(l.smallest_detectable) << ", \"unit\": \"" << l.unit
       << "\", \"within_bounds\": " << (l.within_bounds ? "true" : "false") << "}";
  }
  os << (d.detection_limits.empty() ? "" : "\n  ") << "]\n}\n";
  return os.str();
}

std::string diagnosis_text(const Diagnosis& d) {
  std::ostringstream os;
  os.setf(std::ios::fixed);
  os.precision(3);
  os << "channel " << d.channel << ", " << d.windows << " windows (effective " << d.effective_windows
     << ", lag-1 autocorrelation " << d.lag1_autocorrelation << ")\n";
  for (const auto& note : d.notes) os << note << "\n";
  os << "channel lag: " << d.lag_samples << " samples\n";
  os << "uncalibrated trip energy error: " << d.raw_trip_energy_error_pct << " %\n";
  os << "calibration: channel scale " << d.channel_scale << ", RRC level " << 100 * d.rrc_level_change << " %, aero C "
     << 100 * d.drag_change << " %\n";
  os << "held-out, calibrated: RMSE " << d.heldout_rmse_calibrated_j / 1e3 << " kJ per window, trip energy error "
     << d.heldout_energy_error_pct_calibrated << " %\n";
  os << "verdict: " << d.verdict << "\n";
  for (const auto& f : d.findings) {
    os << "  " << f.effect << " (delta BIC " << f.delta_bic << ")";
    if (!f.confounded_with.empty()) {
      os << " confounded with";
      for (const auto& c : f.confounded_with) os << " " << c;
    }
    os << "\n";
    if (!f.description.empty()) os << "    " << f.description << "\n";
    for (const auto& t : f.separating_tests) os << "    to separate from " << t << "\n";
    for (const auto& p : f.parameters) {
      os << "    " << p.name << " = " << p.value;
      if (p.profiled)
        os << " [" << (p.ci_low_open ? "< " : "") << p.ci_low << ", " << (p.ci_high_open ? "> " : "") << p.ci_high
           << "] " << p.unit << " (profile likelihood, 95 %" << (p.ci_low_open || p.ci_high_open ? "; open at the grid's end" : "")
           << ")\n";
      else if (p.ci_low == p.value && p.ci_high == p.value)
        os << " " << p.unit << " (fixed)\n";
      else
        os << " [" << p.ci_low << ", " << p.ci_high << "] " << p.unit << "\n";
    }
    os << "    held-out RMSE " << f.heldout_rmse_before_j / 1e3 << " -> " << f.heldout_rmse_after_j / 1e3
       << " kJ/window, trip energy error " << f.heldout_energy_error_pct_before << " -> " << f.heldout_energy_error_pct_after
       << " %, residual lag-1 autocorrelation " << f.heldout_lag1_autocorrelation_before << " -> "
       << f.heldout_lag1_autocorrelation_after << " (0: white)\n";
  }
  if (!d.detection_limits.empty()) {
    os << "not found; smallest size of each effect's catalogue shape this data would have shown (a lower bound:\n"
       << "real effects differ from the shape; the discovery benchmark measures 1-3 times these):\n";
    for (const auto& l : d.detection_limits) {
      os << "  " << l.effect << ": " << l.parameter << " " << l.smallest_detectable << " " << l.unit
         << (l.within_bounds ? "" : " (beyond its physical bounds: not detectable here)") << "\n";
    }
  }
  os << "located (measured - calibrated model, mean power, 95 %):\n";
  os.precision(0);
  for (const auto& l : d.located)
    os << "  " << l.regime << ": " << l.mean_w << " W [" << l.ci_low_w << ", " << l.ci_high_w << "] (" << l.samples << " samples)\n";
  return os.str();
}

std::string fitted_vehicle_yaml(const std::string& vehicle_path, const Diagnosis& d) {
  std::ifstream in(vehicle_path);
  if (!in) throw InputError(vehicle_path, "cannot read");
  std::stringstream ss;
  ss << in.rdbuf();
  std::string text = ss.str();
  // Only files without an effects block are rewritten: merging two blocks would silently drop one.
  std::istringstream lines(text);
  for (std::string line; std::getline(lines, line);)
    if (line.rfind("effects:", 0) == 0) throw InputError(vehicle_path, "already has an effects: block; remove it to write a fitted one");
  std::vector<std::pair<std::string, EffectParameters>> eff;
  for (const auto& f : d.findings)
    if (f.effect != "unexplained") eff.emplace_back(f.effect, f.fitted);  // described, not a module
  if (!text.empty() && text.back() != '\n') text += '\n';
  text += "# effects fitted by rollsim diagnose (verdict: " + d.verdict + ")\n";
  if (eff.empty()) return text;
  return text + effects_yaml(eff);
}

}  // namespace rollsim
