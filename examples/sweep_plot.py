#!/usr/bin/env python3
"""Plots a tyre sweep with the rollsim Python API and matplotlib: RRC against inflation pressure at three speeds,
and the electric car's NEDC energy with that tyre on all four wheels.

    PYTHONPATH=build/python python3 examples/sweep_plot.py sweep_plot.png
"""
import sys

import matplotlib

matplotlib.use("Agg")  # files only, no display needed
import matplotlib.pyplot as plt

import rollsim


def main(out_png):
    tyre = "175-70R14"
    points = rollsim.sweep(tyre, [("pressure", 1.6, 3.2, 17), ("speed", 50, 130, 3)], load_n=3500)
    car = rollsim.sweep(tyre, [("pressure", 1.6, 3.2, 9)], vehicle="ev", cycle="nedc")

    fig, (left, right) = plt.subplots(1, 2, figsize=(10, 4), constrained_layout=True)
    for speed in sorted({p["speed_kmh"] for p in points}):
        line = [p for p in points if p["speed_kmh"] == speed]
        left.plot([p["pressure_bar"] for p in line], [1e3 * p["rrc"] for p in line], marker="o", ms=3,
                  label=f"{speed:g} km/h")
    left.set(xlabel="inflation pressure [bar]", ylabel="RRC x 1000 [-]", title=f"{tyre} at 3500 N")
    left.grid(True)
    left.legend()
    right.plot([p["pressure_bar"] for p in car], [p["kwh_per_10km"] for p in car], marker="o")
    right.set(xlabel="inflation pressure [bar]", ylabel="energy [kWh/10 km]", title=f"ev.yaml on NEDC, 4 x {tyre}")
    right.grid(True)
    fig.savefig(out_png, dpi=100)
    print(f"wrote {out_png}: {len(points)} tyre points, {len(car)} car simulations")


if __name__ == "__main__":
    main(sys.argv[1] if len(sys.argv) > 1 else "sweep_plot.png")
