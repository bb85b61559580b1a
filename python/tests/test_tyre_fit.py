"""rollsim.tyre_fit: the fitted tyre reproduces the measured points it was given, a label alone lands on its band's
middle at ISO 28580 conditions (both worked out here by hand), the command line gives the same JSON lines for the
same data, and bad input raises the named error without writing a file. Run by ctest (Python.Api)."""
import json
import os
import subprocess
import tempfile
import unittest
from pathlib import Path

import rollsim

ROOT = Path(__file__).resolve().parents[2]
# The binary ctest names (the build being tested); build/rollsim only when run by hand (it compared another build's
# binary with this module when the build folder was elsewhere).
CLI = Path(os.environ.get("ROLLSIM_BINARY", str(ROOT / "build" / "rollsim")))
POINTS = [(210, 4500, 80, 0.0085), (250, 4500, 80, 0.0079), (210, 4500, 40, 0.0080)]


class TyreFit(unittest.TestCase):
    def test_three_points_fit_three_constants_and_the_tyre_reproduces_each_point(self):
        with tempfile.TemporaryDirectory() as d:
            path = os.path.join(d, "t.yaml")
            r = rollsim.tyre_fit("205/55 R16 91V", points=POINTS, output=path)
            free = [p["key"] for p in r["params"] if p["free"]]
            self.assertEqual(sorted(free), ["deflection_exponent", "frequency_slope_per_hz", "rrc_ref"])
            for kpa, load_n, kmh, rrc in POINTS:
                got = rollsim.tyre(path, pressure_bar=kpa / 100.0, load_n=load_n, speed_kmh=kmh)["rrc"]
                self.assertAlmostEqual(got / rrc, 1.0, places=8)  # the file keeps 9 significant digits
            # The returned dict is that file: a car on it uses the same energy as a car on the file.
            on_file = rollsim.simulate("ev", tyre=path, cycle="nedc", replay=True, trace=False)["summary"]
            at_file = rollsim.tyre(path, load_n=4500, speed_kmh=[40, 80, 120])["rrc"]
        self.assertEqual(list(rollsim.tyre(r["tyre"], load_n=4500, speed_kmh=[40, 80, 120])["rrc"]), list(at_file))
        on_dict = rollsim.simulate("ev", tyre=r["tyre"], cycle="nedc", replay=True, trace=False)["summary"]
        self.assertEqual(on_dict["aec_kwh_per_10km"], on_file["aec_kwh_per_10km"])
        self.assertEqual(len(r["residuals"]), 3)

    def test_a_label_alone_is_its_band_middle_at_iso_28580_conditions(self):
        # Class B: 6.6-7.7 kg/t declared to 0.1, so 6.55-7.75 on ISO 28580's 2.0 m drum, geometric middle
        # sqrt(6.55 x 7.75); on a flat road x sqrt(1 / (1 + r)), r = 8 in + 0.55 x 205 mm; load index 91: 615 kg, 80 %.
        with tempfile.TemporaryDirectory() as d:
            path = os.path.join(d, "t.yaml")
            r = rollsim.tyre_fit("205/55 R16 91V", label="B", output=path)
            got = rollsim.tyre(path, pressure_bar=2.1, load_n=0.8 * 615 * 9.80665, speed_kmh=80)["rrc"]
        flat = (6.55e-3 * 7.75e-3) ** 0.5 * (1.0 / (1.0 + 8 * 0.0254 + 0.55 * 0.205)) ** 0.5
        self.assertAlmostEqual(got / flat, 1.0, places=8)  # the file keeps 9 significant digits
        self.assertAlmostEqual(r["fit"]["iso_rrc_kg_per_t"], (6.55 * 7.75) ** 0.5, places=6)
        self.assertTrue(r["fit"]["inside_label_band"])

    def test_the_command_line_prints_the_same_json_lines(self):
        with tempfile.TemporaryDirectory() as d:
            args = [str(CLI), "tyre", "fit", "--size", "205/55 R16 91V", "--label", "B", "--json",
                    "--output", os.path.join(d, "t.yaml")]
            for p in POINTS:
                args += ["--point", ",".join(str(x) for x in p)]
            lines = subprocess.run(args, capture_output=True, text=True, check=True).stdout.splitlines()
        cli = [json.loads(l) for l in lines]
        r = rollsim.tyre_fit("205/55 R16 91V", points=POINTS, label="B")
        self.assertEqual(cli[0], r["fit"])
        self.assertEqual([c for c in cli if c["kind"] == "param"], r["params"])
        # The residuals name their source as each front end does (--point ... or points[i]); the numbers agree.
        for c, p in zip([c for c in cli if c["kind"] == "residual"], r["residuals"]):
            self.assertEqual({k: v for k, v in c.items() if k != "where"}, {k: v for k, v in p.items() if k != "where"})

    def test_bad_input_raises_the_named_error_and_writes_nothing(self):
        with tempfile.TemporaryDirectory() as d:
            out = os.path.join(d, "t.yaml")
            cases = [(dict(points=["x"]), "points[0]"), (dict(points=[(0, 4000, 80, 0.009)]), "pressure 0 kPa"),
                     (dict(points=[0.5]), "RRC 0.5"), (dict(label="F"), "label"),
                     (dict(points=[0.009], free=["bogus"]), "bogus"), (dict(points=[0.009], pressure_bar=0), "pressure_bar"),
                     (dict(j2452=(-0.4, 0.9, 0.1)), "ALPHA,BETA,A,B,C"), (dict(), "too few points"),
                     (dict(label=2), "label"), (dict(j2452="x"), "j2452"), (dict(points=[0.009], free="rrc_ref"), "free"),
                     (dict(points=[0.009], pressure_bar="2"), "pressure_bar")]
            for kwargs, named in cases:
                with self.assertRaises(rollsim.InputError, msg=str(kwargs)) as e:
                    rollsim.tyre_fit("205/55 R16 91V", output=out, **kwargs)
                self.assertIn(named, str(e.exception))
                self.assertFalse(os.path.exists(out), kwargs)
            rollsim.tyre_fit("205/55 R16 91V", points=[0.0072], output=out)
            self.assertTrue(os.path.exists(out))


if __name__ == "__main__":
    unittest.main()
