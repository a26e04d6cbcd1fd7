#!/usr/bin/env python3
"""Scene fuzzer for `ghostfx run` (ctest label "fuzz"): single-value mutations of small valid
liquid, gas and boiling scenes, each run through the real program.

Every run must end in one of two ways:
  - exit 0, with every frame's output files present and non-empty (the frames asked for);
  - exit 1, with exactly one line on stderr, "ghostfx: error: ..." naming the scene file and a
    key (a dotted path such as settings.spacing or solids[0].geometry).
Never a signal, an "internal error" (exit 2), a time-out, or output files left from a run that
failed (errors come before any output).

Mutations (one per case, at a path drawn from the scene): a type swap, an extreme value (0,
-1, 1e308, 1e-300, 2^63, -2^63), null, a deleted key, NaN and Infinity (not JSON: a parse
error), an empty string, array or object. The seed and the case count are fixed, so a run is
reproducible; a failing case prints its scene and command line.

usage: fuzz_scenes.py --exe build/cmd/ghostfx [--seed 1] [--cases 300] [--budget 900]
       [--timeout 120] [--keep DIR]
"""
import argparse
import copy
import json
import os
import random
import re
import shutil
import subprocess
import sys
import tempfile
import time

FRAMES = 2

# Small valid scenes: each runs its two frames in well under a second on one thread.
BASES = {
    "liquid": {
        "ghostfx_scene": 1,
        "settings": {"method": "ghost", "spacing": 0.03, "substeps": 0, "frame_rate": 30,
                     "frame_range": [1, FRAMES], "stiffness": 2000, "seed": 3},
        "solids": [{"name": "tank", "geometry": {"container": {"min": [0, 0, 0],
                                                               "max": [0.3, 0.3, 0.15]}}}],
        "liquids": [{"name": "water", "geometry": {"box": {"min": [0, 0, 0],
                                                           "max": [0.12, 0.12, 0.15]}},
                     "velocity": [0, 0, 0]}],
        "emitters": [{"name": "tap", "geometry": {"sphere": {"center": [0.2, 0.2, 0.07],
                                                             "radius": 0.04}},
                      "velocity": [0, -0.5, 0], "start": 0, "end": 0.05}],
        "domain": {"kill_box": {"min": [-0.2, -0.2, -0.2], "max": [0.5, 0.5, 0.35]}},
        "outputs": {"points": {"file": "liquid_points.$F4.vdb",
                               "channels": ["v", "id", "density"]},
                    "volume": {"file": "liquid.$F4.vdb", "grids": ["surface", "density"]},
                    "checkpoint": {"file": "checkpoint.$F4.h5", "every": 1},
                    "stats": {"file": "stats.h5"}},
    },
    "gas": {
        "ghostfx_scene": 1,
        "settings": {"method": "gas", "spacing": 0.04, "frame_range": [1, FRAMES],
                     "gas": {"substeps": 2, "seed": 1, "buoyancy": 0.0335}},
        "domain": {"kill_box": {"min": [-0.3, -0.05, -0.3], "max": [0.3, 0.8, 0.3]}},
        "solids": [{"name": "floor", "geometry": {"box": {"min": [-0.3, -0.15, -0.3],
                                                          "max": [0.3, 0.0, 0.3]}}}],
        "gas_sources": [{"name": "burner", "geometry": {"sphere": {"center": [0, 0.1, 0],
                                                                    "radius": 0.08}},
                         "temperature": 600, "velocity": [0, 0.4, 0]}],
        "outputs": {"gas_volume": {"file": "gas.$F4.vdb", "grids": ["density", "temperature"]},
                    "gas_points": {"file": "gas_points.$F4.vdb", "channels": ["v", "id"]}},
    },
    "boiling": {
        "ghostfx_scene": 1,
        "settings": {"method": "ghost", "spacing": 0.03, "substeps": 5, "frame_range": [1, FRAMES]},
        "solids": [{"name": "pan", "geometry": {"container": {"min": [0, 0, 0],
                                                              "max": [0.18, 0.3, 0.18]}}}],
        "liquids": [{"name": "water", "geometry": {"box": {"min": [0, 0, 0],
                                                           "max": [0.18, 0.06, 0.18]}}}],
        "heaters": [{"name": "plate", "geometry": {"box": {"min": [-0.09, -0.09, -0.09],
                                                           "max": [0.27, 0.0, 0.27]}},
                     "temperature": 500}],
        "phase_transition": {"initial_temperature": 372, "latent_heat": 5, "heating_time": 0.02},
        "domain": {"kill_box": {"min": [-0.2, -0.2, -0.2], "max": [0.4, 1.0, 0.4]}},
    },
}

