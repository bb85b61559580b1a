// Diagnosis stage 2: replays of model variants on the recordings' traces, and the channel lag.
#include <algorithm>
#include <atomic>
#include <cmath>
#include <mutex>
#include <thread>

#include "pipeline.hpp"
#include "rollsim/common/parallel.hpp"
#include "rollsim/common/statistics.hpp"
#include "rollsim/sim/simulation.hpp"

namespace rollsim::diag {
namespace {

// The simulated counterpart of the measured channel: fuel power, battery terminal power, or, for a state of charge
// (which counts what leaves the cells), terminal power plus the cells' internal loss. Segment means, as the replay
// integrates them (summed as mean x dt they are `simulate`'s energy on the same trace), or, for a logger that reads
// its channel at the sample's instant, the values at the samples.
double sim_power_w(const TracePoint& t, bool electric, double fuel_j_per_m3, bool cells, bool point) {
  if (!electric) return (point ? t.fuel_rate_m3_per_s : t.segment_fuel_rate_m3_per_s) * fuel_j_per_m3;
  if (point) return cells ? t.battery_power_w + t.battery_loss_w : t.battery_power_w;
  return cells ? t.segment_battery_power_w + t.segment_battery_loss_w : t.segment_battery_power_w;
}

// The instant at the segment's end, at its own acceleration.
double sim_end_power_w(const TracePoint& t, bool electric, double fuel_j_per_m3, bool cells) {
  if (!electric) return t.end_fuel_rate_m3_per_s * fuel_j_per_m3;
  return cells ? t.end_battery_power_w + t.end_battery_loss_w : t.end_battery_power_w;
}

// p(i - lag) with a fractional lag f = pos - k, held at the first sample before the start. Interval means: the
// lagged interval overlaps two samples' intervals, so linear between samples is exact. Instants (`end` given): the
// instant lies a fraction f into segment k, so between its start and its end at its own acceleration; linear between
// two samples' point values mixed the next segment's acceleration in, and on a 1 Hz instantaneous logger with a
// fractional lag that residual named effects on nulls (13 of 20 on session 20's outside check). Linear from start to
// end misses a kink inside the segment (the regen fade or the motor's limit crossed within a second), which a mean
// integrates but an instant may fall on: session 24's outside check of Twizy copies with speed glitches of 10 m/s^2.
double shifted(const std::vector<double>& p, const std::vector<double>* end, std::size_t i, double lag) {
  const double pos = static_cast<double>(i) - lag;
  if (pos <= 0.0) return p.front();
  const auto k = static_cast<std::size_t>(pos);
  const double f = pos - static_cast<double>(k);
  if (end && k < p.size()) return (1.0 - f) * p[k] + f * (*end)[k];
  return k + 1 < p.size() ? (1.0 - f) * p[k] + f * p[k + 1] : p.back();
}

const std::vector<double>* ends_of(const std::vector<std::vector<double>>* end_w, std::size_t recording) {
  return end_w && recording < end_w->size() ? &(*end_w)[recording] : nullptr;
}

double lag_sse(const std::vector<std::vector<double>>& sim_w, const std::vector<std::vector<double>>* end_w,
               const Observations& o, double lag, std::size_t first) {
  double sse = 0.0;
  for (std::size_t ri = 0; ri < sim_w.size(); ++ri)
    for (std::size_t i = first; i < sim_w[ri].size(); ++i) {  // the same samples for every lag searched
      const double e = o.measured_w[ri][i] - shifted(sim_w[ri], ends_of(end_w, ri), i, lag);
      sse += e * e;
    }
  return sse;
}

// The residual left when the measured channel is fitted as s x sim, s least squares within [1 - bound, 1 + bound]
// (the calibration's box), over the samples lag_sse uses.
double scaled_sse(const std::vector<std::vector<double>>& sim_w, const std::vector<std::vector<double>>* end_w,
                  const Observations& o, double lag, std::size_t first, double scale_bound) {
  double mm = 0.0, mp = 0.0, pp = 0.0;
  for (std::size_t ri = 0; ri < sim_w.size(); ++ri)
    for (std::size_t i = first; i < sim_w[ri].size(); ++i) {
      const double p = shifted(sim_w[ri], ends_of(end_w, ri), i, lag), m = o.measured_w[ri][i];
      mm += m * m, mp += m * p, pp += p * p;
    }
  const double s = pp > 0.0 ? std::clamp(mp / pp, 1.0 - scale_bound, 1.0 + scale_bound) : 1.0;
  return std::max(0.0, mm - 2.0 * s * mp + s * s * pp);
}

struct ChannelReading {
  bool electric;
  double fuel_j_per_m3;
  bool cells;
};

// Runs the replay of every recording with the extra effects and hands each trace to `use`.
template <class Use>
void for_each_replay(const Replayer& rp, const EffectList& extra, Use use) {
  VehicleModel model = VehicleModel::assemble(rp.vehicle);
  for (const auto& e : extra) model.effects.push_back(e);
  ChannelReading reading{rp.vehicle.is_electric(), 0.0, rp.cells};
  if (const FuelParams* f = rp.vehicle.fuel()) reading.fuel_j_per_m3 = f->energy_j_per_m3();
  SimulationOptions so;
  so.record_trace = true;
  so.record_segment_ends = rp.point_values;  // an instant's channel needs them (one more evaluation per ramp)
  for (std::size_t ci = 0; ci < rp.cycles.size(); ++ci) {
    const bool own = ci < rp.per_recording.size() && rp.per_recording[ci];
    if (own) model.effects.push_back(rp.per_recording[ci]);
    const SimulationResult r = simulate_replay(model, rp.cycles[ci], so);
    if (own) model.effects.pop_back();
    use(r.trace, reading);
  }
}

}  // namespace

void Replayer::sample(const EffectList& extra, Variant& out) const {
  out.power_w.clear();
  out.end_w.clear();
  for_each_replay(*this, extra, [&](const std::vector<TracePoint>& trace, const ChannelReading& c) {
    std::vector<double> p(trace.size()), end(point_values ? trace.size() : 0);
    for (std::size_t i = 0; i < p.size(); ++i) p[i] = sim_power_w(trace[i], c.electric, c.fuel_j_per_m3, c.cells, point_values);
    for (std::size_t i = 0; i < end.size(); ++i) end[i] = sim_end_power_w(trace[i], c.electric, c.fuel_j_per_m3, c.cells);
    out.power_w.push_back(std::move(p));
    if (point_values) out.end_w.push_back(std::move(end));
  });
}

ChannelPowers Replayer::both_samplings(const EffectList& extra) const {
  ChannelPowers out;
  for_each_replay(*this, extra, [&](const std::vector<TracePoint>& trace, const ChannelReading& c) {
    std::vector<double> mean(trace.size()), point(trace.size());
    for (std::size_t i = 0; i < trace.size(); ++i) {
      mean[i] = sim_power_w(trace[i], c.electric, c.fuel_j_per_m3, c.cells, false);
      point[i] = sim_power_w(trace[i], c.electric, c.fuel_j_per_m3, c.cells, true);
    }
    out.interval_mean.push_back(std::move(mean));
    out.instantaneous.push_back(std::move(point));
  });
  return out;
}

// Independent replays, so they run in parallel (each thread assembles its own model).
std::vector<Variant> Replayer::run(const std::vector<EffectList>& extras, const Observations& o, double lag_samples) const {
  std::vector<Variant> out(extras.size());
  std::exception_ptr failure;
  std::mutex failure_mutex;
  auto work = [&](std::size_t k) {
    {
      try {
        sample(extras[k], out[k]);
        out[k].window_j = window_energies(out[k], o, lag_samples);
      } catch (...) {
        const std::lock_guard<std::mutex> lock(failure_mutex);
        if (!failure) failure = std::current_exception();
      }
    }
  };
  parallel_for(extras.size(), threads, work);
  if (failure) std::rethrow_exception(failure);
  return out;
}

Eigen::VectorXd window_energies(const std::vector<std::vector<double>>& power_w, const Observations& o, double lag_samples,
                                const std::vector<std::vector<double>>* end_w) {
  Eigen::VectorXd e(o.n());
  for (std::size_t w = 0; w < o.windows.size(); ++w) {
    const auto& win = o.windows[w];
    const std::vector<double>* end = ends_of(end_w, win.rec);
    double sum = 0.0;
    for (std::size_t i = win.begin; i < win.end; ++i) sum += shifted(power_w[win.rec], end, i, lag_samples) * o.dt_s[win.rec][i];
    e[static_cast<Eigen::Index>(w)] = sum;
  }
  return e;
}

Eigen::VectorXd window_energies(const Variant& v, const Observations& o, double lag_samples) {
  return window_energies(v.power_w, o, lag_samples, v.end_w.empty() ? nullptr : &v.end_w);
}

double lagged_power_w(const Variant& v, std::size_t recording, std::size_t i, double lag_samples) {
  return shifted(v.power_w[recording], v.end_w.empty() ? nullptr : ends_of(&v.end_w, recording), i, lag_samples);
}

namespace {
double median_dt_s(const Observations& o) { return o.dt_s.front().empty() ? 1.0 : median(o.dt_s.front()); }
// The longest lag searched, up to 10 samples or 3 s, whichever is longer (loggers lag by 0.3-1.7 s; at 10 Hz that is
// 17 samples); every lag is scored on the samples from there on.
int max_lag_samples(double dt_s) { return std::max(10, static_cast<int>(std::ceil(3.0 / dt_s))); }
}  // namespace

double scaled_lag_sse(const std::vector<std::vector<double>>& sim_w, const std::vector<std::vector<double>>* end_w,
                      const Observations& o, double lag_samples, double scale_bound) {
  return scaled_sse(sim_w, end_w, o, lag_samples, static_cast<std::size_t>(max_lag_samples(median_dt_s(o))), scale_bound);
}

// Whole samples first, then 0.05-sample steps about the best; the interval is where the per-sample criterion
// n_eff ln(SSE / SSE_min) stays under 3.84, n_eff from the residual's lag-1 autocorrelation (AR(1)).
LagEstimate estimate_lag(const std::vector<std::vector<double>>& sim_w, const Observations& o,
                         const std::vector<std::vector<double>>* end_w) {
  LagEstimate l;
  if (o.channel == ChannelKind::soc) return l;
  l.estimated = true;
  const double dt = median_dt_s(o);
  const int max_lag = max_lag_samples(dt);
  int best_whole = 0;
  double best = 1e300;
  for (int lag = 0; lag <= max_lag; ++lag) {
    const double sse = lag_sse(sim_w, end_w, o, lag, static_cast<std::size_t>(max_lag));
    if (sse < best) best = sse, best_whole = lag;
  }
  std::vector<double> grid, sse;
  for (double lag = std::max(0.0, best_whole - 1.0); lag <= std::min<double>(max_lag, best_whole + 1.0) + 1e-9; lag += 0.05) {
    grid.push_back(lag);
    sse.push_back(lag_sse(sim_w, end_w, o, lag, static_cast<std::size_t>(max_lag)));
  }
  const std::size_t k = static_cast<std::size_t>(std::min_element(sse.begin(), sse.end()) - sse.begin());
  l.samples = grid[k];
  l.sse_w2 = sse[k];
  // The residual's autocorrelation at the best lag sets how much independent information the samples carry.
  double num = 0.0, den = 0.0, count = 0.0;
  for (std::size_t ri = 0; ri < sim_w.size(); ++ri) {
    double prev = 0.0;
    for (std::size_t i = static_cast<std::size_t>(max_lag); i < sim_w[ri].size(); ++i) {
      const double e = o.measured_w[ri][i] - shifted(sim_w[ri], ends_of(end_w, ri), i, l.samples);
      den += e * e;
      if (i > static_cast<std::size_t>(max_lag)) num += e * prev;
      prev = e;
      count += 1.0;
    }
  }
  const double rho = std::clamp(den > 0.0 ? num / den : 0.0, 0.0, 0.999);
  const double n_eff = std::max(2.0, count * (1.0 - rho) / (1.0 + rho));
  std::size_t lo = k, hi = k;
  while (lo > 0 && n_eff * std::log(sse[lo - 1] / sse[k]) < 3.84) --lo;
  while (hi + 1 < grid.size() && n_eff * std::log(sse[hi + 1] / sse[k]) < 3.84) ++hi;
  l.low = grid[lo];
  l.high = grid[hi];
  // An end that did not leave the best grid point lies within a step of it: read it off the parabola through the
  // best point and its neighbours (a clean channel's criterion rises past the threshold within 0.05 samples, and
  // "2.45 s [2.45, 2.45]" was 43 of 63 of session 26's outside tester's intervals).
  if (k > 0 && k + 1 < grid.size() && (lo == k || hi == k)) {
    const double step = grid[k + 1] - grid[k];
    const double curvature = (sse[k + 1] - 2.0 * sse[k] + sse[k - 1]) / (step * step);  // twice the parabola's a
    if (curvature > 0.0) {
      const double vertex = grid[k] - 0.5 * (sse[k + 1] - sse[k - 1]) / (step * curvature);
      const double least = sse[k] - 0.5 * curvature * (vertex - grid[k]) * (vertex - grid[k]);
      const double half = std::sqrt(std::max(0.0, 2.0 * least * (std::exp(3.84 / n_eff) - 1.0) / curvature));
      if (lo == k) l.low = std::min(grid[k], std::max(grid[k - 1], vertex - half));
      if (hi == k) l.high = std::max(grid[k], std::min(grid[k + 1], vertex + half));
    }
  }
  l.seconds = l.samples * dt;
  l.low_s = l.low * dt;
  l.high_s = l.high * dt;
  return l;
}

}  // namespace rollsim::diag
