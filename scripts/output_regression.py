#!/usr/bin/env python3
"""Runs pdamp's commands on every shipped case and compares two sets of results.

A refactoring that must not change results (the same JSON and CSV, bit for bit) is
checked by running this with the binary before the change and after it:

    scripts/output_regression.py run /tmp/pdamp_before /tmp/outputs_before [--full]
    scripts/output_regression.py run build/pdamp /tmp/outputs_after [--full]
    scripts/output_regression.py compare /tmp/outputs_before /tmp/outputs_after

`run` writes, per command, its --json output (stdout.json), its exit code and its -o
folder. `compare` reads both trees: every JSON value must be equal except the timing keys
(wall and solve times, rates, creation times, MPI balance), and every CSV, .dat and .jsonl
file byte for byte. Plots (PNG, SVG), scripts (.gp) and the HTML report are not compared
(gnuplot's and the report's bytes follow from the data compared). --full adds the long DEM
runs (the optimisation's DEM verification, the DEM decay and the stepped-sine FRF), about
ten minutes on two cores; without it the set takes about two minutes.
"""
import json
import math
import re
import os
import subprocess
import sys

CASES = [
    "low_intensity_36_spheres", "high_intensity_cylinder", "buffered_wall_60hz", "beam_base_excited",
    "manipulator_link_decay", "free_free_beam_shaker", "manipulator_link_optimize", "free_free_beam_placement",
]
FORMAT_1 = ["low_intensity_36_spheres", "high_intensity_cylinder", "buffered_wall_60hz"]
STRUCTURES = ["beam_base_excited", "manipulator_link_decay", "free_free_beam_shaker", "manipulator_link_optimize",
              "free_free_beam_placement"]


def commands(full):
    """(name, argv without the binary, with -o) of every command compared."""
    out = []
    for case in CASES:
        path = f"cases/{case}.json"
        extra = ["--no-verify"] if case == "manipulator_link_optimize" and not full else []
        out.append((f"run_{case}", ["run", path, "--json"] + extra, True))
        out.append((f"validate_{case}", ["validate", path], False))
    for case in FORMAT_1:
        path = f"cases/{case}.json"
        out.append((f"field_formulas_{case}", ["field", path, "--source", "formulas", "--json"], True))
        out.append((f"sensitivity_formulas_{case}", ["sensitivity", path, "--source", "formulas", "--json"], True))
        out.append((f"dem_{case}", ["dem", path, "--periods", "2", "--json"], True))
    for case in STRUCTURES:
        out.append((f"modes_{case}", ["modes", f"cases/{case}.json", "--json"], True))
    for case in ["beam_base_excited", "free_free_beam_shaker"]:
        out.append((f"frf_{case}", ["frf", f"cases/{case}.json", "--json"], True))
    out.append(("frf_field_beam", ["frf", "cases/beam_base_excited.json", "--method", "field", "--json"], True))
    out.append(("decay_formulas_link", ["decay", "cases/manipulator_link_decay.json", "--json"], True))
    out.append(("decay_field_link", ["decay", "cases/manipulator_link_decay.json", "--method", "field", "--json"], True))
    out.append(("optimize_no_verify", ["optimize", "cases/manipulator_link_optimize.json", "--no-verify", "--json"], True))
    out.append(("optimize_ipopt", ["optimize", "cases/manipulator_link_optimize.json", "--no-verify", "--backend",
                                   "ipopt", "--json"], True))
    out.append(("placement_field", ["optimize", "cases/free_free_beam_placement.json", "--json"], True))
    out.append(("loss", ["loss", "--model", "auto", "--clearance", "0.1", "--amplitude", "0.04", "--frequency", "2",
                         "--bed-mass", "0.148", "--json"], True))
    out.append(("optimum", ["optimum", "--model", "rolling", "--clearance", "0.1", "--json"], False))
    out.append(("size", ["size", "--model", "bouncing", "--stroke", "0.003", "--json"], False))
    out.append(("buffer", ["buffer", "--frequency", "60", "--intensity", "20", "--radius", "0.0025", "--layer-modulus",
                           "60e6", "--particles-per-contact", "20", "--json"], False))
    out.append(("bad_input", ["loss", "--model", "auto", "--clearance", "-1", "--amplitude", "0.04", "--frequency", "2",
                              "--json"], False))
    out.append(("frf_dem_linear_short", ["frf", "cases/beam_base_excited.json", "--method", "dem", "--dem-signal",
                                         "linear", "--dem-sweep", "up", "--dem-sweep-rate", "0.2",
                                         "--dem-min-frequency", "1.7", "--dem-max-frequency", "1.9", "--json"], True))
    if full:
        out.append(("frf_dem_beam", ["frf", "cases/beam_base_excited.json", "--method", "dem", "--dem-points", "5",
                                     "--dem-min-frequency", "1.5", "--dem-max-frequency", "2.1", "--json"], True))
        out.append(("frf_compare_beam", ["frf", "cases/beam_base_excited.json", "--compare", "--dem-points", "3",
                                         "--dem-min-frequency", "1.6", "--dem-max-frequency", "2.0", "--json"], True))
        out.append(("decay_dem_link", ["decay", "cases/manipulator_link_decay.json", "--method", "dem", "--json"], True))
    return out