EXTREMES = [0, -1, 1e308, -1e308, 1e-300, 1e-9, 1e9, 1e30, -1e30, 2 ** 31, 2 ** 63, -(2 ** 63), 2 ** 64]
# A key path in a message: settings.spacing, solids[0].geometry, outputs.points.file, ...
KEY_PATH = re.compile(r"[A-Za-z_][A-Za-z0-9_]*(\[\d+\])?(\.[A-Za-z_][A-Za-z0-9_]*|\[\d+\])+"
                      r"|\b(ghostfx_scene|settings|solids|liquids|emitters|gas_sources|heaters|"
                      r"domain|outputs|phase_transition|force_fields)\b")


def paths(value, prefix=()):
    """Every (path, value) in a JSON document, containers included (not the root)."""
    out = []
    items = value.items() if isinstance(value, dict) else (
        enumerate(value) if isinstance(value, list) else [])
    for key, child in items:
        path = prefix + (key,)
        out.append((path, child))
        out += paths(child, path)
    return out


def dotted(path):
    text = ""
    for p in path:
        text += f"[{p}]" if isinstance(p, int) else (("." if text else "") + p)
    return text


def swapped(value, rng):
    """A value of another JSON type than `value`."""
    choices = [3.5, -7, "text", True, [1, 2], {"a": 1}, None]
    choices = [c for c in choices if type(c) is not type(value)]
    return copy.deepcopy(rng.choice(choices))


def mutate(scene, rng):
    """One single-value mutation; returns (scene or raw text, description)."""
    path, value = rng.choice(paths(scene))
    kind = rng.choice(["swap", "extreme", "extreme", "null", "delete", "nan", "empty"])
    doc = copy.deepcopy(scene)
    parent = doc
    for p in path[:-1]:
        parent = parent[p]
    last = path[-1]
    if kind == "delete":
        del parent[last]
        return doc, f"delete {dotted(path)}"
    if kind == "nan":
        parent[last] = "__NAN__"
        token = rng.choice(["NaN", "Infinity", "-Infinity"])
        return json.dumps(doc).replace('"__NAN__"', token), f"{dotted(path)} = {token}"
    new = {"swap": lambda: swapped(value, rng), "extreme": lambda: rng.choice(EXTREMES),
           "null": lambda: None,
           "empty": lambda: rng.choice(["", [], {}])}[kind]()
    parent[last] = new
    return doc, f"{dotted(path)} = {json.dumps(new)}"


def frame_files(scene):
    """Output files each frame must have, from the scene's outputs (the program's defaults for
    what it does not say)."""
    outputs = scene.get("outputs", {}) if isinstance(scene, dict) else {}
    method = scene.get("settings", {}).get("method", "ghost") if isinstance(scene, dict) else ""
    gas = method in ("gas", "gas_ambient", "gas_uncorrected")
    boiling = not gas and bool(scene.get("heaters")) if isinstance(scene, dict) else False
    files = []
    wanted = []
    if not gas:
        wanted += [("points", "liquid_points.$F4.vdb"), ("volume", "liquid.$F4.vdb")]
    if gas or boiling:
        wanted += [("gas_points", "gas_points.$F4.vdb"), ("gas_volume", "gas.$F4.vdb")]
    for key, default in wanted:
        section = outputs.get(key, True) if isinstance(outputs, dict) else True
        if section is False or section is None:
            continue
        name = section.get("file", default) if isinstance(section, dict) else default
        if isinstance(name, str):
            files.append(name)
    return files


def expand(pattern, frame):
    return re.sub(r"\$F(\d?)", lambda m: f"{frame:0{m.group(1) or 1}d}", pattern)


def check_case(exe, scene_text, scene, work, timeout):
    """Run one case; returns (exit code, "" if it ended in one of the allowed ways, else what
    went wrong)."""
    path = os.path.join(work, "scene.json")
    with open(path, "w") as f:
        f.write(scene_text)
    out = os.path.join(work, "out")
    args = [exe, "run", path, "--out", out, "--frames", f"1-{FRAMES}", "-q", "--threads", "1",
            "--sample-cache", "off"]
    try:
        run = subprocess.run(args, capture_output=True, text=True, timeout=timeout)
    except subprocess.TimeoutExpired:
        return None, f"timed out after {timeout} s"
    return run.returncode, judge(run, path, scene, out)


