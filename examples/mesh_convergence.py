"""Mesh convergence of a general scene, one with no reduced model: the chain released curved onto a table
(cases/scenes/curved_falling_chain.toml). The heap's front position s0 at a fixed time is computed on
meshes of N = 21, 41, 81, 161 nodes (a sweep over string.nodes); the differences between successive meshes
give the observed order of convergence, log2(|d_k| / |d_{k+1}|).

    PYTHONPATH=build/python:python /usr/bin/python3 examples/mesh_convergence.py [--quick]
"""
import math
import os

import chainsim
from _common import SCENES, out_dir, quick

out = out_dir("mesh_convergence")
nodes = [11, 21, 41] if quick() else [21, 41, 81, 161]
t = 0.15 if quick() else 0.3
scene = chainsim.Scene.from_file(os.path.join(SCENES, "curved_falling_chain.toml"))
df = chainsim.sweep(scene, {"string.nodes": nodes}, t_end=t)
df.to_csv(os.path.join(out, "mesh_convergence.csv"), index=False)
assert (df.status == "completed").all(), df[["status", "error"]]

s0 = df["fronts_final_s0.heap_end"].to_numpy()
print(f"s0 of the heap's front at t = {t} s (m); its change between meshes; observed order")
diffs = [s0[k + 1] - s0[k] for k in range(len(s0) - 1)]
for k, n in enumerate(nodes):
    line = f"  N = {n:4d}  s0 = {s0[k]:.12f}"
    if k > 0:
        line += f"  d = {diffs[k - 1]: .3e}"
    if k > 1 and diffs[k - 1] != 0:
        line += f"  order {math.log2(abs(diffs[k - 2] / diffs[k - 1])):.2f}"
    print(line + f"  (wall {df.wall_time_s[k]:.2f} s, ledger {df.relative_energy_drift[k]:.1e})")
