"""Runs examples/sweep_plot.py (argv[1]) writing argv[2] and checks the PNG is there and not blank (ctest)."""
import os
import subprocess
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.image
import numpy as np

script, png = sys.argv[1], sys.argv[2]
if os.path.exists(png):
    os.remove(png)
subprocess.run([sys.executable, script, png], check=True)
with open(png, "rb") as f:
    assert f.read(8) == b"\x89PNG\r\n\x1a\n", "not a PNG"
size = os.path.getsize(png)
assert size > 20000, f"{png} is only {size} bytes"
pixels = matplotlib.image.imread(png)[:, :, :3]
colours = len(np.unique((pixels * 255).astype(np.uint8).reshape(-1, 3), axis=0))
inked = np.mean(pixels.min(axis=2) < 0.9)  # share of pixels that are not near-white
assert colours > 50 and inked > 0.02, f"{png} looks blank: {colours} colours, {inked:.3f} inked"
print(f"{png}: {size} bytes, {pixels.shape[1]}x{pixels.shape[0]}, {colours} colours, {100 * inked:.1f} % inked")