def judge(run, path, scene, out):
    """What is wrong with how `run` of the scene at `path` ended ("" if nothing)."""
    err = run.stderr
    lines = [l for l in err.splitlines() if l.strip()]
    if run.returncode < 0:
        return f"ended by signal {-run.returncode}: {err[-2000:]}"
    if run.returncode == 0:
        if not isinstance(scene, dict):
            return "exit 0 for a scene that is not JSON"
        missing = []
        for pattern in frame_files(scene):
            for frame in range(1, FRAMES + 1):
                file = os.path.join(out, expand(pattern, frame))
                if not os.path.isfile(file) or os.path.getsize(file) == 0:
                    missing.append(os.path.relpath(file, out))
        if missing:
            return f"exit 0 but frames are missing or empty: {missing[:4]}; stderr: {err[-1000:]}"
        leftover = [n for n in os.listdir(out) if n.startswith(".")]
        return f"temporaries left behind: {leftover}" if leftover else ""
    if run.returncode != 1:
        return f"exit {run.returncode}: {err[-2000:]}"
    errors = [l for l in lines if l.startswith("ghostfx: error: ")]
    if len(errors) != 1 or "internal error" in err:
        return f"exit 1 without exactly one error line: {err[-2000:]}"
    line = errors[0]
    if path not in line:
        return f"the error does not name the scene file: {line}"
    if not KEY_PATH.search(line[len("ghostfx: error: "):].replace(path, "")):
        return f"the error names no key: {line}"
    leftover = [n for n in os.listdir(out) if n.startswith(".")] if os.path.isdir(out) else []
    if leftover:
        return f"temporaries left behind: {leftover}; {line}"
    # An input error comes before any output; a blow-up during the run keeps the frames before.
    if os.path.isdir(out) and os.listdir(out) and "blew up" not in line:
        return f"exit 1 but output was written: {sorted(os.listdir(out))[:5]}; {line}"
    return ""


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--exe", required=True)
    parser.add_argument("--seed", type=int, default=1)
    parser.add_argument("--cases", type=int, default=300)
    parser.add_argument("--budget", type=float, default=900,
                        help="seconds; after it no new case starts (the count run is printed)")
    parser.add_argument("--timeout", type=float, default=120, help="seconds a case may take")
    parser.add_argument("--keep", help="folder to keep failing cases in")
    args = parser.parse_args()

    rng = random.Random(args.seed)
    names = sorted(BASES)
    start = time.monotonic()
    failures, outcomes = [], {"exit 0": 0, "exit 1": 0}
    root = tempfile.mkdtemp(prefix="ghostfx_fuzz_")
    try:
        for case in range(args.cases):
            if time.monotonic() - start > args.budget:
                break
            base = names[case % len(names)]
            mutated, what = mutate(BASES[base], rng)
            text = mutated if isinstance(mutated, str) else json.dumps(mutated, indent=1)
            scene = None if isinstance(mutated, str) else mutated
            work = os.path.join(root, f"case{case}")
            os.makedirs(work)
            t0 = time.monotonic()
            code, problem = check_case(args.exe, text, scene, work, args.timeout)
            took = time.monotonic() - t0
            if problem:
                failures.append((case, base, what, problem))
                print(f"FAIL case {case} ({base}: {what}, {took:.1f} s): {problem}", flush=True)
                if args.keep:
                    kept = os.path.join(args.keep, f"case{case}.json")
                    os.makedirs(args.keep, exist_ok=True)
                    with open(kept, "w") as f:
                        f.write(text)
            else:
                outcomes[f"exit {code}"] += 1
            shutil.rmtree(work, ignore_errors=True)
        ran = sum(outcomes.values()) + len(failures)
        print(f"[measured] {ran} cases in {time.monotonic() - start:.0f} s (seed {args.seed}): "
              f"{outcomes['exit 0']} ran, {outcomes['exit 1']} refused with one line, "
              f"{len(failures)} failed")
    finally:
        shutil.rmtree(root, ignore_errors=True)
    if ran < min(args.cases, 100):
        print(f"only {ran} cases fit the budget of {args.budget} s (expected at least 100)")
        return 1
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
