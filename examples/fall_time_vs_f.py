"""The falling chain's fall time against the dissipation f, three ways, in one figure:
the exact quadrature (a curve), the reduced ODE (a sweep of chainsim.reduced) and the string solver with
front tracking (chainsim.compare, a discrete chain of N nodes). The straight falling chain is exact on any
mesh, so the three agree to the integrators' tolerances; the script prints the worst differences.

    PYTHONPATH=build/python:python /usr/bin/python3 examples/fall_time_vs_f.py [--quick]
"""
import os

import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

import chainsim  # noqa: E402
from _common import out_dir, quick  # noqa: E402

out = out_dir("fall_time_vs_f")
fs_curve = np.linspace(0.0, 1.0, 11 if quick() else 41)
fs_string = [0.0, 0.5, 1.0] if quick() else [0.0, 0.25, 0.5, 0.75, 1.0]
nodes = 11 if quick() else 41

reduced = chainsim.sweep("falling", {"f": fs_curve})            # the reduced ODE, with the quadrature's time
string = [chainsim.compare("falling", f=f, nodes=nodes).summary for f in fs_string]

print(f"{'f':>5} {'string t/t0':>16} {'reduced t/t0':>16} {'exact t/t0':>16}")
for f, s in zip(fs_string, string):
    row = reduced.iloc[int(np.argmin(abs(reduced.f - f)))]
    print(f"{f:5.2f} {s['t_stop_over_t0']:16.12f} {row.t_stop_over_t0:16.12f} {row.t_stop_over_t0_exact:16.12f}")
worst_reduced = float(np.max(abs(reduced.t_stop_over_t0 / reduced.t_stop_over_t0_exact - 1)))
worst_string = max(s["rel_err_t_stop"] for s in string)
print(f"reduced ODE vs quadrature: worst relative difference {worst_reduced:.2e}")
print(f"string solver ({nodes} nodes) vs reduced ODE: worst relative difference {worst_string:.2e}")
assert worst_reduced < 1e-8 and worst_string < 1e-8

fig, ax = plt.subplots(figsize=(6, 4))
ax.plot(reduced.f, reduced.t_stop_over_t0_exact, "k-", lw=1, label="exact (quadrature)")
ax.plot(reduced.f, reduced.t_stop_over_t0, "o", mfc="none", ms=6, label="reduced ODE")
ax.plot(fs_string, [s["t_stop_over_t0"] for s in string], "x", ms=8, mew=2, label=f"string solver, {nodes} nodes")
ax.set_xlabel("dissipation f")
ax.set_ylabel(r"fall time $t/t_0$ (to $\eta = \varepsilon$)")
ax.set_title(r"Falling chain onto a table, released at rest ($\eta_0 = 1$)")
ax.grid(alpha=0.3)
ax.legend()
fig.tight_layout()
path = os.path.join(out, "fall_time_vs_f.png")
fig.savefig(path, dpi=120)
print(path)
