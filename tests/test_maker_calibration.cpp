// The maker calibration against samples whose truth is written here: makes with known offsets, makes without.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <random>
#include <string>
#include <vector>

#include "rollsim/validate/maker_calibration.hpp"

using namespace rollsim;
using validate::CalibrationSample;
using validate::EpaCycle;
using validate::EpaFuel;
using validate::MakerCalibration;

namespace {

// Uniform in [-1, 1) from the raw 32-bit stream of mt19937, which the standard fixes bit for bit.
struct Noise {
  std::mt19937 engine{20261125u};
  double operator()() { return 2.0 * static_cast<double>(engine()) / 4294967296.0 - 1.0; }
};

// `makes` makes, each `models` models of `rows` rows on the FTP-75: a make's log error is its offset plus a model's
// own scatter plus a row's.
std::vector<CalibrationSample> samples(const std::vector<double>& offsets, int models, int rows, double model_scatter,
                                       double row_scatter, Noise& noise) {
  std::vector<CalibrationSample> out;
  for (std::size_t m = 0; m < offsets.size(); ++m) {
    for (int j = 0; j < models; ++j) {
      const double model_error = model_scatter * noise();
      for (int r = 0; r < rows; ++r) {
        out.push_back({EpaFuel::petrol, EpaCycle::ftp75, "Make" + std::to_string(m), "Model " + std::to_string(j),
                       offsets[m] + model_error + row_scatter * noise()});
      }
    }
  }
  return out;
}

}  // namespace

TEST(MakerCalibration, LearnsEachMakesOffsetAndCalibratesANewModelOfIt) {
  Noise noise;
  const std::vector<double> offsets = {0.10, -0.08, 0.05, -0.04, 0.0, 0.12};
  const auto fitting = samples(offsets, 6, 3, 0.02, 0.02, noise);
  const auto c = MakerCalibration::fit(fitting);
  const auto& choice = c.choices().at(EpaFuel::petrol);
  ASSERT_TRUE(std::isfinite(choice.shrinkage_rows));
  EXPECT_LT(choice.mean_abs_log_error_calibrated, 0.5 * choice.mean_abs_log_error_uncalibrated);
  EXPECT_EQ(choice.groups, offsets.size());
  EXPECT_EQ(choice.rows, fitting.size());
  for (std::size_t m = 0; m < offsets.size(); ++m) {
    // A model the fit never saw: the factor divides out the make's offset to within the models' scatter.
    const double f = c.factor(EpaFuel::petrol, EpaCycle::ftp75, "MAKE" + std::to_string(m));
    EXPECT_NEAR(std::log(f), -offsets[m], 0.02) << m;
  }
  // What the fitting half does not hold is left alone: another make, cycle or energy source.
  EXPECT_EQ(c.factor(EpaFuel::petrol, EpaCycle::ftp75, "Another make"), 1.0);
  EXPECT_EQ(c.factor(EpaFuel::petrol, EpaCycle::hwfet, "Make0"), 1.0);
  EXPECT_EQ(c.factor(EpaFuel::electricity, EpaCycle::ftp75, "Make0"), 1.0);
}

TEST(MakerCalibration, WhereMakesDoNotDifferItCorrectsLittle) {
  // Every make at the same level: what is left is the models' and the rows' scatter (5 % and 1 %), which a make's
  // other models cannot predict. Ten draws, as a choice by the best score can find a pattern in one: at this
  // commit eight choose no calibration and two a shrinkage of 20 rows that gains 2.7-2.8 % (the list's petrol
  // rows gain 5.8 %, its electric rows 39 %).
  for (std::uint32_t seed = 1; seed <= 10; ++seed) {
    Noise noise;
    noise.engine.seed(seed);
    const auto fitting = samples(std::vector<double>(20, 0.0), 5, 3, 0.05, 0.01, noise);
    const auto c = MakerCalibration::fit(fitting);
    const auto& choice = c.choices().at(EpaFuel::petrol);
    EXPECT_LE(choice.mean_abs_log_error_calibrated, choice.mean_abs_log_error_uncalibrated);
    EXPECT_GT(choice.mean_abs_log_error_calibrated, 0.97 * choice.mean_abs_log_error_uncalibrated) << seed;
    for (int m = 0; m < 20; ++m) EXPECT_LT(std::abs(std::log(c.factor(EpaFuel::petrol, EpaCycle::ftp75, "Make" + std::to_string(m)))), 0.03);
  }
}

