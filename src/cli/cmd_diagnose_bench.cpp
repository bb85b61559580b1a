// `rollsim diagnose-bench`: the discovery scorecard (concealed effects, pairs, two at once, nulls) with baselines.
#include <unistd.h>

#include <iostream>
#include <memory>
#include <string>
#include <vector>

#include "commands.hpp"
#include "rollsim/common/error.hpp"
#include "rollsim/common/yaml_reader.hpp"
#include "rollsim/discovery/scorecard.hpp"
#include "rollsim/diagnose/diagnose.hpp"
#include "rollsim/recording/recording.hpp"

namespace rollsim::cli {
namespace {

struct CliOptions {
  std::string vehicle = "ev";
  // As text, read as every command reads a count (CLI11's own conversion took --threads 0 and 4294967295 and said
  // 'Could not convert' or 'Value abc not in range' for a word: session 22's outside testing).
  std::string seeds, null_seeds, threads;
  std::vector<std::string> real_traces;
  std::string real_trace_preset = "rsk_twizy";
  BenchOptions bench;
};

}  // namespace

void register_diagnose_bench_command(CLI::App& app, const ProcessGroup& group) {
  auto o = std::make_shared<CliOptions>();
  CLI::App* sub = app.add_subcommand("diagnose-bench", "Scorecard of rollsim diagnose on synthetic recordings with concealed effects, beside two baselines");
  sub->add_option("--vehicle", o->vehicle, "Vehicle YAML (electric; default ev)")->type_name("FILE");
  sub->add_option("--seeds", o->seeds, "Seeds per effect case (default 20)")->type_name("N");
  sub->add_option("--null-seeds", o->null_seeds, "Seeds of the null and time-reversed null (default 200); the fuel and SOC channels' nulls and the "
                  "trip-scatter null run a quarter of them, at least 50, and the 4-trip null half, at least 100 (not with --quick)")->type_name("N");
  sub->add_option("--threads", o->threads, "Worker threads (default: every core)")->type_name("N");
  sub->add_flag("--quick", o->bench.quick, "CI subset: warm-up at 30 %, two pairs, the nulls");
  sub->add_option("--real-trace", o->real_traces, "A real recording whose speed trace also carries the null and a "
                  "concealed tyre warm-up (repeatable)")->type_name("CSV");
  sub->add_option("--only", o->bench.only, "Only the rows whose label contains this text (repeatable), e.g. 'real logger'")
      ->type_name("TEXT");
  sub->add_flag("--road-profile,!--no-road-profile", o->bench.infer_road_profile,
                "Diagnose with the road_profile stage on (default) or off, on every row");
  sub->add_option("--real-trace-preset", o->real_trace_preset, "Column preset of the --real-trace files (default rsk_twizy)")
      ->type_name("NAME");
  sub->callback([o, &group] {
    const Vehicle v = load_vehicle_file(resolve_data_file(o->vehicle, "vehicles", ".yaml", "--vehicle"));
    // The rows' concealed effects and their channels (terminal power, SOC) are an electric car's; the fuel-channel
    // rows bring their own petrol car.
    if (!v.is_electric()) {
      throw InputError("--vehicle '" + o->vehicle + "'", "is not electric: the scorecard's rows need an electric car");
    }
    BenchOptions b = o->bench;
    if (!o->seeds.empty()) b.seeds = parse_option_count(o->seeds, "--seeds", Range::closed(1, 1000));
    if (!o->null_seeds.empty()) b.null_seeds = parse_option_count(o->null_seeds, "--null-seeds", Range::closed(1, 5000));
    if (!o->threads.empty()) b.threads = static_cast<unsigned>(parse_option_count(o->threads, "--threads", Range::closed(1, 1024)));
    ColumnMapping mapping = preset_mapping(o->real_trace_preset);
    mapping.how_to_map = "with a --real-trace-preset that names it";
    for (const auto& path : o->real_traces) b.real_traces.push_back(cycle_of_recording(load_recording(path, mapping)));
    b.progress = group.is_root() && isatty(STDERR_FILENO) != 0;
    b.map_cases = group.mapper();
    b.ranks = group.size();
    std::cout << bench_text(run_discovery_bench(v, b));
  });
}

}  // namespace rollsim::cli
