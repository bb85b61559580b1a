// `rollsim diagnose-bench`: blind diagnosis of synthetic recordings with a concealed tyre warm-up, and null cases.
#include <cmath>
#include <iomanip>
#include <iostream>
#include <sstream>
#include <memory>
#include <string>

#include "commands.hpp"
#include "rollsim/common/yaml_reader.hpp"
#include "rollsim/diagnose/diagnose.hpp"

namespace rollsim::cli {
namespace {

struct BenchOptions {
  std::string vehicle = "ev";
  int seeds = 20;
};

// Wilson score interval (95 %) for k successes in n trials: honest at rates near 0.
std::pair<double, double> wilson(int k, int n) {
  if (n == 0) return {0.0, 1.0};
  const double z = 1.96, p = static_cast<double>(k) / n, z2n = z * z / n;
  const double c = (p + z2n / 2) / (1 + z2n), h = z * std::sqrt(p * (1 - p) / n + z2n / (4.0 * n)) / (1 + z2n);
  return {std::max(0.0, c - h), std::min(1.0, c + h)};
}

void run_bench(const BenchOptions& o) {
  const Vehicle v = load_vehicle_file(resolve_data_file(o.vehicle, "vehicles", ".yaml", "--vehicle"));
  std::cout << "truth: two-node tyre thermal model (not the catalogue's), WLTC x 2, noise 400 W, 100 W quantum, 1 s lag,\n"
               "RRC level +-3 %, channel scale +-2 %; " << o.seeds << " seeds per case\n\n";
  std::cout << std::left << std::setw(34) << "case" << std::right << std::setw(8) << "named" << std::setw(12) << "confounded"
            << std::setw(8) << "missed" << std::setw(10) << "mistaken" << "\n";
  for (double size : {0.05, 0.1, 0.2, 0.3}) {
    int named = 0, conf = 0, missed = 0, wrong = 0;
    for (int s = 1; s <= o.seeds; ++s) {
      SyntheticOptions so;
      so.tyre_cold_excess = size;
      so.seed = static_cast<unsigned>(1000 + s);
      const Diagnosis d = diagnose(v, {generate_recording(v, so)});
      if (d.findings.empty()) {
        ++missed;
        continue;
      }
      const auto& f = d.findings.front();
      bool in_conf = false;
      for (const auto& c : f.confounded_with) in_conf = in_conf || c == "tyre_warmup";
      if (f.effect == "tyre_warmup" && f.confounded_with.empty()) ++named;
      else if (f.effect == "tyre_warmup" || in_conf) ++conf;
      else ++wrong;
    }
    std::ostringstream name;
    name << "tyre_warmup cold excess " << size * 100 << " %";
    std::cout << std::left << std::setw(34) << name.str() << std::right << std::setw(8) << named << std::setw(12) << conf
              << std::setw(8) << missed << std::setw(10) << wrong << "\n";
  }
  for (bool reversed : {false, true}) {
    int discoveries = 0;
    for (int s = 1; s <= o.seeds; ++s) {
      SyntheticOptions so;
      so.seed = static_cast<unsigned>(5000 + s);
      if (reversed) {
        so.tyre_cold_excess = 0.3;
        so.time_reversed = true;
      }
      const Diagnosis d = diagnose(v, {generate_recording(v, so)});
      // For the reversed case only a warm-up with a positive cold excess is a false discovery of warm-up.
      bool bad = !d.findings.empty();
      if (reversed) {
        bad = false;
        for (const auto& f : d.findings)
          if (f.effect == "tyre_warmup" && f.parameters.front().value > 0.0) bad = true;
      }
      discoveries += bad ? 1 : 0;
    }
    const auto [lo, hi] = wilson(discoveries, o.seeds);
    std::cout << (reversed ? "time-reversed decay: called warm-up " : "null: false discoveries ") << discoveries << "/" << o.seeds
              << " (" << std::fixed << std::setprecision(1) << 100.0 * discoveries / o.seeds << " %, 95 % CI " << 100 * lo << "-"
              << 100 * hi << " %)\n" << std::defaultfloat;
  }
}

}  // namespace

void register_diagnose_bench_command(CLI::App& app) {
  auto o = std::make_shared<BenchOptions>();
  CLI::App* sub = app.add_subcommand("diagnose-bench", "Scorecard of rollsim diagnose on synthetic recordings with a concealed effect");
  sub->add_option("--vehicle", o->vehicle, "Vehicle YAML (electric; default ev)")->type_name("FILE");
  sub->add_option("--seeds", o->seeds, "Seeds per case (default 20)")->check(CLI::Range(1, 1000));
  sub->callback([o] { run_bench(*o); });
}

}  // namespace rollsim::cli
