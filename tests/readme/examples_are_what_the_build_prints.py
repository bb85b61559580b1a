#!/usr/bin/env python3
"""ctest Readme.ExamplesAreWhatTheBuildPrints: every README example of the form

    $ ./build/rollsim ARGS
    OUTPUT LINE
    ...

is run from the repository with the built binary, and each of its output lines must be a line the command prints
(a README may leave lines out, and `...` marks a cut). A pasted output that drifts from what the code computes
fails here, instead of going stale in front of a reader.
Usage: examples_are_what_the_build_prints.py ROLLSIM SOURCE_DIR"""
import re
import shlex
import subprocess
import sys


def examples(readme):
    lines = readme.split("\n")
    i = 0
    while i < len(lines):
        m = re.match(r"^    \$ \./build/rollsim (.*?)(\s+#.*)?$", lines[i])
        i += 1
        if not m:
            continue
        out = []
        while i < len(lines) and lines[i].startswith("    ") and not lines[i].startswith("    $ "):
            out.append(lines[i][4:].rstrip())
            i += 1
        if out:
            yield m.group(1), [l for l in out if l != "..."]


def main():
    rollsim, source = sys.argv[1], sys.argv[2]
    with open(f"{source}/README.md", encoding="utf-8") as f:
        readme = f.read()
    failed = checked = 0
    for args, expected in examples(readme):
        run = subprocess.run([rollsim] + shlex.split(args), cwd=source, capture_output=True, text=True, timeout=300)
        printed = {l.rstrip() for l in run.stdout.split("\n")}
        missing = [l for l in expected if l not in printed]
        checked += 1
        if run.returncode != 0 or missing:
            failed += 1
            print(f"FAIL rollsim {args}: exit {run.returncode}; README lines the build does not print:")
            for l in missing:
                print(f"     {l}")
        else:
            print(f"ok   rollsim {args} ({len(expected)} lines)")
    print(f"{checked} README examples, {failed} differ from the build")
    return 1 if failed or checked == 0 else 0


if __name__ == "__main__":
    sys.exit(main())
