// Discovery benchmark: concealed-effect cases, blind diagnosis, parameter-only and sparse-regression baselines.
#include "rollsim/diagnose/bench.hpp"

#include <unistd.h>

#include <Eigen/Dense>
#include <algorithm>
#include <filesystem>
#include <array>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <iomanip>
#include <mutex>
#include <optional>
#include <sstream>
#include <thread>

#include "rollsim/common/yaml_reader.hpp"
#include "rollsim/cycle/drive_cycle.hpp"
#include "rollsim/diagnose/diagnose.hpp"
#include "rollsim/sim/simulation.hpp"

namespace rollsim {

std::pair<double, double> wilson_interval(int k, int n) {
  if (n == 0) return {0.0, 1.0};
  const double z = 1.96, p = static_cast<double>(k) / n, z2n = z * z / n;
  const double c = (p + z2n / 2) / (1 + z2n), h = z * std::sqrt(p * (1 - p) / n + z2n / (4.0 * n)) / (1 + z2n);
  return {std::max(0.0, c - h), std::min(1.0, c + h)};
}

std::vector<std::string> sparse_regression_discovery(const Vehicle& vehicle, const Recording& rec, double window_s) {
  // Nominal model on the recorded speed: the regression explains the measured window energy by the simulated one
  // plus library terms, as a SINDy user without the physics catalogue would.
  const DriveCycle c = cycle_of_recording(rec);
  SimulationOptions so;
  so.record_trace = true;
  const SimulationResult sim = simulate_replay(VehicleModel::assemble(vehicle), c, so);
  // The channel in the simulation's energy domain: battery power, fuel chemical power, or SOC x capacity.
  double fuel_j_per_m3 = 0.0, capacity_j = 0.0;
  if (const auto* cp = std::get_if<CombustionPowertrainParams>(&vehicle.powertrain))
    fuel_j_per_m3 = cp->fuel.density_kg_per_m3 * cp->fuel.lower_heating_value_j_per_kg;
  if (const auto* ep = std::get_if<ElectricPowertrainParams>(&vehicle.powertrain)) capacity_j = ep->battery.usable_capacity_j;
  const bool soc = !rec.battery_power_w && !rec.fuel_rate_m3ps && rec.soc_fraction;
  std::vector<double> meas(rec.time_s.size(), 0.0);
  if (rec.battery_power_w) meas = *rec.battery_power_w;
  else if (rec.fuel_rate_m3ps)
    for (std::size_t i = 0; i < meas.size(); ++i) meas[i] = (*rec.fuel_rate_m3ps)[i] * fuel_j_per_m3;
  const double kWindowS = window_s;  // the diagnosis' windows
  constexpr int kTerms = 7;          // sim, 1, v, v^2, v^3, a, a v
  std::vector<std::array<double, kTerms>> rows;
  std::vector<double> y;
  std::array<double, kTerms> acc{};
  double yw = 0.0, w0 = rec.time_s.front();
  for (std::size_t i = 0; i + 1 < rec.time_s.size() && i < sim.trace.size(); ++i) {
    const double dt = rec.time_s[i + 1] - rec.time_s[i], v = rec.speed_mps[i];
    const double a = (rec.speed_mps[i + 1] - v) / dt;
    const double sim_w = fuel_j_per_m3 > 0.0 ? sim.trace[i].fuel_rate_m3_per_s * fuel_j_per_m3 : sim.trace[i].battery_power_w;
    const std::array<double, kTerms> phi{sim_w, 1.0, v, v * v, v * v * v, a, a * v};
    for (int k = 0; k < kTerms; ++k) acc[k] += phi[k] * dt;
    // SOC is a state: a window's energy is its drop times the capacity, not an integral of samples.
    yw += soc ? ((*rec.soc_fraction)[i] - (*rec.soc_fraction)[i + 1]) * capacity_j : meas[i] * dt;
    if (rec.time_s[i + 1] - w0 >= kWindowS) {
      rows.push_back(acc);
      y.push_back(yw);
      acc = {};
      yw = 0.0;
      w0 = rec.time_s[i + 1];
    }
  }
  const auto n = static_cast<Eigen::Index>(y.size());
  Eigen::MatrixXd x(n, kTerms);
  Eigen::VectorXd yv(n);
  for (Eigen::Index r = 0; r < n; ++r) {
    yv[r] = y[r];
    for (int k = 0; k < kTerms; ++k) x(r, k) = rows[r][k];
  }
  // Sequential thresholded least squares (Brunton et al. 2016) on unit-norm columns: a term whose contribution
  // |c_k| ||x_k|| is below 1 % of ||y|| is dropped and the rest refitted, until the set stops changing. The 1 % is
  // fixed in advance (about the size of the smallest effects of the sweep); the simulated energy is always kept.
  constexpr double kLambda = 0.01;
  std::vector<bool> on(kTerms, true);
  Eigen::VectorXd coef = Eigen::VectorXd::Zero(kTerms);
  for (int iter = 0; iter < 20; ++iter) {
    std::vector<int> idx;
    for (int k = 0; k < kTerms; ++k)
      if (on[k]) idx.push_back(k);
    Eigen::MatrixXd xs(n, static_cast<Eigen::Index>(idx.size()));
    for (std::size_t j = 0; j < idx.size(); ++j) xs.col(static_cast<Eigen::Index>(j)) = x.col(idx[j]);
    const Eigen::VectorXd c = xs.colPivHouseholderQr().solve(yv);
    coef.setZero();
    for (std::size_t j = 0; j < idx.size(); ++j) coef[idx[j]] = c[static_cast<Eigen::Index>(j)];
    bool changed = false;
    for (int k = 1; k < kTerms; ++k) {
      if (on[k] && std::abs(coef[k]) * x.col(k).norm() < kLambda * yv.norm()) {
        on[k] = false;
        changed = true;
      }
    }
    if (!changed) break;
  }
  // Mapping of terms to catalogue signatures (power terms): 1 -> aux_load (constant power); v^2 -> wind (the
  // 2 rho CdA u v force); a -> regen_limit (the only catalogue effect that acts on the sign of a: braking losses);
  // a v -> mass or rotational_inertia (inertial power, the two cannot be told apart from it). v and v^3 are the
  // RRC level and CdA, calibration quantities, so never discoveries. Time-dependent effects (warm-ups) and F^2 v
  // (slip) have no term: the library cannot name them.
  const char* map[kTerms] = {nullptr, "aux_load", nullptr, "wind", nullptr, "regen_limit", "mass|rotational_inertia"};
  std::vector<std::pair<double, std::string>> found;
  for (int k = 1; k < kTerms; ++k)
    if (on[k] && map[k]) found.push_back({std::abs(coef[k]) * x.col(k).norm(), map[k]});
  std::sort(found.begin(), found.end(), [](const auto& p, const auto& q) { return p.first > q.first; });
  std::vector<std::string> out;
  for (const auto& f : found) out.push_back(f.second);
  return out;
}

namespace {

struct Case {
  std::string group, label;
  SyntheticCase synth;
  std::vector<std::string> expected;
  int seeds = 0;
  unsigned seed0 = 0;
  bool combustion = false;  ///< run on the combustion car (fuel channel) instead of the bench's electric one
};

struct Outcome {
  std::vector<std::string> first;  ///< first finding: effect then its confounded set
  std::vector<std::string> all;    ///< every finding's effect and confounded ids
  double first_value = 0.0;
  std::vector<std::string> sparse;
};

bool has(const std::vector<std::string>& v, const std::string& s) { return std::find(v.begin(), v.end(), s) != v.end(); }

std::string num(double v) {
  std::ostringstream os;
  os << v;
  return os.str();
}

std::vector<Case> build_cases(const BenchOptions& o) {
  std::vector<Case> cases;
  auto add = [&](std::string group, std::string label, SyntheticCase s, std::vector<std::string> expected, int seeds, unsigned seed0) {
    cases.push_back({std::move(group), std::move(label), std::move(s), std::move(expected), seeds, seed0});
  };
  unsigned block = 1000;
  for (const auto& t : concealed_truths()) {
    for (double size : t.sweep) {
      if (o.quick && !(t.truth == "tyre_two_node" && size == 0.3)) continue;
      SyntheticCase s;
      s.effects = {{t.truth, size}};
      s.channel = t.channel;
      const char* where = t.channel == SyntheticChannel::fuel_rate ? " (ice, fuel)" : t.channel == SyntheticChannel::soc ? " (SOC)" : "";
      add("single", t.truth + " " + num(size) + " " + t.size_unit + where, s, {t.catalogue_id}, o.seeds, block);
      cases.back().combustion = t.channel == SyntheticChannel::fuel_rate;
      block += 1000;
    }
  }
  // Confounded pairs: honest answers are "confounded" (or the right name); a confident wrong name fails.
  {
    SyntheticCase s;
    s.effects = {{"payload_drop", 150}};
    add("pair", "flat road: payload 150 kg vs rotational_inertia + RRC level", s, {"mass", "rotational_inertia"}, o.seeds, 90000);
    SyntheticCase st;
    st.cycle = "steady";
    st.effects = {{"aux_compressor", 600}};
    add("pair", "steady 90 km/h: aux 600 W vs RRC level", st, {"aux_load"}, o.seeds, 91000);
  }
  if (!o.quick) {
    SyntheticCase a;
    a.effects = {{"tyre_two_node", 0.3}, {"aux_compressor", 600}};
    add("two", "tyre warm-up 30 % + aux 600 W", a, {"tyre_warmup", "aux_load"}, o.seeds, 92000);
    SyntheticCase b;
    b.effects = {{"wind_gusty", 3}, {"payload_drop", 150}};
    add("two", "wind 3 m/s + payload 150 kg", b, {"wind", "mass"}, o.seeds, 93000);
  }
  add("null", "null (calibration and noise only)", SyntheticCase{}, {}, o.null_seeds, 50000);
  if (!o.quick) {
    // The fuel and SOC channels' own nulls (their artefacts differ: a flow meter's quantum and zero under fuel cut;
    // a 0.1 % SOC quantum with lengthened windows), at least 50 seeds each.
    const int channel_null_seeds = std::max(50, o.null_seeds / 4);
    SyntheticCase f;
    f.channel = SyntheticChannel::fuel_rate;
    add("null", "null, fuel channel (ice.yaml)", f, {}, channel_null_seeds, 52000);
    cases.back().combustion = true;
    SyntheticCase q;
    q.channel = SyntheticChannel::soc;
    add("null", "null, SOC channel (ev.yaml)", q, {}, channel_null_seeds, 54000);
  }
  // The same on real speed traces (urban trips with their own stop-and-go), one block per trace.
  unsigned real_block = 70000;
  for (const auto& trace : o.real_traces) {
    const std::string name = std::filesystem::path(trace.name).stem().string();
    SyntheticCase nul;
    nul.trace = trace;
    add("null", "null on real trace " + name, nul, {}, std::max(1, o.null_seeds / 4), real_block);
    if (!o.quick) {
      for (double size : {0.2, 0.3}) {
        SyntheticCase w;
        w.trace = trace;
        w.effects = {{"tyre_two_node", size}};
        add("single", "tyre_two_node " + num(size) + " on real trace " + name, w, {"tyre_warmup"}, o.seeds,
            real_block + 1000 * static_cast<unsigned>(size * 10));
      }
    }
    real_block += 5000;
  }
  SyntheticCase r;
  r.effects = {{"tyre_two_node", 0.3}};
  r.time_reversed = true;
  add("reversed", "time-reversed warm-up decay (RRC rises at the end)", r, {}, o.quick ? o.null_seeds / 2 : o.null_seeds, 60000);
  return cases;
}

// Single effects and pairs: by the first finding. Two at once: named = both expected ids among all findings (as
// name or confounded), confounded = one of them, mistaken = a finding names neither.
void score_one(const Case& c, const Outcome& r, BenchRow& row) {
  auto score = [&](const std::vector<std::string>& first, const std::vector<std::string>& all, Score& s) {
    if (c.group == "two") {
      int hit = 0;
      for (const auto& e : c.expected) hit += has(all, e) ? 1 : 0;
      if (hit == 2) ++s.named;
      else if (hit == 1) ++s.confounded;
      else if (all.empty()) ++s.missed;
      else ++s.mistaken;
      return;
    }
    if (first.empty() || first.front() == "unexplained") {
      ++s.missed;
      return;
    }
    if (first.size() == 1 && has(c.expected, first.front())) ++s.named;
    else if (std::any_of(c.expected.begin(), c.expected.end(), [&](const std::string& e) { return has(first, e); })) ++s.confounded;
    else ++s.mistaken;
  };
  score(r.first, r.all, row.rollsim);
  if (!r.first.empty() && r.first.front() == "unexplained") ++row.rollsim_unexplained;
  // Parameter-only calibration fits scale, RRC level and CdA and can say nothing else: "nothing missing".
  ++row.calibration.missed;
  // Sparse regression: its first mapped term; the inertial term is a confounded pair by construction.
  std::vector<std::string> sf, sa;
  for (std::size_t k = 0; k < r.sparse.size(); ++k) {
    std::vector<std::string> ids;
    std::stringstream ss(r.sparse[k]);
    for (std::string id; std::getline(ss, id, '|');) ids.push_back(id);
    if (k == 0) sf = ids;
    sa.insert(sa.end(), ids.begin(), ids.end());
  }
  score(sf, sa, row.sparse);
}

}  // namespace

BenchResult run_discovery_bench(const Vehicle& vehicle, const BenchOptions& opt) {
  const auto t0 = std::chrono::steady_clock::now();
  const std::vector<Case> cases = build_cases(opt);
  std::optional<Vehicle> combustion;
  if (std::any_of(cases.begin(), cases.end(), [](const Case& c) { return c.combustion; }))
    combustion = load_vehicle_file(resolve_data_file(opt.combustion_vehicle, "vehicles", ".yaml", "combustion vehicle"));
  struct Task {
    std::size_t c;
    int s;
  };
  std::vector<Task> tasks;
  for (std::size_t c = 0; c < cases.size(); ++c)
    for (int s = 0; s < cases[c].seeds; ++s) tasks.push_back({c, s});
  std::vector<Outcome> out(tasks.size());
  std::atomic<std::size_t> next{0}, done{0};
  std::mutex io;
  const unsigned threads = opt.threads > 0 ? opt.threads : std::max(1u, std::thread::hardware_concurrency());
  auto worker = [&] {
    for (std::size_t k; (k = next.fetch_add(1)) < tasks.size();) {
      const Case& c = cases[tasks[k].c];
      SyntheticCase s = c.synth;
      s.seed = c.seed0 + static_cast<unsigned>(tasks[k].s);
      const Vehicle& car = c.combustion ? *combustion : vehicle;
      const Recording rec = generate_case(car, s);
      const Diagnosis d = diagnose(car, {rec});
      Outcome& o = out[k];
      for (std::size_t f = 0; f < d.findings.size(); ++f) {
        o.all.push_back(d.findings[f].effect);
        o.all.insert(o.all.end(), d.findings[f].confounded_with.begin(), d.findings[f].confounded_with.end());
        if (f == 0) {
          o.first = o.all;
          o.first_value = d.findings[f].parameters.empty() ? 0.0 : d.findings[f].parameters.front().value;
        }
      }
      o.sparse = sparse_regression_discovery(car, rec, d.window_s);
      const std::size_t n = done.fetch_add(1) + 1;
      if (opt.progress) {
        std::lock_guard<std::mutex> lock(io);
        std::fprintf(stderr, "\rdiagnose-bench: %zu/%zu recordings", n, tasks.size());
        if (n == tasks.size()) std::fprintf(stderr, "\n");
      }
    }
  };
  std::vector<std::thread> pool;
  for (unsigned i = 0; i < threads; ++i) pool.emplace_back(worker);
  for (auto& th : pool) th.join();

  BenchResult res;
  res.threads = threads;
  for (const auto& c : cases) res.rows.push_back({c.group, c.label, c.expected, {}, {}, {}, 0});
  for (std::size_t k = 0; k < tasks.size(); ++k) {
    const Case& c = cases[tasks[k].c];
    BenchRow& row = res.rows[tasks[k].c];
    const Outcome& r = out[k];
    if (c.group == "null") {
      // Any finding (named or unexplained) is a false discovery; the baselines' too.
      (r.first.empty() ? row.rollsim.missed : row.rollsim.mistaken)++;
      ++row.calibration.missed;
      (r.sparse.empty() ? row.sparse.missed : row.sparse.mistaken)++;
    } else if (c.group == "reversed") {
      // Only a warm-up with a positive cold excess (anywhere in the findings' first place) is calling it warm-up.
      const bool warm = !r.first.empty() && r.first.front() == "tyre_warmup" && r.first_value > 0.0;
      (warm ? row.rollsim.mistaken : row.rollsim.missed)++;
      ++row.calibration.missed;
      ++row.sparse.missed;  // the library has no time-dependent term: it cannot call anything warm-up
    } else {
      score_one(c, r, row);
    }
  }
  res.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return res;
}

std::string bench_text(const BenchResult& r) {
  std::ostringstream os;
  auto cell = [](const Score& s) {
    std::ostringstream c;
    c << s.named << "/" << s.confounded << "/" << s.missed << "/" << s.mistaken;
    return c.str();
  };
  os << "Scores are named first / named confounded / missed / mistaken, over seeds. Baselines: calib = parameter-only\n"
        "calibration (scale, RRC level, CdA: can only say nothing missing); sparse = STLSQ on window integrals of\n"
        "{1, v, v^2, v^3, a, a v}, terms mapped 1->aux_load, v^2->wind, a->regen_limit, a v->mass|rotational_inertia.\n"
        "Two at once: named = both found, confounded = one found. rollsim 'missed' includes unexplained findings (unexpl.).\n\n";
  std::string group;
  for (const auto& row : r.rows) {
    if (row.group == "null" || row.group == "reversed") continue;
    if (row.group != group) {
      group = row.group;
      os << (group == "single" ? "Single concealed effects (truth -> expected catalogue id)"
             : group == "pair" ? "Confounded pairs"
                               : "Two effects at once")
         << "\n"
         << std::left << std::setw(62) << "case" << std::setw(18) << "expected" << std::right << std::setw(14) << "rollsim"
         << std::setw(8) << "unexpl." << std::setw(12) << "calib" << std::setw(14) << "sparse" << "\n";
    }
    std::string exp;
    for (const auto& e : row.expected) exp += (exp.empty() ? "" : "+") + e;
    os << std::left << std::setw(62) << row.label << std::setw(18) << exp << std::right << std::setw(14) << cell(row.rollsim)
       << std::setw(8) << row.rollsim_unexplained << std::setw(12) << cell(row.calibration) << std::setw(14) << cell(row.sparse)
       << "\n";
  }
  os << "\n";
  for (const auto& row : r.rows) {
    if (row.group != "null" && row.group != "reversed") continue;
    auto rate = [&](const char* who, const Score& s) {
      const auto [lo, hi] = wilson_interval(s.mistaken, s.n());
      os << "  " << std::left << std::setw(8) << who << std::right << s.mistaken << "/" << s.n() << " (" << std::fixed
         << std::setprecision(1) << 100.0 * s.mistaken / std::max(1, s.n()) << " %, Wilson 95 % " << 100 * lo << "-" << 100 * hi
         << " %)\n"
         << std::defaultfloat;
    };
    os << row.label << (row.group == "null" ? ": false discoveries\n" : ": called warm-up\n");
    rate("rollsim", row.rollsim);
    rate("calib", row.calibration);
    rate("sparse", row.sparse);
  }
  os << "\n" << std::fixed << std::setprecision(1) << r.seconds << " s on " << r.threads << " threads\n" << std::defaultfloat;
  return os.str();
}

}  // namespace rollsim
