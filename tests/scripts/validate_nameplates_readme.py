#!/usr/bin/env python3
"""The README's `scripts/validate-nameplates v.json` output is what the script prints on this build's validate --json.

Usage: validate_nameplates_readme.py ROLLSIM SOURCE_DIR"""
import os
import re
import subprocess
import sys
import tempfile

rollsim, source = sys.argv[1], sys.argv[2]
with open(os.path.join(source, "README.md"), encoding="utf-8") as f:
    lines = f.read().split("\n")
at = next(i for i, l in enumerate(lines) if re.match(r"^\s+\$ scripts/validate-nameplates v\.json", l))
indent = len(lines[at]) - len(lines[at].lstrip())
expected = []
for l in lines[at + 1:]:
    if not l.startswith(" " * indent) or l.strip().startswith("$") or not l.strip():
        break
    expected.append(l[indent:].rstrip())
assert expected, "no output lines under the README's validate-nameplates example"
with tempfile.TemporaryDirectory() as d:
    v = os.path.join(d, "v.json")
    with open(v, "w") as out:
        subprocess.run([rollsim, "validate", "--epa-test-car-list", "../shared/data/vehicles/epa_test_car_list_2022_part.csv",
                        "--threads", "2", "--json"], cwd=source, stdout=out, check=True)
    printed = subprocess.run([sys.executable, os.path.join(source, "scripts", "validate-nameplates"), v],
                             capture_output=True, text=True, check=True).stdout.split("\n")
printed = {l.rstrip() for l in printed}
missing = [l for l in expected if l not in printed]
if missing:
    sys.exit("README lines validate-nameplates does not print:\n" + "\n".join(missing))
print(f"validate-nameplates: the README's {len(expected)} lines are what it prints")
