"""rollsim.engine_map against the map's analytic limits, derived here from the mean-effective-pressure balance.

The balance (EngineMap, after Heywood ch. 13): gross imep = bmep + fmep + pumping, pumping falling linearly from
pc at closed throttle to 0 at the unthrottled imep a, so while throttled imep = (bmep + fmep + pc) / (1 + pc / a);
fuel power = imep V_d w / (4 pi) / eta, and bmep V_d w / (4 pi) = torque x w. The keys are converted to SI here
by hand (l, bar, krpm, %), so a slip in the reader's conversions shows. No fuel map is needed.
Run by ctest (Python.Api) with PYTHONPATH=build/python.
"""
import math
import warnings
import unittest
from pathlib import Path

import numpy as np

import rollsim

# A petrol engine in the vehicle file's units, with every friction term non-zero so each conversion is exercised.
ENGINE = {
    "displacement_l": 2.0, "gross_indicated_efficiency": 0.42, "friction_mep_bar": 0.6,
    "friction_mep_bar_per_krpm": 0.1, "friction_mep_bar_per_krpm2": 0.04, "pumping_mep_closed_throttle_bar": 0.8,
    "unthrottled_imep_bar": 10.0, "knock_start_load_pct": 80, "knock_efficiency_loss_at_full_load_pct": 10,
    "enrichment_start_load_pct": 90, "enrichment_at_full_load_pct": 20, "idle_speed_rpm": 750,
    "idle_torque_reserve_nm": 8, "rated_speed_rpm": 6000, "max_speed_rpm": 6500, "max_torque_nm": 200,
    "max_power_kw": 110,
}
VD_M3, ETA, PC_PA, A_PA = 2.0e-3, 0.42, 0.8e5, 10.0e5


def radps(rpm):
    return rpm * 2.0 * math.pi / 60.0


def fmep_pa(rpm):
    k = rpm / 1000.0
    return (0.6 + 0.1 * k + 0.04 * k * k) * 1e5


