"""Timings of the Python module against the command-line tool, side by side in one run (docs/python.md, "Measured").

    PYTHONPATH=build/python:python /usr/bin/python3 scripts/bench_python.py [--rounds N]

1. Overhead of a short run: `chainsim run` as a process (start, parse, build, run, write the run directory) against
   Scene.from_file(...).run() (parse, build, run, arrays) and .run() + .write(dir) in one process; alternating, N
   rounds, medians. The integration's own wall time (summary wall_s) is reported to separate it.
2. A sweep of 8 points (falling chain, f x nodes) on 1 and on 2 workers: threads (chainsim.sweep's default), processes
   (concurrent.futures.ProcessPoolExecutor on the same point function), and a 2-worker Dask LocalCluster (started
   once, outside the timing); alternating rounds, medians, speed-ups against 1 thread.
"""
import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile
import time
from concurrent.futures import ProcessPoolExecutor

import chainsim

SOURCE = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
BINARY = os.environ.get("CHAINSIM_BINARY", os.path.join(SOURCE, "build", "chainsim"))


def timed(fn):
    start = time.perf_counter()
    value = fn()
    return time.perf_counter() - start, value


def cpu_per_wall(fn):
    """CPU time of this process (all its threads) over the wall time: above 1 when threads ran at once."""
    cpu, start = time.process_time(), time.perf_counter()
    fn()
    return (time.process_time() - cpu) / (time.perf_counter() - start)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--rounds", type=int, default=11)
    args = ap.parse_args()
    print(f"load average before: {os.getloadavg()}, {os.cpu_count()} cores")
    tmp = tempfile.mkdtemp(prefix="chainsim_bench_")

    # 1. a short run
    scene_file = os.path.join(SOURCE, "cases", "scenes", "hanging_chain.toml")
    t_end = 0.2
    scene = chainsim.Scene.from_file(scene_file).set("string.nodes", 21)
    cli, py_run, py_write, integ = [], [], [], []
    for k in range(args.rounds):
        out = os.path.join(tmp, "cli")
        t, _ = timed(lambda: subprocess.run([BINARY, "run", scene_file, "--set", "string.nodes=21", "--t-end",
                                             str(t_end), "--out", out, "--quiet"], check=True, capture_output=True))
        cli.append(t)
        t, r = timed(lambda: chainsim.Scene.from_file(scene_file).set("string.nodes", 21).run(t_end=t_end))
        py_run.append(t)
        integ.append(r.summary["wall_s"])
        t, _ = timed(lambda: scene.run(t_end=t_end).write(os.path.join(tmp, "py")))
        py_write.append(t)
    med = statistics.median
    print(f"\nshort run: hanging_chain.toml, 21 nodes, t_end = {t_end} s, {args.rounds} alternating rounds, medians")
    print(f"  chainsim run (process, writes the run directory)   {med(cli) * 1e3:8.2f} ms")
    print(f"  Scene.from_file().run() (in process, arrays)       {med(py_run) * 1e3:8.2f} ms")
    print(f"  scene.run().write(dir) (in process, same files)    {med(py_write) * 1e3:8.2f} ms")
    print(f"  of which the integration (summary wall_s)          {med(integ) * 1e3:8.2f} ms")

    # 2. a sweep of 8 points
    falling = chainsim.Scene.from_file(os.path.join(SOURCE, "cases", "scenes", "falling_chain.toml"))
    grid = {"f": [0.0, 0.25, 0.5, 1.0], "string.nodes": [101, 161]}
    tasks = [(falling.text, falling.source, falling.overrides, None, p)
             for p in chainsim._core.sweep_points([(k, [chainsim._toml_value(v) for v in vs]) for k, vs in grid.items()])]
    from dask.distributed import Client, LocalCluster
    cluster = LocalCluster(n_workers=2, threads_per_worker=1, dashboard_address=None)
    client = Client(cluster)
    client.gather(client.map(chainsim._scene_point, tasks[:2], pure=False))   # warm the workers
    pool1, pool2 = ProcessPoolExecutor(1), ProcessPoolExecutor(2)
    list(pool1.map(chainsim._scene_point, tasks[:1]))
    list(pool2.map(chainsim._scene_point, tasks[:2]))
    times = {"threads 1": [], "threads 2": [], "processes 1": [], "processes 2": [], "dask 2 workers": []}
    for k in range(max(3, args.rounds // 3)):
        times["threads 1"].append(timed(lambda: chainsim.sweep(falling, grid, workers=1))[0])
        times["threads 2"].append(timed(lambda: chainsim.sweep(falling, grid, workers=2))[0])
        times["processes 1"].append(timed(lambda: list(pool1.map(chainsim._scene_point, tasks)))[0])
        times["processes 2"].append(timed(lambda: list(pool2.map(chainsim._scene_point, tasks)))[0])
        times["dask 2 workers"].append(timed(lambda: chainsim.sweep(falling, grid, client=client))[0])
    overlap = [cpu_per_wall(lambda: chainsim.sweep(falling, grid, workers=2)) for _ in range(3)]
    client.close()
    cluster.close()
    base = med(times["threads 1"])
    print(f"\nsweep: falling_chain.toml, 8 points (f x nodes 101, 161, to the cutoff), {len(times['threads 1'])} "
          f"alternating rounds, medians")
    for name, ts in times.items():
        print(f"  {name:16s} {med(ts):7.3f} s   speed-up vs 1 thread {base / med(ts):5.2f}")
    print(f"  threads 2: CPU time of the process / wall time = {med(overlap):.2f} (median of 3; 2 = both cores "
          f"all the time)")
    print(f"load average after: {os.getloadavg()}")


if __name__ == "__main__":
    main()
