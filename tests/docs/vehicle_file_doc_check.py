#!/usr/bin/env python3
"""ctest Docs.VehicleFileReferenceIsWhatTheReadersRead: docs/vehicle-file.md against the code that reads vehicle files.

Keys are taken from the source, not from a list kept beside it:
- src/vehicle/*.cpp and src/diagnose/calibration.cpp: every string literal passed as the key to a YamlMap reader
  call (number, number_or, optional_number, numbers, string, string_or, boolean_or, map, optional_map, accept, has,
  ...), also through a helper that takes (YamlMap, key) such as rpm(m, "idle_speed_rpm"); with the Range and the
  literal default each call gives, and the plausibility Range a helper such as for_road_vehicle adds;
- src/effects/catalogue.cpp: each effect's name and each parameter's {name, unit, neutral, nominal, min, max};
- src/recording/recording.cpp: the canonical columns, the keys of recording_columns and recording_scale;
- include/rollsim/diagnose/diagnose.hpp: calibration_priors' defaults (the struct's initialisers).

The doc's keys are the first cells of its tables' rows (one `key` in backticks). Checked both ways:
1. every key the code reads is a row of the doc;
2. every row of the doc is a key the code reads;
3. a row's Default cell holds the code's literal default (or says "required" for a key only ever read as
   required), its Allowed cell every interval the code enforces, and an effect parameter's Unit cell its unit.
With the rollsim binary, each example vehicle file in the doc (a ```yaml block whose first line is `# file: NAME`)
is written to a scratch folder, and each `$ ./build/rollsim ...` line after it is run there: it must succeed and
print every output line the doc shows beneath it.
Usage: vehicle_file_doc_check.py SOURCE_DIR [ROLLSIM]"""
import glob
import os
import re
import shlex
import subprocess
import sys
import tempfile

READ_METHODS = {"number", "number_or", "optional_number", "numbers", "optional_numbers", "string", "string_or",
                "optional_string", "boolean_or", "map", "optional_map", "accept", "has"}
REQUIRED_METHODS = {"number", "numbers", "string", "map"}
NUM = r"[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?"


def literal_number(text):
    text = text.strip()
    return float(text) if re.fullmatch(NUM, text) else None


def args_at(src, open_paren):
    """The top-level arguments of the call whose '(' is at src[open_paren], and the index after its ')'."""
    depth, start, out, i = 0, open_paren + 1, [], open_paren
    in_str = False
    while i < len(src):
        c = src[i]
        if in_str:
            if c == "\\":
                i += 1
            elif c == '"':
                in_str = False
        elif c == '"':
            in_str = True
        elif c in "([{":
            depth += 1
        elif c in ")]}":
            depth -= 1
            if depth == 0:
                out.append(src[start:i].strip())
                return out, i + 1
        elif c == "," and depth == 1:
            out.append(src[start:i].strip())
            start = i + 1
        i += 1
    raise ValueError("unbalanced call")


def string_literal(arg):
    m = re.fullmatch(r'"([A-Za-z0-9_]+)"', arg.strip())
    return m.group(1) if m else None


def interval(range_expr, ranges):
    """(lo, hi, lo_open, hi_open) of a Range expression with literal bounds, or None (a bound read from the file,
    Range{} which allows any number)."""
    e = re.sub(r"\s+", "", range_expr)
    if e in ranges:
        return ranges[e]
    named = {"Range::fraction()": (0.0, 1.0, False, False), "Range::efficiency()": (0.0, 1.0, True, False)}
    if e in named:
        return named[e]
    m = re.fullmatch(r"Range::(closed|open_low)\((.*),(.*)\)", e)
    if m and literal_number(m.group(2)) is not None and literal_number(m.group(3)) is not None:
        return (literal_number(m.group(2)), literal_number(m.group(3)), m.group(1) == "open_low", False)
    return None


class Key:
    def __init__(self):
        self.where = set()       # files that read it
        self.intervals = set()   # intervals the code enforces
        self.defaults = set()    # literal defaults
        self.read_required = False  # read by a call that throws when the key is missing
        self.read_optional = False  # read by a call with a default, or an optional one
        self.unit = None            # an effect parameter's unit

    @property
    def required_only(self):
        return self.read_required and not self.read_optional


