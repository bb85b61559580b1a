// Synthetic recordings with a concealed effect: the truth is a richer model than the catalogue's, on its own code.
#include <cmath>
#include <random>

#include "rollsim/cycle/drive_cycle.hpp"
#include "rollsim/diagnose/diagnose.hpp"
#include "rollsim/sim/simulation.hpp"

namespace rollsim {
namespace {

// Truth tyre: two thermal nodes (tread, carcass). Hysteresis loss heats both (60/40); the tread convects to air
// with h ~ (1 + v/v0)^0.8 (turbulent forced convection) and conducts to the carcass; the carcass loses little.
// RRC follows an exponential law in a weighted temperature (not the catalogue's linear-to-warm law). The
// time_reversed option warms the tyre at the start and lets it cool (RRC rises) towards the end instead.
class TwoNodeTyreTruth final : public Effect {
 public:
  TwoNodeTyreTruth(double excess, double rrc_level, bool reversed, double duration_s)
      : excess_(excess), level_(rrc_level), reversed_(reversed), duration_s_(duration_s) {}
  std::string id() const override { return "truth_two_node_tyre"; }
  int num_states() const override { return 2; }
  void state_derivatives(const EffectInputs& in, const double* x, double* xdot) const override {
    const double v = std::max(in.speed_mps, 0.0);
    const double p = in.base_rolling_force_n * rolling_resistance_factor(in, x) * v;
    const double h_tread = 18.0 * std::pow(1.0 + v / 8.0, 0.8);
    const double g_tc = 25.0;  // tread-carcass conductance [W/K]
    xdot[0] = (0.6 * p - h_tread * x[0] - g_tc * (x[0] - x[1])) / 22000.0;
    xdot[1] = (0.4 * p + g_tc * (x[0] - x[1]) - 4.0 * x[1]) / 40000.0;
  }
  double rolling_resistance_factor(const EffectInputs& in, const double* x) const override {
    double cold = std::exp(-(0.4 * x[0] + 0.6 * x[1]) / 12.0);
    // Reversed null: the same-sized transient mirrored in time (decay placed at the end).
    if (reversed_) cold = std::exp(-std::max(0.0, duration_s_ - in.time_s) / 700.0);
    return level_ * (1.0 + excess_ * cold);
  }

 private:
  double excess_, level_;
  bool reversed_;
  double duration_s_;
};

}  // namespace

Recording generate_recording(const Vehicle& vehicle, const SyntheticOptions& o) {
  std::mt19937 rng(o.seed);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  const DriveCycle one = load_cycle(o.cycle);
  DriveCycle c;
  c.name = o.cycle + " x" + std::to_string(o.repeats);
  for (int k = 0; k < o.repeats; ++k) {
    const double t0 = c.time_s.empty() ? 0.0 : c.time_s.back() + 1.0;
    for (std::size_t i = 0; i < one.time_s.size(); ++i) {
      c.time_s.push_back(t0 + one.time_s[i] - one.time_s.front());
      c.speed_mps.push_back(one.speed_mps[i]);
      c.grade.push_back(0.0);
    }
  }
  VehicleModel model = VehicleModel::assemble(vehicle);
  const double level = 1.0 + o.rrc_level_jitter * unit(rng);
  model.effects.push_back(std::make_shared<TwoNodeTyreTruth>(o.tyre_cold_excess, level, o.time_reversed, c.duration_s()));
  SimulationOptions so;
  so.record_trace = true;
  const SimulationResult r = simulate_replay(model, c, so);
  const double scale = 1.0 + o.scale_jitter * unit(rng);
  std::normal_distribution<double> noise(0.0, o.noise_w);
  Recording rec;
  rec.source = "synthetic " + c.name + " seed " + std::to_string(o.seed);
  const std::size_t n = r.trace.size();  // one point per segment start; the last sample is dropped
  const auto lag = static_cast<std::size_t>(std::lround(std::max(0.0, o.lag_s)));
  std::vector<double> p(n);
  for (std::size_t i = 0; i < n; ++i) {
    const double truth = r.trace[i >= lag ? i - lag : 0].battery_power_w * scale + noise(rng);
    p[i] = o.quantum_w > 0.0 ? o.quantum_w * std::round(truth / o.quantum_w) : truth;
  }
  rec.time_s.assign(c.time_s.begin(), c.time_s.begin() + static_cast<long>(n));
  rec.speed_mps.assign(c.speed_mps.begin(), c.speed_mps.begin() + static_cast<long>(n));
  rec.battery_power_w = p;
  return rec;
}

}  // namespace rollsim