class EngineMapLimits(unittest.TestCase):
    def test_zero_torque_burns_friction_and_pumping_at_the_throttled_imep(self):
        # torque 0: imep = fmep + pc (1 - imep / a), so imep = (fmep + pc) / (1 + pc / a).
        rpm = np.array([1000.0, 2000.0, 3500.0, 5000.0, 6000.0])
        got = rollsim.engine_map(ENGINE, rpm, 0.0)["fuel_power_w"]
        expected = (fmep_pa(rpm) + PC_PA) / (1 + PC_PA / A_PA) * VD_M3 * radps(rpm) / (4 * math.pi) / ETA
        np.testing.assert_allclose(got, expected, rtol=1e-12)

    def test_part_load_step_costs_one_over_eta_times_one_plus_pc_over_a(self):
        # Below the knock and enrichment loads and throttled, fuel is linear in brake power with this slope.
        rpm = np.array([1200.0, 2500.0, 4000.0])
        low_nm, high_nm = 20.0, 60.0  # at most 60 / 200 = 30 % load: below 80 % knock, 90 % enrichment
        fuel = rollsim.engine_map(ENGINE, rpm[:, None], np.array([low_nm, high_nm]))["fuel_power_w"]
        slope = (fuel[:, 1] - fuel[:, 0]) / ((high_nm - low_nm) * radps(rpm))
        np.testing.assert_allclose(slope, 1.0 / (ETA * (1 + PC_PA / A_PA)), rtol=1e-10)

    def test_full_load_is_unthrottled_knock_limited_and_rich(self):
        # 3000 rpm is the knee (half rated speed): full load is the plateau, bmep 12.6 bar > a, so no pumping;
        # the efficiency is 10 % down and the mixture 20 % rich.
        rpm, torque_nm = 3000.0, 200.0
        got = rollsim.engine_map(ENGINE, rpm, torque_nm)
        self.assertAlmostEqual(got["max_torque_nm"], 200.0, delta=1e-12)
        w = radps(rpm)
        expected = (torque_nm * w + fmep_pa(rpm) * VD_M3 * w / (4 * math.pi)) / ETA * 1.2 / (1 - 0.1)
        self.assertAlmostEqual(got["fuel_power_w"] / expected, 1.0, delta=1e-12)

    def test_full_load_curve_plateau_power_limit_and_idle(self):
        rpm = np.array([750.0, 3000.0, 5000.0, 6000.0, 6600.0])
        got = rollsim.engine_map(ENGINE, rpm, 0.0)["max_torque_nm"]
        # idle: 70 % of the plateau; knee: the plateau; above 110 kW / 200 N m = 5252 rpm: rated power; past the
        # rev limit: nothing.
        expected = [0.7 * 200.0, 200.0, min(200.0, 110e3 / radps(5000.0)), 110e3 / radps(6000.0), 0.0]
        np.testing.assert_allclose(got, expected, rtol=1e-12)

    def test_idle_burns_the_torque_reserve(self):
        # At idle speed the controller's 8 N m reserve is burnt on top of the load: the same fuel as 8 N m more.
        at_idle = rollsim.engine_map(ENGINE, 750.0, 10.0)["fuel_power_w"]
        slope = 1.0 / (ETA * (1 + PC_PA / A_PA))
        no_load = (fmep_pa(750.0) + PC_PA) / (1 + PC_PA / A_PA) * VD_M3 * radps(750.0) / (4 * math.pi) / ETA
        self.assertAlmostEqual(at_idle / (no_load + slope * 18.0 * radps(750.0)), 1.0, delta=1e-12)

    def test_scalars_give_floats_and_arrays_broadcast(self):
        self.assertIsInstance(rollsim.engine_map(ENGINE, 2000, 50)["fuel_power_w"], float)
        with warnings.catch_warnings():  # the grid's corner at 1000 rpm, 150 N m is beyond full load
            warnings.simplefilter("ignore", UserWarning)
            grid = rollsim.engine_map(ENGINE, np.linspace(1000, 5000, 5)[:, None], np.linspace(10, 150, 8))
        self.assertEqual(grid["fuel_power_w"].shape, (5, 8))
        self.assertTrue(np.all(np.diff(grid["fuel_power_w"], axis=1) > 0))  # more torque, more fuel

    def test_shipped_camry_block_reads(self):
        import yaml  # the file's own block, as the vehicle reader takes it
        with open(Path(__file__).resolve().parents[2] / "vehicles" / "camry_2018_map.yaml") as f:
            engine = yaml.safe_load(f)["powertrain"]["engine"]
        got = rollsim.engine_map(engine, 4000.0, 0.0)
        self.assertAlmostEqual(got["max_torque_nm"], min(250.0, 151e3 / radps(4000.0)), delta=1e-12)

    def test_bad_keys_and_values_raise_the_readers_named_error(self):
        cases = [({**ENGINE, "friction_mep_bar": -1}, "friction_mep_bar"),
                 ({**ENGINE, "inertia_kgm2": 0.1}, "inertia_kgm2"),
                 ({k: v for k, v in ENGINE.items() if k != "max_power_kw"}, "max_power_kw"),
                 ({**ENGINE, "knock_start_load_pct": 100}, "knock_start_load_pct")]
        for engine, key in cases:
            with self.assertRaisesRegex(rollsim.InputError, key):
                rollsim.engine_map(engine, 2000.0, 50.0)
        with self.assertRaisesRegex(rollsim.InputError, "speed_rpm"):
            rollsim.engine_map(ENGINE, [2000.0, -1.0], 50.0)
        with self.assertRaisesRegex(rollsim.InputError, "torque_nm"):
            rollsim.engine_map(ENGINE, 2000.0, float("nan"))
        # Beyond full load there is no operating point (session 20: a figure was returned for 10 kN m without a word):
        # a warning; at full load none.
        full = rollsim.engine_map(ENGINE, 3000.0, 0.0)["max_torque_nm"]
        with self.assertWarnsRegex(UserWarning, "1 point\\(s\\) beyond the engine's full-load torque"):
            rollsim.engine_map(ENGINE, 3000.0, 10000.0)
        with warnings.catch_warnings():
            warnings.simplefilter("error", UserWarning)
            self.assertGreater(rollsim.engine_map(ENGINE, 3000.0, full)["fuel_power_w"], 0.0)


if __name__ == "__main__":
    unittest.main()
