#!/usr/bin/env python3
"""Writes cycles/nedc.csv: the NEDC at 1 Hz, linearly interpolated from its breakpoint table.

The table is UNECE R83 / R101 Annex 4a (Directive 70/220/EEC Annex III): the elementary urban cycle
(ECE-15, 195 s) run four times, then the extra-urban cycle (EUDC, 400 s). Each tuple is (time s, km/h) at
the start/end of an operation; see cycles/SOURCES.md for the operation list and its source.
Run from the repository root: python3 scripts/make_nedc.py
"""
from fractions import Fraction

ECE15 = [(0, 0), (11, 0), (15, 15), (23, 15), (25, 10), (28, 0), (49, 0), (54, 15), (56, 15), (61, 32),
         (85, 32), (93, 10), (96, 0), (117, 0), (122, 15), (124, 15), (133, 35), (135, 35), (143, 50),
         (155, 50), (163, 35), (176, 35), (178, 35), (185, 10), (188, 0), (195, 0)]
EUDC = [(0, 0), (20, 0), (25, 15), (27, 15), (36, 35), (38, 35), (46, 50), (48, 50), (61, 70), (111, 70),
        (119, 50), (188, 50), (201, 70), (251, 70), (286, 100), (316, 100), (336, 120), (346, 120),
        (362, 80), (370, 50), (380, 0), (400, 0)]

points = []
for k in range(4):
    points += [(t + 195 * k, v) for t, v in ECE15 if not (points and t == 0)]
points += [(t + 780, v) for t, v in EUDC if t > 0]
assert points[-1][0] == 1180

def speed(t):
    for (t0, v0), (t1, v1) in zip(points, points[1:]):
        if t0 <= t <= t1:
            return Fraction(v0) + Fraction(v1 - v0, t1 - t0) * (t - t0)
    raise ValueError(t)

with open("cycles/nedc.csv", "w") as f:
    f.write("time_s,speed_kmh\n")
    for t in range(0, 1181):
        v = speed(t)
        text = f"{float(v):.10f}".rstrip("0").rstrip(".")
        f.write(f"{t},{text}\n")
