#!/usr/bin/env python3
"""What a run costs beyond its solver: start-up, parsing and writing the outputs (issue "no overhead").

Usage (from the source root, after a Release build):
    /usr/bin/python3 tests/bench/output_overhead.py build/chainsim [OTHER_BINARY ...] [--repeat 7]

The run: the hanging chain on its first mode (docs/data/hanging_chain_mode1.toml) at 251 nodes, dirk4,
rtol 1e-6, atol 1e-10, t_end 5 s (3 periods) and a frame every 0.01 s: 501 frames, every output at its
default (nodes, tension, energy, forces as CSV; a ParaView frame each; stats.json), written to a fresh
directory each time. The binaries run in turn, `repeat` times each, so that they see the same machine.
For each binary: the medians of the whole process's wall time, its CPU time (user + system, all
threads), the run's own `wall_s` (the solver, from stats.json) and their difference (the overhead).
With --python, the same run by chainsim.Scene(...).run() in this process (PYTHONPATH=build/python): the
median of its time (scene parsing, the run, the arrays copied into numpy; no files) beside the CLI's.
With --set KEY=VALUE (repeatable) the runs take more settings, e.g. --set 'output.formats=["csv"]'.
With --floor: what the file system alone costs for the ParaView frames, 501 files of the size of this run's
frames created, written and renamed one after the other (os.open, os.write, os.rename: no formatting), and
the same bytes as one file; the medians of `repeat` rounds.
Under a load from other processes a run's wall time is mostly waiting for a core: run the script under
`chrt -f 50` (as root) to time it as on an idle machine.
The same run by hand: /usr/bin/time -v build/chainsim run docs/data/hanging_chain_mode1.toml --out DIR
--set string.nodes=251 --set solver.method=dirk4 --set solver.rtol=1e-6 --set solver.atol=1e-10
--set stop.t_end=5.0 --set output.interval=0.01 --quiet
"""
import argparse
import json
import os
import shutil
import statistics
import subprocess
import tempfile
import time

SCENE = "docs/data/hanging_chain_mode1.toml"
SETTINGS = ["string.nodes=251", "solver.method=dirk4", "solver.rtol=1e-6", "solver.atol=1e-10",
            "stop.t_end=5.0", "output.interval=0.01"]


def one_run(binary, out, extra=()):
    shutil.rmtree(out, ignore_errors=True)
    args = [binary, "run", SCENE, "--out", out, "--quiet"]
    for s in SETTINGS + list(extra):
        args += ["--set", s]
    before = os.times()
    t0 = time.perf_counter()
    subprocess.run(args, check=True, stdout=subprocess.DEVNULL)
    wall = time.perf_counter() - t0
    after = os.times()
    cpu = (after.children_user - before.children_user) + (after.children_system - before.children_system)
    with open(os.path.join(out, "stats.json")) as f:
        solver = json.load(f)["wall_s"]
    return wall, cpu, solver


def write_files(directory, sizes):
    """Seconds to create, write and rename one file per size in a fresh `directory`."""
    shutil.rmtree(directory, ignore_errors=True)
    os.makedirs(directory)
    data = b"x" * max(sizes)
    t0 = time.perf_counter()
    for k, size in enumerate(sizes):
        temp = os.path.join(directory, f".frame_{k:04d}.vtp.tmp")
        fd = os.open(temp, os.O_WRONLY | os.O_CREAT | os.O_TRUNC, 0o644)
        os.write(fd, data[:size])
        os.close(fd)
        os.rename(temp, os.path.join(directory, f"frame_{k:04d}.vtp"))
    return time.perf_counter() - t0


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("binaries", nargs="+")
    parser.add_argument("--repeat", type=int, default=7)
    parser.add_argument("--python", action="store_true", help="also time chainsim.Scene(...).run()")
    parser.add_argument("--set", action="append", default=[], help="another KEY=VALUE for the runs")
    parser.add_argument("--floor", action="store_true", help="also time the file system alone (see above)")
    a = parser.parse_args()
    runs = {b: [] for b in a.binaries}
    scene = None
    if a.python:
        import chainsim
        scene = chainsim.Scene.from_file(SCENE).set(**{k: float(v) if "." in v or "e" in v else (int(v) if v.isdigit() else v)
                                                       for k, v in (x.split("=") for x in SETTINGS)})
        runs["chainsim.Scene(...).run()"] = []
    with tempfile.TemporaryDirectory() as tmp:
        out = os.path.join(tmp, "run")
        for _ in range(a.repeat):
            for b in a.binaries:
                runs[b].append(one_run(b, out, a.set))
            if scene is not None:
                t0 = time.perf_counter()
                result = scene.run()
                wall = time.perf_counter() - t0
                runs["chainsim.Scene(...).run()"].append((wall, wall, result.summary["wall_s"]))
        if a.floor:
            frames = os.path.join(out, "frames")
            sizes = [os.path.getsize(os.path.join(frames, f)) for f in sorted(os.listdir(frames))]
            many, one = [], []
            for _ in range(a.repeat):
                many.append(write_files(os.path.join(tmp, "floor"), sizes))
                one.append(write_files(os.path.join(tmp, "floor"), [sum(sizes)]))
            print(f"file system floor: {len(sizes)} files, {sum(sizes) / 1e6:.1f} MB: {statistics.median(many) * 1e3:.1f} ms; "
                  f"the same bytes as one file: {statistics.median(one) * 1e3:.1f} ms")
    print(f"{'binary':40s} {'wall ms':>9s} {'cpu ms':>9s} {'solver ms':>10s} {'overhead ms':>12s}")
    for b, rs in runs.items():
        wall, cpu, solver = (statistics.median(x) * 1e3 for x in zip(*rs))
        over = statistics.median(w - s for w, _, s in rs) * 1e3
        print(f"{b:40s} {wall:9.1f} {cpu:9.1f} {solver:10.1f} {over:12.1f}")


if __name__ == "__main__":
    main()
