// Diagnosis: a fuel-rate recording's engine start (cold or hot) inferred from its first minutes of running.
#include <algorithm>
#include <cmath>

#include "pipeline.hpp"

namespace rollsim {

std::string to_string(EngineStart s) {
  switch (s) {
    case EngineStart::cold: return "cold";
    case EngineStart::hot: return "hot";
    case EngineStart::infer: return "infer";
  }
  return "cold";
}

namespace diag {
namespace {

// Measured and simulated fuel energy per block of `block_s` of running (engine-off segments skipped), each block
// tagged by the running time at its start.
struct Block {
  double start_s = 0.0, measured_j = 0.0, simulated_j = 0.0;
};
std::vector<Block> running_blocks(const std::vector<double>& measured_w, const std::vector<double>& sim_w,
                                  const std::vector<double>& dt_s, const DriveCycle& c, double block_s) {
  std::vector<Block> out;
  double running_s = 0.0;
  for (std::size_t i = 0; i < dt_s.size() && i < measured_w.size() && i < sim_w.size(); ++i) {
    if (c.engine_off_at(i)) continue;
    if (out.empty() || running_s >= out.back().start_s + block_s) out.push_back({running_s, 0.0, 0.0});
    out.back().measured_j += measured_w[i] * dt_s[i];
    out.back().simulated_j += sim_w[i] * dt_s[i];
    running_s += dt_s[i];
  }
  if (!out.empty() && running_s < out.back().start_s + 0.5 * block_s) out.pop_back();  // a stub at the end
  return out;
}

}  // namespace

// A cold engine burns more than the warm model in its first minutes, and the same later: the early blocks' ratio of
// measured to simulated fuel over the late blocks' ratio is the early excess, free of the channel's scale and of
// any level error the model carries all trip long. Its standard error comes from the late blocks' own scatter.
EngineStartState infer_engine_start(const std::vector<double>& measured_w, const std::vector<double>& sim_w,
                                    const std::vector<double>& dt_s, const DriveCycle& c, const DiagnoseOptions& opt) {
  constexpr double kBlock_s = 60.0;
  EngineStartState s;
  s.start = EngineStart::cold;
  double em = 0.0, es = 0.0, lm = 0.0, ls = 0.0;
  int ne = 0;
  std::vector<double> late_ratio, late_weight;
  for (const Block& b : running_blocks(measured_w, sim_w, dt_s, c, kBlock_s)) {
    if (b.start_s + kBlock_s <= opt.engine_start_early_s + 1e-9) {
      em += b.measured_j, es += b.simulated_j, ++ne;
    } else if (b.start_s >= opt.engine_start_late_s && b.simulated_j > 0.0) {
      lm += b.measured_j, ls += b.simulated_j;
      late_ratio.push_back(b.measured_j / b.simulated_j);
      late_weight.push_back(b.simulated_j);
    }
  }
  const auto nl = late_ratio.size();
  if (ne < 2 || nl < 3 || !(es > 0.0) || !(ls > 0.0) || !(lm > 0.0)) return s;  // too short to tell: cold, as before
  const double late = lm / ls, early = em / es;
  // Scatter of a block's ratio about the late mean (energy-weighted: an idling block's ratio is noisier).
  const double mean_w = ls / static_cast<double>(nl);
  double ss = 0.0;
  for (std::size_t k = 0; k < nl; ++k) ss += late_weight[k] / mean_w * (late_ratio[k] - late) * (late_ratio[k] - late);
  const double block_sd = std::sqrt(ss / static_cast<double>(nl - 1));
  const double se = block_sd * std::sqrt(1.0 / ne + 1.0 / static_cast<double>(nl)) / late;
  s.inferred = true;
  s.early_excess = early / late - 1.0;
  s.early_excess_ci_low = s.early_excess - 1.96 * se;
  s.early_excess_ci_high = s.early_excess + 1.96 * se;
  s.start = s.early_excess_ci_high < opt.engine_start_min_cold_excess ? EngineStart::hot : EngineStart::cold;
  return s;
}

}  // namespace diag
}  // namespace rollsim
