// Discovery benchmark: concealed-effect cases, blind diagnosis, parameter-only and sparse-regression baselines.
#include "rollsim/common/distribute.hpp"
#include "rollsim/discovery/scorecard.hpp"

#include <algorithm>
#include <filesystem>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <iomanip>
#include <mutex>
#include <optional>
#include <sstream>
#include <thread>

#include "rollsim/common/error.hpp"
#include "rollsim/common/yaml_reader.hpp"
#include "rollsim/cycle/drive_cycle.hpp"
#include "rollsim/diagnose/diagnose.hpp"
#include "rollsim/common/format.hpp"

namespace rollsim {

std::pair<double, double> wilson_interval(int k, int n) {
  if (n == 0) return {0.0, 1.0};
  const double z = 1.96, p = static_cast<double>(k) / n, z2n = z * z / n;
  const double c = (p + z2n / 2) / (1 + z2n), h = z * std::sqrt(p * (1 - p) / n + z2n / (4.0 * n)) / (1 + z2n);
  return {std::max(0.0, c - h), std::min(1.0, c + h)};
}

namespace {

// A row's second figure, as "    what: k/n (p %, Wilson 95 % lo-hi %)".
void sub_rate_line(std::ostream& os, const std::string& what, int k, int n) {
  const auto [lo, hi] = wilson_interval(k, n);
  os << "    " << what << ": " << k << "/" << n << std::fixed << std::setprecision(0) << " (" << 100.0 * k / std::max(1, n)
     << " %, Wilson 95 % " << 100 * lo << "-" << 100 * hi << " %)\n" << std::defaultfloat;
}

struct Case {
  std::string group, label;
  SyntheticCase synth;
  std::vector<std::string> expected;
  int seeds = 0;
  unsigned seed0 = 0;
  bool combustion = false;  ///< run on the combustion car (fuel channel) instead of the bench's electric one
  std::optional<MultiTripCase> trips;  ///< several trips diagnosed together instead of `synth` alone
  int sign = 0;                         ///< RowRule::sign
  std::string never_called{};           ///< RowRule::never_called ("reversed" rows); `{}`: rows may leave it out
};

struct Outcome {
  std::vector<FindingSummary> findings;
  /// The sparse baseline's mapped terms (every trip's, in order): per sparse_thresholds() entry, then at BIC's choice.
  std::vector<std::vector<std::string>> sparse;
};

// Adds ids not yet in `to`, in order.
void merge_ids(std::vector<std::string>& to, const std::vector<std::string>& from) {
  for (const auto& id : from)
    if (std::find(to.begin(), to.end(), id) == to.end()) to.push_back(id);
}

bool has(const std::vector<std::string>& v, const std::string& s) { return std::find(v.begin(), v.end(), s) != v.end(); }

std::string num(double v) { return significant(v, 6); }

// The steady-wind truth's bearing per seed: golden-angle steps, spread evenly round the compass over any run of seeds.
double truth_bearing_deg(unsigned seed) { return std::fmod(137.50776405 * seed, 360.0); }

double bearing_error_deg(double a_deg, double b_deg) {
  const double d = std::fmod(std::abs(a_deg - b_deg), 360.0);
  return std::min(d, 360.0 - d);
}

std::vector<Case> build_cases(const BenchOptions& o) {
  std::vector<Case> cases;
  auto add = [&](std::string group, std::string label, SyntheticCase s, std::vector<std::string> expected, int seeds, unsigned seed0) {
    cases.push_back({std::move(group), std::move(label), std::move(s), std::move(expected), seeds, seed0, false, std::nullopt});
  };
  unsigned block = 1000;
  for (const auto& t : concealed_truths()) {
    if (t.multi_trip) continue;  // below, on several trips
    for (double size : t.sweep) {
      if (o.quick && !(t.truth == "tyre_two_node" && size == 0.3)) continue;
      SyntheticCase s;
      s.effects = {{t.truth, size}};
      s.channel = t.channel;
      if (!t.cycle.empty()) s.cycle = t.cycle, s.soak_s = t.soak_s;
      s.gps = t.gps;
      if (t.real_logger) s = real_logger(s);
      std::string where = t.channel == SyntheticChannel::fuel_rate ? " (ice, fuel" : t.channel == SyntheticChannel::soc ? " (SOC" : "";
      if (!t.cycle.empty()) where += (where.empty() ? " (" : ", ") + t.cycle + " x2, " + num(t.soak_s) + " s soak";
      if (t.gps) where += where.empty() ? " (GPS" : ", GPS";
      if (!where.empty()) where += ")";
      const std::string logger = t.real_logger ? ", real logger" : "";
      if (t.never_called.empty()) {
        // A withheld net climb with hills is a road profile too: road_profile carries the net climb with the hills.
        std::vector<std::string> expected{t.catalogue_id};
        if (t.catalogue_id == "road_grade") expected.push_back("road_profile");
        add("single", t.truth + " " + num(size) + " " + t.size_unit + where + logger, s, expected, o.seeds, block);
      } else {
        add("reversed", t.truth + " " + num(size) + " " + t.size_unit + where + logger + ": called " + t.never_called, s, {},
            o.seeds, block);
        cases.back().never_called = t.never_called;
      }
      cases.back().sign = t.sign;
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
  // Real loggers: a lag of 0.3-1.7 s that is not whole samples, and a channel scale within +-3 %.
  add("null", "null, real logger (lag 0.3-1.7 s, scale +-3 %)", real_logger(SyntheticCase{}), {}, o.quick ? o.null_seeds / 3 : o.null_seeds,
      56000);
  if (!o.quick) {
    SyntheticCase w = real_logger(SyntheticCase{});
    w.effects = {{"tyre_two_node", 0.35}};
    add("single", "tyre_two_node 0.35 1 (cold RRC excess), real logger", w, {"tyre_warmup"}, o.seeds, 57000);
    cases.back().sign = +1;
  }
  if (!o.quick) {
    // The fuel and SOC channels' own nulls (their artefacts differ: a flow meter's quantum and zero under fuel cut;
    // a 0.1 % SOC quantum with lengthened windows), at least 50 seeds each.
    const int channel_null_seeds = std::max(50, o.null_seeds / 4);
    SyntheticCase f;
    f.channel = SyntheticChannel::fuel_rate;
    add("null", "null, fuel channel (ice.yaml)", f, {}, channel_null_seeds, 52000);
    cases.back().combustion = true;
    // A hot engine switched off for a 10-minute soak between two UDDS (as a cold-start test's, without the cold).
    f.cycle = "udds";
    f.soak_s = 600.0;
    add("null", "null, fuel channel (ice.yaml), udds x2, 600 s soak", f, {}, o.null_seeds, 58000);
    cases.back().combustion = true;
    SyntheticCase g;
    g.gps = true;
    add("null", "null, GPS on a winding route", g, {}, o.null_seeds, 59000);
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
  // Ambient temperature on RRC: four trips (WLTC, FTP-75, Artemis road, WLTC) at ambients spread over -5..30 degC,
  // each trip's RRC level scattered +-1.5 % (pressure, road surface), diagnosed together (held out by trip).
  {
    auto add_trips = [&](std::string group, std::string label, std::vector<ConcealedEffect> effects,
                         std::vector<std::string> expected, int seeds, unsigned seed0) {
      add(std::move(group), std::move(label), SyntheticCase{}, std::move(expected), seeds, seed0);
      MultiTripCase m;
      m.effects = std::move(effects);
      cases.back().trips = m;
    };
    const int trip_null_seeds = o.quick ? std::max(1, o.null_seeds / 3) : std::max(100, o.null_seeds / 2);
    add_trips("null", "null, 4 trips at -5..30 degC (trip RRC scatter +-1.5 %)", {}, {}, trip_null_seeds, 80000);
    if (!o.quick) {
      // Stress: trip-to-trip RRC scatter of +-3 % (sd 1.7 %), above the 1 % the diagnosis assumes.
      add_trips("null", "null, 4 trips, trip RRC scatter +-3 % (above the assumed 1 % sd)", {}, {},
                std::max(50, o.null_seeds / 4), 88000);
      cases.back().trips->trip_rrc_scatter = 0.03;
    }
    const ConcealedTruthInfo& warm = concealed_truth("ambient_compound");
    unsigned trip_block = 100000;
    for (double size : warm.sweep) {
      trip_block += 1000;
      if (o.quick && size != 0.008) continue;
      add_trips("trips", "ambient_compound " + num(size) + " /K, 4 trips -5..30 degC", {{"ambient_compound", size}},
                {"ambient_rrc"}, o.quick ? std::max(1, o.seeds / 2) : o.seeds, trip_block);
    }
    // Cabin conditioning by the ambient: the same four trips over -5..35 degC (heating and cooling days).
    const ConcealedTruthInfo& hvac = concealed_truth("hvac_cabin");
    unsigned hvac_block = 110000;
    for (double size : hvac.sweep) {
      hvac_block += 1000;
      if (o.quick) continue;
      add_trips("trips", "hvac_cabin " + num(size) + " W/K, 4 trips -5..35 degC", {{"hvac_cabin", size}}, {"hvac_ambient"},
                o.seeds, hvac_block);
      cases.back().trips->ambient_max_c = 35.0;
    }
    if (!o.quick) {
      // Cold starts: the tyre starts each trip at ambient, so a colder trip also warms up more (both effects true).
      add_trips("two", "ambient_cold_start 0.008 /K (+ tyre warm-up), 4 trips", {{"ambient_cold_start", 0.008}},
                {"ambient_rrc", "tyre_warmup"}, o.seeds, 89000);
    }
  }
  SyntheticCase r;
  r.effects = {{"tyre_two_node", 0.3}};
  r.time_reversed = true;
  add("reversed", "time-reversed warm-up decay (RRC rises at the end): called tyre_warmup", r, {},
      o.quick ? o.null_seeds / 2 : o.null_seeds, 60000);
  cases.back().never_called = "tyre_warmup";
  for (auto& c : cases)  // every multi-trip truth is signed (a colder trip rolls harder)
    if (c.trips && !c.expected.empty()) c.sign = +1;
  if (!o.only.empty()) {
    std::string labels;  // the first few, to show what a label looks like
    for (std::size_t k = 0; k < cases.size() && k < 6; ++k) labels += (k ? "; " : "") + cases[k].label;
    labels += "; ... (" + std::to_string(cases.size()) + " rows)";
    std::erase_if(cases, [&](const Case& c) {
      return std::none_of(o.only.begin(), o.only.end(), [&](const std::string& s) { return c.label.find(s) != std::string::npos; });
    });
    if (cases.empty()) throw InputError("--only", "matches no row's label; the rows are: " + labels);
  }
  return cases;
}

void count_into(Score& s, Tally t) {
  switch (t) {
    case Tally::named: ++s.named; break;
    case Tally::confounded: ++s.confounded; break;
    case Tally::missed: ++s.missed; break;
    case Tally::mistaken: ++s.mistaken; break;
  }
}

// The sparse baseline's mapped terms as findings: "mass|rotational_inertia" (the inertial term) is a confounded pair
// by construction; the terms carry no physical size.
std::vector<FindingSummary> sparse_findings(const std::vector<std::string>& terms) {
  std::vector<FindingSummary> out;
  for (const auto& term : terms) {
    std::vector<std::string> ids;
    std::stringstream ss(term);
    for (std::string id; std::getline(ss, id, '|');) ids.push_back(id);
    out.push_back({ids.front(), std::vector<std::string>(ids.begin() + 1, ids.end()), 0.0});
  }
  return out;
}

}  // namespace

Tally score_findings(const RowRule& rule, const std::vector<FindingSummary>& findings, bool* wrong_sign) {
  if (wrong_sign) *wrong_sign = false;
  auto ids_of = [](const FindingSummary& f) {
    std::vector<std::string> ids{f.effect};
    ids.insert(ids.end(), f.confounded_with.begin(), f.confounded_with.end());
    return ids;
  };
  if (rule.group == "null") return findings.empty() ? Tally::missed : Tally::mistaken;
  if (rule.group == "reversed") {
    for (const auto& f : findings) {
      if (f.effect != rule.never_called) continue;
      if (wrong_sign) *wrong_sign = f.size < 0.0;
      return Tally::mistaken;
    }
    return Tally::missed;
  }
  if (rule.group == "two") {
    // As in every effect row, an unexplained finding names nothing: missed, not a wrong name.
    std::vector<std::string> all;
    for (const auto& f : findings)
      if (f.effect != "unexplained") merge_ids(all, ids_of(f));
    int hit = 0;
    for (const auto& e : rule.expected) hit += has(all, e) ? 1 : 0;
    if (hit >= 2) return Tally::named;
    if (hit == 1) return Tally::confounded;
    return all.empty() ? Tally::missed : Tally::mistaken;
  }
  if (findings.empty() || findings.front().effect == "unexplained") return Tally::missed;
  const FindingSummary& f = findings.front();
  // A load that gives power back, a tyre that rolls easier cold: not the physics the name stands for.
  if (rule.sign > 0 && f.size < 0.0 && has(rule.expected, f.effect)) {
    if (wrong_sign) *wrong_sign = true;
    return Tally::mistaken;
  }
  const std::vector<std::string> first = ids_of(f);
  if (first.size() == 1 && has(rule.expected, f.effect)) return Tally::named;
  for (const auto& e : rule.expected)
    if (has(first, e)) return Tally::confounded;
  return Tally::mistaken;
}

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
  const unsigned threads = opt.threads > 0 ? opt.threads : std::max(1u, std::thread::hardware_concurrency());
  // Each recording's outcome travels as bytes: it may be diagnosed on another MPI rank.
  auto worker = [&](std::size_t k) {
    Outcome o;
    {
      const Case& c = cases[tasks[k].c];
      SyntheticCase s = c.synth;
      s.seed = c.seed0 + static_cast<unsigned>(tasks[k].s);
      if (s.gps) s.wind_from_deg = truth_bearing_deg(s.seed);
      const Vehicle& car = c.combustion ? *combustion : vehicle;
      std::vector<Recording> recs;
      if (c.trips) {
        MultiTripCase m = *c.trips;
        m.seed = s.seed;
        recs = generate_trips(car, m);
      } else {
        recs.push_back(generate_case(car, s));
      }
      DiagnoseOptions dopt;
      dopt.infer_road_profile = opt.infer_road_profile;
      const Diagnosis d = diagnose(car, recs, dopt);
      for (const auto& f : d.findings) {
        const auto from = f.fitted.find("wind_from_deg");
        const auto decay = f.fitted.find("decay_s");
        FindingSummary fs{f.effect, f.confounded_with, f.parameters.empty() ? 0.0 : f.parameters.front().value,
                          from == f.fitted.end() ? -1.0 : from->second, 0.0, 0.0, decay == f.fitted.end() ? -1.0 : decay->second};
        for (const auto& p : f.parameters)
          if (p.name == "wind_from_deg" && p.profiled) fs.wind_from_low_deg = p.ci_low, fs.wind_from_high_deg = p.ci_high;
        o.findings.push_back(std::move(fs));
      }
      // The sparse regression sees one trip at a time (its library has no trip-level term): every trip's terms.
      o.sparse.assign(sparse_thresholds().size() + 1, {});
      for (const auto& rec : recs) {
        const SparseSweep sw = sparse_regression_sweep(car, rec, d.window_s);
        for (std::size_t t = 0; t < sw.by_threshold.size(); ++t) merge_ids(o.sparse[t], sw.by_threshold[t]);
        merge_ids(o.sparse.back(), sw.bic);
      }
    }
    std::string bytes;
    put(bytes, o.findings.size());
    for (const auto& f : o.findings) {
      put(bytes, f.effect);
      put(bytes, f.confounded_with);
      put(bytes, f.size);
      put(bytes, f.wind_from_deg);
      put(bytes, f.wind_from_low_deg);
      put(bytes, f.wind_from_high_deg);
      put(bytes, f.decay_s);
    }
    put(bytes, o.sparse);
    return bytes;
  };
  std::mutex io;
  CaseProgress progress;
  if (opt.progress) {
    progress = [&io](std::size_t n, std::size_t total) {
      std::lock_guard<std::mutex> lock(io);
      std::fprintf(stderr, "\rdiagnose-bench: %zu/%zu recordings", n, total);
      if (n == total) std::fprintf(stderr, "\n");
    };
  }
  const auto gathered = map_cases(opt.map_cases, tasks.size(), opt.threads, worker, progress);
  std::vector<Outcome> out(tasks.size());
  for (std::size_t k = 0; k < tasks.size(); ++k) {
    std::string_view in = gathered[k];
    std::size_t n = 0;
    take(in, n);
    out[k].findings.resize(n);
    for (auto& f : out[k].findings) {
      take(in, f.effect);
      take(in, f.confounded_with);
      take(in, f.size);
      take(in, f.wind_from_deg);
      take(in, f.wind_from_low_deg);
      take(in, f.wind_from_high_deg);
      take(in, f.decay_s);
    }
    take(in, out[k].sparse);
  }

  BenchResult res;
  res.threads = threads;
  res.ranks = opt.ranks;
  const std::size_t nt = sparse_thresholds().size();
  for (const auto& c : cases) {
    BenchRow row;
    row.group = c.group;
    row.label = c.label;
    row.expected = c.expected;
    row.sparse_by_threshold.assign(nt, {});
    res.rows.push_back(std::move(row));
  }
  for (std::size_t k = 0; k < tasks.size(); ++k) {
    const Case& c = cases[tasks[k].c];
    BenchRow& row = res.rows[tasks[k].c];
    const Outcome& r = out[k];
    auto sparse_score = [&](std::size_t t) -> Score& { return t < nt ? row.sparse_by_threshold[t] : row.sparse_bic; };
    const RowRule rule{c.group, c.expected, c.sign, c.never_called};
    bool wrong_sign = false;
    count_into(row.rollsim, score_findings(rule, r.findings, &wrong_sign));
    if (wrong_sign) ++row.rollsim_wrong_sign;
    if (c.synth.gps && has(c.expected, "wind_heading")) {
      row.scores_direction = true;
      const auto& f = r.findings;
      const double truth_deg = truth_bearing_deg(c.seed0 + static_cast<unsigned>(tasks[k].s));
      if (!f.empty() && f.front().effect == "wind_heading" && f.front().confounded_with.empty()) {
        if (bearing_error_deg(f.front().wind_from_deg, truth_deg) <= 45.0) ++row.rollsim_direction_right;
        // The interval's ends are unwrapped about the fitted bearing: the truth is taken to the same turn.
        const double on_turn = f.front().wind_from_deg + std::remainder(truth_deg - f.front().wind_from_deg, 360.0);
        if (on_turn >= f.front().wind_from_low_deg && on_turn <= f.front().wind_from_high_deg) ++row.rollsim_interval_holds;
      }
    }
    // Whether an auxiliary load was found decaying: the winter heater's shape, and how often the duty-cycled and
    // steady loads (a decay only on half the cabin_load seeds) are given one.
    static const std::vector<std::string> kLoadTruths{"winter_heater", "cabin_load", "ac_duty_cycle", "aux_compressor"};
    if (c.synth.effects.size() == 1 && has(kLoadTruths, c.synth.effects.front().truth)) {
      row.scores_decay = true;
      const auto& f = r.findings;
      if (!f.empty() && f.front().effect == "aux_load" && f.front().confounded_with.empty() && f.front().decay_s > 0.0)
        ++row.rollsim_decay_found;
    }
    if (!r.findings.empty() && r.findings.front().effect == "unexplained") ++row.rollsim_unexplained;
    // Parameter-only calibration fits scale, RRC level and CdA and can say nothing else: "nothing missing".
    ++row.calibration.missed;
    // Sparse regression, at each threshold and at BIC's (its library has no time term: it never calls warm-up).
    for (std::size_t t = 0; t <= nt; ++t) count_into(sparse_score(t), score_findings(rule, sparse_findings(r.sparse[t])));
  }
  // The sparse baseline at its best threshold, chosen after scoring (an oracle choice, generous to the baseline):
  // the most effects named (alone or confounded) among thresholds whose pooled null false-discovery rate is at most
  // 5 %; if none is, the threshold with the lowest null rate (ties: the most named).
  {
    // Null rows count false discoveries; effect rows (not the time-reversed one) count what was named.
    auto pool = [](SparseThresholdSummary& m, const std::string& group, const Score& sc) {
      if (group == "null") {
        m.null_false += sc.mistaken;
        m.null_n += sc.n();
      } else if (group != "reversed") {
        m.named += sc.named;
        m.confounded += sc.confounded;
        m.mistaken += sc.mistaken;
        m.effect_n += sc.n();
      }
    };
    int best = 0;
    std::vector<SparseThresholdSummary> sums(nt);
    for (std::size_t t = 0; t < nt; ++t) {
      auto& m = sums[t];
      m.threshold = sparse_thresholds()[t];
      for (const auto& row : res.rows) pool(m, row.group, row.sparse_by_threshold[t]);
    }
    auto ok = [](const SparseThresholdSummary& m) { return m.null_false <= 0.05 * m.null_n; };
    auto hits = [](const SparseThresholdSummary& m) { return m.named + m.confounded; };
    for (std::size_t t = 1; t < nt; ++t) {
      const auto &a = sums[t], &b = sums[static_cast<std::size_t>(best)];
      const bool better = ok(a) != ok(b) ? ok(a)
                          : ok(a)        ? hits(a) > hits(b)
                                         : (a.null_false * b.null_n < b.null_false * a.null_n ||
                                            (a.null_false * b.null_n == b.null_false * a.null_n && hits(a) > hits(b)));
      if (better) best = static_cast<int>(t);
    }
    for (auto& row : res.rows) row.sparse = row.sparse_by_threshold[static_cast<std::size_t>(best)];
    res.sparse_best = best;
    res.sparse_summary = std::move(sums);
    // BIC's own choice, pooled the same way.
    SparseThresholdSummary bic;
    for (const auto& row : res.rows) pool(bic, row.group, row.sparse_bic);
    res.sparse_bic_summary = bic;
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
        "{1, v, v^2, v^3, a, a v}, terms mapped 1->aux_load, v^2->wind, a->regen_limit, a v->mass|rotational_inertia,\n"
        "shown at its best threshold of the sweep (table at the end).\n"
        "Two at once: named = both found, confounded = one found. rollsim 'missed' includes unexplained findings (unexpl.).\n"
        "Where the truth's physics has a sign, the expected effect with a negative size is mistaken (neg.: how many).\n"
        "named %: rollsim's named-alone rate with its Wilson 95 % interval.\n\n";
  const double best_threshold =
      r.sparse_summary.empty() ? 0.0 : r.sparse_summary[static_cast<std::size_t>(r.sparse_best)].threshold;
  std::size_t label_w = 62;  // the case column fits the longest label
  for (const auto& row : r.rows) label_w = std::max(label_w, row.label.size() + 2);
  const int lw = static_cast<int>(label_w);
  std::string group;
  for (const auto& row : r.rows) {
    if (row.group == "null" || row.group == "reversed") continue;
    if (row.group != group) {
      group = row.group;
      os << (group == "single"  ? "Single concealed effects (truth -> expected catalogue id)"
             : group == "pair"  ? "Confounded pairs"
             : group == "trips" ? "Across trips: ambient temperature on RRC and on the cabin's load (4 trips diagnosed together, held out by trip)"
                                : "Two effects at once")
         << "\n"
         << std::left << std::setw(lw) << "case" << std::setw(18) << "expected" << std::right << std::setw(14) << "rollsim"
         << std::setw(8) << "unexpl." << std::setw(6) << "neg." << std::setw(18) << "named % (Wilson)" << std::setw(12)
         << "calib" << std::setw(14) << ("sparse@" + num(best_threshold)) << "\n";
    }
    std::string exp;
    for (const auto& e : row.expected) exp += (exp.empty() ? "" : "+") + e;
    const auto [lo, hi] = wilson_interval(row.rollsim.named, row.rollsim.n());
    std::ostringstream named;
    named << std::fixed << std::setprecision(0) << 100.0 * row.rollsim.named / std::max(1, row.rollsim.n()) << " (" << 100 * lo
          << "-" << 100 * hi << ")";
    os << std::left << std::setw(lw) << row.label << std::setw(18) << exp << std::right << std::setw(14) << cell(row.rollsim)
       << std::setw(8) << row.rollsim_unexplained << std::setw(6) << row.rollsim_wrong_sign << std::setw(18) << named.str()
       << std::setw(12) << cell(row.calibration) << std::setw(14) << cell(row.sparse) << "\n";
    if (row.scores_direction)
    {
      sub_rate_line(os, "named with the wind's bearing within 45 deg", row.rollsim_direction_right, row.rollsim.n());
      sub_rate_line(os, "named with the bearing's 95 % interval holding the truth", row.rollsim_interval_holds, row.rollsim.n());
    }
    if (row.scores_decay)
      sub_rate_line(os, "named with a decay from the trip's start (decay_s fitted)", row.rollsim_decay_found, row.rollsim.n());
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
    os << row.label << (row.group == "null" ? ": false discoveries\n" : " (either sign)\n");
    rate("rollsim", row.rollsim);
    if (row.group == "reversed")
      os << "    of which with a negative size: " << row.rollsim_wrong_sign << "; first finding unexplained: " << row.rollsim_unexplained
         << "\n";
    rate("calib", row.calibration);
    rate("sparse", row.sparse);
  }
  // The sparse baseline over its threshold sweep, pooled: so its best setting is shown, not one chosen for it.
  if (!r.sparse_summary.empty()) {
    os << "\nSparse baseline by threshold (pooled; effects: named/confounded/mistaken of seeds in single, pair and two rows;\n"
          "null: false discoveries over every null row). Best: most named or confounded with null FDR <= 5 %, else the\n"
          "lowest null FDR.\n";
    os << std::left << std::setw(22) << "threshold" << std::right << std::setw(26) << "effects n/c/m of N" << std::setw(36)
       << "null FDR (Wilson 95 %)" << "\n";
    auto line = [&](const std::string& name, const SparseThresholdSummary& m) {
      const auto [lo, hi] = wilson_interval(m.null_false, m.null_n);
      std::ostringstream e, f;
      e << m.named << "/" << m.confounded << "/" << m.mistaken << " of " << m.effect_n;
      f << m.null_false << "/" << m.null_n << " = " << std::fixed << std::setprecision(1)
        << 100.0 * m.null_false / std::max(1, m.null_n) << " % (" << 100 * lo << "-" << 100 * hi << ")";
      os << std::left << std::setw(22) << name << std::right << std::setw(26) << e.str() << std::setw(36) << f.str() << "\n";
    };
    for (std::size_t t = 0; t < r.sparse_summary.size(); ++t)
      line(num(r.sparse_summary[t].threshold) + (static_cast<int>(t) == r.sparse_best ? " (best)" : ""), r.sparse_summary[t]);
    line("BIC per recording", r.sparse_bic_summary);
  }
  // Under mpirun the threads are each rank's: "on 2 threads" hid the other ranks (session 23's notes).
  os << "\n" << std::fixed << std::setprecision(1) << r.seconds << " s on " << r.threads << (r.threads == 1 ? " thread" : " threads")
     << (r.ranks > 1 ? " on each of " + std::to_string(r.ranks) + " MPI ranks\n" : std::string("\n")) << std::defaultfloat;
  return os.str();
}

}  // namespace rollsim
