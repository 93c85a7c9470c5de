#!/usr/bin/env python3
"""The Python module's overhead over the CLI (issue 52's goal: at most 5% of the CLI's time), in
one run: the same character, clip and settings through `animorder optimize -o` and through
`animorder.load` / `run` / `write_sidecar` in a fresh python3, each a whole process, rounds
interleaved; medians and their ratio. The two outputs must be the same bytes.

    PYTHONPATH=build/python python3 bench/bench_python.py build/animorder FILE [--clip NAME] [--rounds 3]
"""
import argparse
import os
import statistics
import subprocess
import sys
import tempfile
import time

parser = argparse.ArgumentParser()
parser.add_argument("cli")
parser.add_argument("input")
parser.add_argument("--clip", default=None)
parser.add_argument("--rounds", type=int, default=3)
args = parser.parse_args()

with tempfile.TemporaryDirectory() as scratch:
    os.makedirs(os.path.join(scratch, "cli"))
    os.makedirs(os.path.join(scratch, "py"))
    clip = ["--clip", args.clip] if args.clip else []
    cli_command = [args.cli, "optimize", args.input, "-q", *clip, "-o", os.path.join(scratch, "cli", "out")]
    script = (
        "import animorder, sys\n"
        "c = animorder.load(sys.argv[1], clips=sys.argv[3:])\n"
        "animorder.write_sidecar(c, animorder.run(c), sys.argv[2])\n"
    )
    py_command = [sys.executable, "-c", script, args.input, os.path.join(scratch, "py", "out"),
                  *([args.clip] if args.clip else [])]
    times = {"cli": [], "python": []}
    for _ in range(args.rounds):
        for name, command in (("cli", cli_command), ("python", py_command)):
            start = time.perf_counter()
            subprocess.run(command, check=True, stdout=subprocess.DEVNULL)
            times[name].append(time.perf_counter() - start)
    for suffix in (".animorder.bin", ".animorder.json"):
        with open(os.path.join(scratch, "cli", "out" + suffix), "rb") as a, \
             open(os.path.join(scratch, "py", "out" + suffix), "rb") as b:
            if a.read() != b.read():
                sys.exit("bench_python: the module's " + suffix + " differs from the CLI's")

cli_s, py_s = statistics.median(times["cli"]), statistics.median(times["python"])
print(f"input {args.input}{' clip ' + args.clip if args.clip else ''}, {args.rounds} rounds each, interleaved")
print(f"cli_median_s {cli_s:.3f}")
print(f"python_median_s {py_s:.3f}")
print(f"python_over_cli {py_s / cli_s:.4f}")
