"""Reading a run directory of the command-line tool back into Python: `chainsim run` writes it, chainsim.read_run
reads its tables by column name, and the same scene run from Python gives the same numbers (the module runs
the same C++). Then the figures of `chainsim plot`, drawn from Python.

    PYTHONPATH=build/python:python /usr/bin/python3 examples/read_cli_run.py [--quick]
"""
import os
import subprocess

import numpy as np

import chainsim
from _common import SCENES, binary, out_dir, quick

out = out_dir("read_cli_run")
scene_file = os.path.join(SCENES, "whip_crack.toml")
t_end = "0.2" if quick() else "0.8"
run_dir = os.path.join(out, "whip_crack")
subprocess.run([binary(), "run", scene_file, "--out", run_dir, "--t-end", t_end, "--quiet"], check=True)

run = chainsim.read_run(run_dir)                      # the CLI's files, by column name
print(f"{run.kind} run: {len(run.t)} frames, status {run.summary['status']}, t_stop {run.summary['t_stop']} s")
energy = run.energy
print(f"energy ledger: max |drift| = {np.max(np.abs(energy['drift'])):.3e} J over {len(energy['t'])} frames")

result = chainsim.Scene.from_file(scene_file).run(t_end=float(t_end))   # the same scene from Python
assert np.array_equal(result.energy["drift"], energy["drift"]), "the module and the CLI differ"
tip = result.nodes["vx"][:, -1], result.nodes["vy"][:, -1]
print(f"the tip's top speed: {np.max(np.hypot(*tip)):.3f} m/s (identical arrays from the CLI's files and the module)")
for path in chainsim.plot(run_dir, times=None):
    print(path)