def run(binary, root, full):
    root = os.path.abspath(root)
    os.makedirs(root, exist_ok=True)
    for name, argv, with_dir in commands(full):
        folder = os.path.join(root, name)
        os.makedirs(folder, exist_ok=True)
        args = [os.path.abspath(binary)] + argv + (["-o", os.path.join(folder, "out")] if with_dir else [])
        done = subprocess.run(args, capture_output=True, text=True)
        with open(os.path.join(folder, "stdout.txt"), "w") as f:
            f.write(done.stdout)
        with open(os.path.join(folder, "exit_code"), "w") as f:
            f.write(f"{done.returncode}\n")
        print(f"{name}: exit {done.returncode}", file=sys.stderr)


TIMING_KEYS = ("time_s", "steps_per_s", "wall", "busy_fraction", "created", "stage_s")
# A solver's one-line report ends with its wall time: "..., 312 evaluations, 0.68 s".
WALL_TIME_IN_TEXT = re.compile(r"[0-9.e+-]+ s$")


def timing(key):
    return any(t in key for t in TIMING_KEYS) and key not in ("settling_time_s", "final_time_s", "time_s",
                                                              "bed_settling_time_s", "settling_steps")


def diff_json(a, b, where, out, root_a, root_b):
    if isinstance(a, dict) and isinstance(b, dict):
        for key in sorted(set(a) | set(b)):
            if timing(key) or key == "mpi":
                continue
            if key not in a or key not in b:
                out.append(f"{where}/{key}: only in {'after' if key in b else 'before'}")
                continue
            diff_json(a[key], b[key], f"{where}/{key}", out, root_a, root_b)
    elif isinstance(a, list) and isinstance(b, list):
        if len(a) != len(b):
            out.append(f"{where}: {len(a)} items before, {len(b)} after")
        for i, (x, y) in enumerate(zip(a, b)):
            diff_json(x, y, f"{where}/{i}", out, root_a, root_b)
    elif isinstance(a, str) and isinstance(b, str):
        if where.endswith("/report"):
            a, b = WALL_TIME_IN_TEXT.sub("T s", a), WALL_TIME_IN_TEXT.sub("T s", b)
        if a.replace(root_a, "ROOT") != b.replace(root_b, "ROOT"):
            out.append(f"{where}: {a!r} before, {b!r} after")
    elif isinstance(a, float) and isinstance(b, float) and math.isnan(a) and math.isnan(b):
        pass
    elif a != b or type(a) != type(b):
        out.append(f"{where}: {a!r} before, {b!r} after")


def compare(root_a, root_b):
    problems = []
    compared = 0
    for name in sorted(os.listdir(root_a)):
        a, b = os.path.join(root_a, name), os.path.join(root_b, name)
        if not os.path.isdir(b):
            problems.append(f"{name}: missing after")
            continue
        for sub, _, files in os.walk(a):
            for file in sorted(files):
                fa = os.path.join(sub, file)
                fb = os.path.join(b, os.path.relpath(fa, a))
                rel = os.path.relpath(fa, root_a)
                if not os.path.exists(fb):
                    problems.append(f"{rel}: missing after")
                    continue
                if file.endswith((".png", ".svg", ".gp", ".html", ".log")) or file.startswith(".pdamp"):
                    continue
                compared += 1
                if file == "stdout.txt" or file.endswith(".json"):
                    ta, tb = open(fa).read(), open(fb).read()
                    try:
                        ja, jb = json.loads(ta), json.loads(tb)
                    except json.JSONDecodeError:
                        if ta.replace(root_a, "ROOT") != tb.replace(root_b, "ROOT"):
                            problems.append(f"{rel}: text differs")
                        continue
                    out = []
                    diff_json(ja, jb, rel, out, os.path.abspath(root_a), os.path.abspath(root_b))
                    problems += out
                elif open(fa, "rb").read() != open(fb, "rb").read():
                    problems.append(f"{rel}: bytes differ")
        for sub, _, files in os.walk(b):
            for file in files:
                fb = os.path.join(sub, file)
                if not os.path.exists(os.path.join(a, os.path.relpath(fb, b))) and not file.startswith(".pdamp"):
                    problems.append(f"{os.path.relpath(fb, root_b)}: only after")
    for p in problems:
        print(p)
    print(f"{compared} files compared, {len(problems)} differences", file=sys.stderr)
    return 1 if problems else 0


if __name__ == "__main__":
    if len(sys.argv) >= 4 and sys.argv[1] == "run":
        run(sys.argv[2], sys.argv[3], "--full" in sys.argv[4:])
    elif len(sys.argv) == 4 and sys.argv[1] == "compare":
        sys.exit(compare(sys.argv[2], sys.argv[3]))
    else:
        print(__doc__, file=sys.stderr)
        sys.exit(2)