def code_keys(source):
    keys = {}

    def key(name, where):
        k = keys.setdefault(name, Key())
        k.where.add(where)
        return k

    files = sorted(glob.glob(os.path.join(source, "src", "vehicle", "*.cpp"))) + \
        [os.path.join(source, "src", "diagnose", "calibration.cpp")]
    for path in files:
        src = open(path, encoding="utf-8").read()
        rel = os.path.relpath(path, source)
        if rel.endswith("calibration.cpp"):  # only the vehicle file's block is read there
            start = src.index("CalibrationPriors calibration_priors_from_yaml")
            src = src[start:src.index("\n}\n", start)]
        ranges = {}  # `const Range fraction = Range::closed(0.001, 0.5);`
        for m in re.finditer(r"const Range (\w+) = (Range::[^;]+);", src):
            ranges[m.group(1)] = interval(m.group(2), {})
        # Helpers that take (YamlMap, key): the key is the literal their callers pass.
        helpers = {}
        for m in re.finditer(r"\b(\w+)\(((?:const )?YamlMap&? \w+, const std::string& \w+[^)]*)\)\s*\{", src):
            params = [p.strip().split()[-1] for p in m.group(2).split(",")]
            types = [" ".join(p.strip().split()[:-1]) for p in m.group(2).split(",")]
            body_start = m.end() - 1
            depth, i = 0, body_start
            while True:
                depth += {"{": 1, "}": -1}.get(src[i], 0)
                i += 1
                if depth == 0:
                    break
            helpers[m.group(1)] = (params, types, src[body_start:i])
        for m in re.finditer(r"(?:\.|->)(\w+)\(", src):
            if m.group(1) not in READ_METHODS:
                continue
            args, _ = args_at(src, m.end() - 1)
            name = string_literal(args[0]) if args else None
            if not name:
                continue
            k = key(name, rel)
            method = m.group(1)
            if method in REQUIRED_METHODS:
                k.read_required = True
            elif method not in ("accept", "has"):
                k.read_optional = True
            range_arg = {"number": 1, "numbers": 1, "optional_number": 1, "optional_numbers": 1, "number_or": 2}
            if method in range_arg and len(args) > range_arg[method]:
                iv = interval(args[range_arg[method]], ranges)
                if iv:
                    k.intervals.add(iv)
            if method == "number_or" and literal_number(args[1]) is not None:
                k.defaults.add(literal_number(args[1]))
        for helper, (params, types, body) in helpers.items():
            for m in re.finditer(r"(?<![\w.>])" + helper + r"\(", src):
                if src[max(0, m.start() - 40):m.start()].rstrip().endswith(("double", "std::string", "void")):
                    continue  # its definition
                args, _ = args_at(src, m.end() - 1)
                name = string_literal(args[1]) if len(args) > 1 else None
                if not name:
                    continue
                k = key(name, rel)
                bound = dict(zip(params, args))
                for p, t in zip(params, types):  # a Range the caller gives: for_road_vehicle's physical range
                    if t == "Range" and p in bound:
                        iv = interval(bound[p], ranges)
                        if iv:
                            k.intervals.add(iv)
                for inner in re.finditer(r"\.(number|number_or)\(" + params[1] + r"\b", body):
                    iargs, _ = args_at(body, inner.end() - len(params[1]) - 1)
                    iargs = [bound.get(a, a) for a in iargs]
                    if inner.group(1) == "number_or":
                        k.read_optional = True
                    else:
                        k.read_required = True
                        if literal_number(iargs[1]) is not None:
                            k.defaults.add(literal_number(iargs[1]))
                    iv = interval(iargs[-1], ranges)
                    if iv:
                        k.intervals.add(iv)

    catalogue = open(os.path.join(source, "src", "effects", "catalogue.cpp"), encoding="utf-8").read()
    for m in re.finditer(r"row<\w+, \w+>\(\s*I::\w+,\s*\"(\w+)\"", catalogue):
        key(m.group(1), "src/effects/catalogue.cpp")
    field = r"\{\"(\w+)\", \"([^\"]*)\", (NUM), (NUM), (NUM), (NUM), (?:true|false)\}".replace("NUM", NUM)
    for m in re.finditer(field, catalogue):
        k = key(m.group(1), "src/effects/catalogue.cpp")
        k.unit = m.group(2)
        k.defaults.add(float(m.group(3)))
        k.intervals.add((float(m.group(5)), float(m.group(6)), False, False))

    recording = open(os.path.join(source, "src", "recording", "recording.cpp"), encoding="utf-8").read()
    canonical = re.search(r"kCanonical = \{(.*?)\};", recording, re.S).group(1)
    for name in re.findall(r"\"(\w+)\"", canonical):
        key(name, "src/recording/recording.cpp")

    header = open(os.path.join(source, "include", "rollsim", "diagnose", "diagnose.hpp"), encoding="utf-8").read()
    priors = re.search(r"struct CalibrationPriors \{(.*?)\};", header, re.S).group(1)
    for m in re.finditer(r"double (\w+) = (" + NUM + ");", priors):
        if m.group(1) in keys:
            keys[m.group(1)].defaults.add(float(m.group(2)))
    return keys


def doc_rows(doc):
    """{key: [row cells by header name]} from every table whose first column is headed Key."""
    rows = {}
    lines = doc.split("\n")
    i = 0
    while i < len(lines):
        if not lines[i].startswith("|"):
            i += 1
            continue
        table = []
        while i < len(lines) and lines[i].startswith("|"):
            table.append([c.strip() for c in lines[i].strip().strip("|").split("|")])
            i += 1
        header = [h.lower() for h in table[0]]
        if not header or not header[0].startswith("key"):
            continue
        for cells in table[2:]:
            m = re.fullmatch(r"`([A-Za-z0-9_]+)`", cells[0])
            if not m:
                raise SystemExit(f"docs/vehicle-file.md: a table row's first cell is not one `key`: {cells[0]!r}")
            rows.setdefault(m.group(1), []).append(dict(zip(header, cells)))
    return rows


