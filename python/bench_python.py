#!/usr/bin/env python3
"""Times `import rollsim` and `rollsim.simulate` on NEDC from Python against the library's Google Benchmarks
(run by hand; medians). From the repository root, after the Release build:

    python3 python/bench_python.py [--repetitions 31]

Library: BM_SimulateForward/NedcEv (the simulate call on a model assembled once) and BM_RunVehicleFiles/NedcEv
(load ev.yaml and the cycle, assemble, simulate, write the --json summary: the work one Python call does).
The loader's floor is loading libstdc++ and yaml-cpp into a fresh interpreter, which a C++ program using the
library pays as well when it starts; import plus one call is compared with that floor plus the same work.
"""
import argparse
import json
import os
import statistics
import subprocess
import sys
import time
from pathlib import Path

root = Path(__file__).resolve().parents[1]
build = root / "build"
sys.path.insert(0, str(build / "python"))


def median_import_s(n):
    """(wall, CPU) of `import rollsim` in a fresh interpreter, timed inside it."""
    code = ("import time; w = time.perf_counter(); c = time.process_time(); import rollsim; "
            "print(time.perf_counter() - w, time.process_time() - c)")
    env = {**os.environ, "PYTHONPATH": str(build / "python")}
    runs = [tuple(map(float, subprocess.run([sys.executable, "-c", code], check=True, env=env, capture_output=True,
                                            text=True).stdout.split())) for _ in range(n)]
    return statistics.median(r[0] for r in runs), statistics.median(r[1] for r in runs)


def median_loader_floor_s(n):
    """(wall, CPU) of loading the shared libraries the module needs (libstdc++, yaml-cpp) in a fresh interpreter:
    what any C++ extension that reads YAML pays before its own code runs."""
    code = ("import ctypes, time; ctypes.CDLL('libz.so.1'); w = time.perf_counter(); c = time.process_time(); "
            "ctypes.CDLL('libstdc++.so.6'); ctypes.CDLL('libyaml-cpp.so.0.7'); "
            "print(time.perf_counter() - w, time.process_time() - c)")
    runs = [tuple(map(float, subprocess.run([sys.executable, "-c", code], check=True, capture_output=True,
                                            text=True).stdout.split())) for _ in range(n)]
    return statistics.median(r[0] for r in runs), statistics.median(r[1] for r in runs)


def median_call_s(n, **kwargs):
    """(wall, CPU) medians of one rollsim.simulate call."""
    import rollsim
    rollsim.simulate(**kwargs)  # warm: the first call imports json and numpy
    wall, cpu = [], []
    for _ in range(n):
        w, c = time.perf_counter(), time.process_time()
        rollsim.simulate(**kwargs)
        wall.append(time.perf_counter() - w)
        cpu.append(time.process_time() - c)
    return statistics.median(wall), statistics.median(cpu)


def library_medians_s(reps):
    """{benchmark: (wall, CPU)} medians from rollsim_bench."""
    out = subprocess.run([str(build / "rollsim_bench"), "--benchmark_filter=BM_SimulateForward/NedcEv|BM_RunVehicleFiles/NedcEv",
                          f"--benchmark_repetitions={reps}", "--benchmark_report_aggregates_only=true",
                          "--benchmark_format=json"], check=True, capture_output=True, text=True).stdout
    scale = {"ns": 1e-9, "us": 1e-6, "ms": 1e-3, "s": 1.0}
    return {b["run_name"]: (b["real_time"] * scale[b["time_unit"]], b["cpu_time"] * scale[b["time_unit"]])
            for b in json.loads(out)["benchmarks"] if b.get("aggregate_name") == "median"}


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--repetitions", type=int, default=31)
    n = ap.parse_args().repetitions
    lib = library_medians_s(9)
    imp = median_import_s(11)
    floor = median_loader_floor_s(11)
    py_no_trace = median_call_s(n, vehicle="ev", cycle="nedc", trace=False)
    py_trace = median_call_s(n, vehicle="ev", cycle="nedc", trace=True)
    sim = lib["BM_SimulateForward/NedcEv"]
    files = lib["BM_RunVehicleFiles/NedcEv"]
    print(f"{'medians, ms':62s} {'wall':>8s} {'CPU':>8s}   CPU ratio")
    def row(label, t, ratio=""):
        print(f"{label:62s} {t[0] * 1e3:8.3f} {t[1] * 1e3:8.3f}   {ratio}")
    row("library BM_SimulateForward/NedcEv (model assembled once)", sim)
    row("library BM_RunVehicleFiles/NedcEv (load files, run, json)", files)
    row("python  import rollsim (fresh interpreter)", imp)
    row("  of which loading libstdc++ and yaml-cpp (the loader's floor)", floor)
    row("python  rollsim.simulate('ev', cycle='nedc', trace=False)", py_no_trace,
        f"{py_no_trace[1] / sim[1]:.2f} x simulate call, {py_no_trace[1] / files[1]:.2f} x same work in C++")
    row("python  rollsim.simulate('ev', cycle='nedc') with the trace", py_trace, f"{py_trace[1] / sim[1]:.2f} x simulate call")
    both = (imp[0] + py_no_trace[0], imp[1] + py_no_trace[1])
    row("python  import + one simulate (trace=False)", both, f"{both[1] / sim[1]:.2f} x simulate call")
    # A C++ program that does the same work pays the loader's floor too, when it starts; Python's own cost is the
    # rest of the import (the module's relocation and registration) and the call's conversions.
    cpp = (floor[0] + files[0], floor[1] + files[1])
    row("C++     loader's floor + the same work (a program that starts)", cpp)
    print(f"import + one simulate from Python against a C++ program doing the same from its start: "
          f"{both[1] / cpp[1]:.2f} x (CPU); the module's own import share: {(imp[1] - floor[1]) * 1e3:.2f} ms")


if __name__ == "__main__":
    main()
