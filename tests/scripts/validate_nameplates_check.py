#!/usr/bin/env python3
"""scripts/validate-nameplates against a case whose answers are worked by hand (not its own output pasted back)."""
import json
import math
import os
import subprocess
import sys
import tempfile

script = os.path.join(sys.argv[1], "scripts", "validate-nameplates")


def row(half, model, measured, predicted, factor):
    return {"fuel": "electric", "cycle": "CD UDDS", "half": half, "make": "Maker", "model": model,
            "measured": measured, "predicted": predicted, "error_pct": 100 * (predicted / measured - 1),
            "maker_factor": factor, "maker_calibrated_error_pct": 100 * (factor * predicted / measured - 1)}


# Fitting half: two rows of the nameplate Alpha (ln errors 0.1 each) and one of Beta (0.2). With k = 0 a new model
# gets exp(-median(0.1, 0.1, 0.2)) = exp(-0.1); the held-out "Alpha 2" (predicted 10 % high) is then +(1.1 e^-0.1
# - 1) = -0.47 %. Without Alpha's fitting rows only Beta's 0.2 remains: 1.1 e^-0.2 - 1 = -9.94 %.
e1, e2 = math.exp(0.1), math.exp(0.2)
rows = [row("fitting", "Alpha 1", 100.0, 100.0 * e1, math.exp(-0.2)),
        row("fitting", "Alpha 1", 90.0, 90.0 * e1, math.exp(-0.2)),
        row("fitting", "Beta", 80.0, 80.0 * e2, math.exp(-0.1)),
        row("held-out", "Alpha 2", 120.0, 132.0, math.exp(-0.1))]
with tempfile.TemporaryDirectory() as d:
    path = os.path.join(d, "v.json")
    with open(path, "w") as f:
        f.write("\n".join(json.dumps(r) for r in rows))
    out = subprocess.run([sys.executable, script, path], capture_output=True, text=True, check=True).stdout
line = next(l for l in out.splitlines() if l.startswith("electric CD UDDS"))
cells = line.split()
assert cells[3:5] == ["1", "1"], line                                       # one held-out row, sharing Alpha
assert cells[5:] == ["10.00/", "10.00", "0.47/", "0.47", "9.94/", "9.94"], line
# Fitting half, k = 0: physics mean |ln| (0.1 + 0.1 + 0.2) / 3; each Alpha 1 row without its own model gets Beta's
# 0.2 (|0.1 - 0.2|), Beta gets 0.1 (|0.2 - 0.1|): 0.1; the nameplate is Alpha 1's own model here: 0.1 again.
fitting = next(l for l in out.splitlines() if l.strip().startswith("electric:"))
assert "k = 0;" in fitting and "physics 0.1333" in fitting and "without its own model 0.1000" in fitting \
    and "without its nameplate 0.1000" in fitting, fitting
print("validate-nameplates: hand-worked case reproduced")