def cell(row, name):
    return next((v for h, v in row.items() if h.startswith(name)), None)


def intervals_in(text):
    out = set()
    for m in re.finditer(r"([\[(])\s*(" + NUM + r")\s*,\s*(" + NUM + r")\s*([\])])", text.replace("−", "-")):
        out.add((float(m.group(2)), float(m.group(3)), m.group(1) == "(", m.group(4) == ")"))
    return out


def numbers_in(text):
    return {float(x) for x in re.findall(NUM, text)}


def check_keys(source):
    keys = code_keys(source)
    with open(os.path.join(source, "docs", "vehicle-file.md"), encoding="utf-8") as f:
        rows = doc_rows(f.read())
    failures = []
    if len(keys) < 100:
        failures.append(f"only {len(keys)} keys found in the readers: has the key extraction broken?")
    for name in sorted(set(keys) - set(rows)):
        failures.append(f"key '{name}' is read by {', '.join(sorted(keys[name].where))} but is not a row of the doc")
    for name in sorted(set(rows) - set(keys)):
        failures.append(f"the doc has a row for '{name}', which no reader reads")
    for name in sorted(set(keys) & set(rows)):
        k, rs = keys[name], rows[name]
        defaults = " ".join(cell(r, "default") or "" for r in rs)
        allowed = " ".join(cell(r, "allowed") or "" for r in rs)
        units = " ".join(cell(r, "unit") or "" for r in rs)
        for d in sorted(k.defaults):
            if d not in numbers_in(defaults):
                failures.append(f"'{name}': the code's default {d:g} is not in the doc's Default cell ({defaults!r})")
        if k.required_only and "required" not in defaults.lower():
            failures.append(f"'{name}' is only read as required, and its Default cell does not say so ({defaults!r})")
        for iv in sorted(k.intervals):
            if iv not in intervals_in(allowed):
                lo, hi, lo_open, hi_open = iv
                text = f"{'(' if lo_open else '['}{lo:g}, {hi:g}{')' if hi_open else ']'}"
                failures.append(f"'{name}': the code enforces {text}, not in the doc's Allowed cell ({allowed!r})")
        if k.unit is not None and f"`{k.unit}`" not in units and k.unit not in units.split():
            failures.append(f"'{name}': the catalogue's unit '{k.unit}' is not in the doc's Unit cell ({units!r})")
    return keys, rows, failures


def check_examples(source, rollsim):
    with open(os.path.join(source, "docs", "vehicle-file.md"), encoding="utf-8") as f:
        lines = f.read().split("\n")
    failures, ran = [], 0
    env = dict(os.environ, ROLLSIM_DATA_DIR=source)
    with tempfile.TemporaryDirectory() as scratch:
        i = 0
        while i < len(lines):
            if lines[i].strip() == "```yaml" and i + 1 < len(lines) and lines[i + 1].startswith("# file: "):
                name = lines[i + 1][len("# file: "):].strip()
                j = lines.index("```", i + 1)
                with open(os.path.join(scratch, name), "w", encoding="utf-8") as out:
                    out.write("\n".join(lines[i + 1:j]) + "\n")
                i = j + 1
                continue
            m = re.match(r"^    \$ \./build/rollsim (.*?)(\s+#.*)?$", lines[i])
            i += 1
            if not m:
                continue
            expected = []
            while i < len(lines) and lines[i].startswith("    ") and not lines[i].startswith("    $ "):
                if lines[i].strip() != "...":
                    expected.append(lines[i][4:].rstrip())
                i += 1
            run = subprocess.run([rollsim] + shlex.split(m.group(1)), cwd=scratch, env=env, capture_output=True,
                                 text=True, timeout=300)
            printed = {l.rstrip() for l in run.stdout.split("\n")}
            missing = [l for l in expected if l not in printed]
            ran += 1
            if run.returncode != 0 or missing:
                failures.append(f"rollsim {m.group(1)}: exit {run.returncode} {run.stderr.strip()}; doc lines it does "
                                "not print:\n     " + "\n     ".join(missing))
            else:
                print(f"ok   rollsim {m.group(1)} ({len(expected)} lines)")
    if ran < 2:
        failures.append(f"{ran} example runs found in the doc; expected the electric and the petrol car")
    return failures


def main():
    source = os.path.abspath(sys.argv[1])
    keys, rows, failures = check_keys(source)
    print(f"{len(keys)} keys read by the code, {len(rows)} keys in the doc's tables")
    if len(sys.argv) > 2:
        failures += check_examples(source, os.path.abspath(sys.argv[2]))
    for f in failures:
        print("FAIL " + f)
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