TEST(MakerCalibration, AFittingRowIsCalibratedWithoutItsOwnModel) {
  // One make with two models far apart: each is calibrated from the other only, so neither gets its own level.
  std::vector<CalibrationSample> fitting = {
      {EpaFuel::electricity, EpaCycle::cd_udds, "Audi", "e-tron S", 0.30},
      {EpaFuel::electricity, EpaCycle::cd_udds, "Audi", "e-tron S", 0.34},
      {EpaFuel::electricity, EpaCycle::cd_udds, "Audi", "Q4 e-tron", 0.10},
      {EpaFuel::electricity, EpaCycle::cd_udds, "Tesla", "Model 3", -0.05},
      {EpaFuel::electricity, EpaCycle::cd_udds, "Tesla", "Model Y", -0.07},
  };
  const auto c = MakerCalibration::fit(fitting);
  ASSERT_EQ(c.choices().at(EpaFuel::electricity).shrinkage_rows, 0.0);  // unshrunk does best on these five
  EXPECT_NEAR(c.factor(EpaFuel::electricity, EpaCycle::cd_udds, "Audi", "e-tron S"), std::exp(-0.10), 1e-12);
  EXPECT_NEAR(c.factor(EpaFuel::electricity, EpaCycle::cd_udds, "audi", "Q4 E-TRON"), std::exp(-0.32), 1e-12);
  EXPECT_NEAR(c.factor(EpaFuel::electricity, EpaCycle::cd_udds, "Tesla", "Model 3"), std::exp(0.07), 1e-12);
  // A new model of the make is calibrated from all of them.
  EXPECT_NEAR(c.factor(EpaFuel::electricity, EpaCycle::cd_udds, "Audi"), std::exp(-0.30), 1e-12);
  EXPECT_NEAR(c.factor(EpaFuel::electricity, EpaCycle::cd_udds, "Tesla"), std::exp(0.06), 1e-12);
}

TEST(MakerCalibration, WithOneModelPerMakeThereIsNothingToLearnAndNoCalibration) {
  const std::vector<CalibrationSample> fitting = {
      {EpaFuel::e85, EpaCycle::ftp75, "Ford", "F150", 0.11},
      {EpaFuel::e85, EpaCycle::hwfet, "Ford", "F150", 0.01},
  };
  const auto c = MakerCalibration::fit(fitting);
  const auto& choice = c.choices().at(EpaFuel::e85);
  EXPECT_TRUE(std::isinf(choice.shrinkage_rows));
  EXPECT_EQ(choice.mean_abs_log_error_calibrated, choice.mean_abs_log_error_uncalibrated);
  EXPECT_EQ(c.factor(EpaFuel::e85, EpaCycle::ftp75, "Ford"), 1.0);
  EXPECT_EQ(c.factor(EpaFuel::e85, EpaCycle::ftp75, "Ford", "F150"), 1.0);
}

TEST(MakerCalibration, AModelTheListLeavesBlankIsLeftOutLikeAnyOther) {
  // The list may leave a model's name empty; those rows are one model (as the split treats them), so a fitting row
  // of it is calibrated from the make's other models only, not from its own rows.
  const std::vector<CalibrationSample> fitting = {
      {EpaFuel::petrol, EpaCycle::hwfet, "X", "", 0.20},  {EpaFuel::petrol, EpaCycle::hwfet, "X", "", 0.21},
      {EpaFuel::petrol, EpaCycle::hwfet, "X", "A", 0.19}, {EpaFuel::petrol, EpaCycle::hwfet, "X", "A", 0.20},
      {EpaFuel::petrol, EpaCycle::hwfet, "Y", "B", -0.10}, {EpaFuel::petrol, EpaCycle::hwfet, "Y", "C", -0.11},
  };
  const auto c = MakerCalibration::fit(fitting);
  ASSERT_EQ(c.choices().at(EpaFuel::petrol).shrinkage_rows, 0.0);
  EXPECT_NEAR(c.factor(EpaFuel::petrol, EpaCycle::hwfet, "X", std::string()), std::exp(-0.195), 1e-12);
  EXPECT_NEAR(c.factor(EpaFuel::petrol, EpaCycle::hwfet, "X", std::string("A")), std::exp(-0.205), 1e-12);
  EXPECT_NEAR(c.factor(EpaFuel::petrol, EpaCycle::hwfet, "X"), std::exp(-0.20), 1e-12);
}

TEST(MakerCalibration, ABlankMakeOrANonFiniteErrorTeachesNothing) {
  // Rows the list gives no make are not one maker's cars, so they share no factor; an error that is not a number
  // (a prediction that failed without being caught) must not reach a median.
  const std::vector<CalibrationSample> fitting = {
      {EpaFuel::petrol, EpaCycle::us06, "", "A", 0.20},  {EpaFuel::petrol, EpaCycle::us06, "", "B", 0.21},
      {EpaFuel::petrol, EpaCycle::us06, "Z", "C", 0.10}, {EpaFuel::petrol, EpaCycle::us06, "Z", "D", 0.11},
      {EpaFuel::petrol, EpaCycle::us06, "Z", "E", std::nan("")},
  };
  const auto c = MakerCalibration::fit(fitting);
  const auto& choice = c.choices().at(EpaFuel::petrol);
  EXPECT_EQ(choice.rows, 2u);
  EXPECT_EQ(choice.groups, 1u);
  EXPECT_EQ(c.factor(EpaFuel::petrol, EpaCycle::us06, ""), 1.0);
  EXPECT_EQ(c.factor(EpaFuel::petrol, EpaCycle::us06, "  "), 1.0);
  EXPECT_TRUE(std::isfinite(c.factor(EpaFuel::petrol, EpaCycle::us06, "Z")));
  EXPECT_NEAR(c.factor(EpaFuel::petrol, EpaCycle::us06, "Z"), std::exp(-0.105), 1e-12);
}
