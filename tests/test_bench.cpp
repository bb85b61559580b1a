// Discovery benchmark, CI subset: the null's false-discovery rate, the warm-up's detection, the time-reversed null.
#include <gtest/gtest.h>

#include "rollsim/common/error.hpp"
#include "rollsim/discovery/scorecard.hpp"

namespace rollsim {
namespace {

TEST(Bench, QuickSubsetMeetsTheIssuesBars) {
  // Thresholds are the issue's (false discoveries at most 5 %) and the brief's (warm-up at 30 % named or confounded
  // in at least 80 % of seeds), fixed before running.
  const Vehicle v = load_vehicle_file(std::string(ROLLSIM_SOURCE_DIR) + "/vehicles/ev.yaml");
  BenchOptions o;
  o.quick = true;
  o.seeds = 20;
  o.null_seeds = 60;
  const BenchResult r = run_discovery_bench(v, o);
  bool saw_null = false, saw_reversed = false, saw_warmup = false, saw_ambient = false, saw_trip_null = false;
  bool saw_real_logger_null = false;
  for (const auto& row : r.rows) {
    if (row.group == "null") {
      saw_null = true;
      saw_trip_null = saw_trip_null || row.label.find("4 trips") != std::string::npos;
      saw_real_logger_null = saw_real_logger_null || row.label.find("real logger") != std::string::npos;
      EXPECT_LE(row.rollsim.mistaken, 0.05 * row.rollsim.n()) << bench_text(r);
    } else if (row.group == "reversed") {
      saw_reversed = true;
      EXPECT_LE(row.rollsim.mistaken, 0.05 * row.rollsim.n()) << bench_text(r);
    } else if (row.group == "single" && row.expected == std::vector<std::string>{"tyre_warmup"}) {
      saw_warmup = true;
      EXPECT_GE(row.rollsim.named + row.rollsim.confounded, 0.8 * row.rollsim.n()) << bench_text(r);
    } else if (row.group == "trips") {
      // Ambient RRC at 0.008 /K (the UN R117 correction's size) over four trips: named or confounded in >= 80 %.
      saw_ambient = true;
      EXPECT_EQ(row.expected, std::vector<std::string>{"ambient_rrc"});
      EXPECT_GE(row.rollsim.named + row.rollsim.confounded, 0.8 * row.rollsim.n()) << bench_text(r);
    }
  }
  EXPECT_TRUE(saw_null && saw_reversed && saw_warmup && saw_ambient && saw_trip_null && saw_real_logger_null);
  // The sparse baseline was scored at every threshold of its sweep, and its best is one of them.
  ASSERT_EQ(r.sparse_summary.size(), sparse_thresholds().size());
  EXPECT_GE(r.sparse_best, 0);
  EXPECT_LT(r.sparse_best, static_cast<int>(sparse_thresholds().size()));
}

// Issue 9's bar: an RRC rising over the trip (a null for warm-up) is never called tyre_warmup, of either sign. The
// engine before the pipeline called it a warm-up with a negative cold excess in 19 of 20 seeds (docs/diagnose.md).
TEST(Bench, RisingRrcIsNeverCalledWarmup) {
  const Vehicle v = load_vehicle_file(std::string(ROLLSIM_SOURCE_DIR) + "/vehicles/ev.yaml");
  BenchOptions o;
  o.seeds = 20;
  o.only = {"rising_rrc 0.2"};
  const BenchResult r = run_discovery_bench(v, o);
  ASSERT_EQ(r.rows.size(), 1u);
  EXPECT_EQ(r.rows.front().rollsim.mistaken, 0) << bench_text(r);
}

TEST(Bench, OnlyKeepsTheRowsAskedFor) {
  BenchOptions o;
  o.seeds = 1;
  o.null_seeds = 1;
  o.only = {"aux_compressor 150 W"};
  const auto kept = run_discovery_bench(load_vehicle_file(std::string(ROLLSIM_SOURCE_DIR) + "/vehicles/ev.yaml"), o).rows;
  ASSERT_EQ(kept.size(), 1u);
  EXPECT_NE(kept[0].label.find("aux_compressor 150 W"), std::string::npos);
  // Text that matches no row is an error naming the option, not an empty scorecard (outside testing, session 16).
  o.only = {"no row has this label"};
  EXPECT_THROW(run_discovery_bench(load_vehicle_file(std::string(ROLLSIM_SOURCE_DIR) + "/vehicles/ev.yaml"), o), InputError);
}

TEST(Bench, WilsonIntervalBracketsTheRate) {
  // 0 of 100: the upper bound is about 3.7 % (z^2 / (n + z^2)); 50 of 100 is symmetric about a half.
  const auto [lo0, hi0] = wilson_interval(0, 100);
  EXPECT_EQ(lo0, 0.0);
  EXPECT_NEAR(hi0, 1.96 * 1.96 / (100 + 1.96 * 1.96), 1e-12);
  const auto [lo, hi] = wilson_interval(50, 100);
  EXPECT_NEAR(lo + hi, 1.0, 1e-12);
}

}  // namespace
}  // namespace rollsim
