#!/usr/bin/python3
"""Figures of docs/stability.md, from runs of build/chainsim.

Usage: /usr/bin/python3 scripts/plot_stability.py [FIGURE_DIR]   (default docs/figures)
Runs the reduced models at their smallest allowed cutoffs, a 1000-period hanging chain, a pulled fold
and a string pushed at an end (work files in a temporary directory), and writes
  stability_power_laws.png   speed and P/P0 up to the cutoff against the exact laws, and their errors
  stability_ledger.png       energy-ledger residuals over long runs
  stability_slack.png        slack detection at a pushed end against the rigid-motion tension
Needs Debian's python3-matplotlib and a built build/chainsim.
"""
import csv
import json
import math
import os
import subprocess
import sys
import tempfile

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
CHAINSIM = os.path.join(ROOT, "build", "chainsim")


def read(path):
    with open(path, newline="") as fh:
        rows = list(csv.DictReader(fh))
    return {k: [float(r[k]) for r in rows] for k in rows[0]}


def chainsim(*args, check=True):
    return subprocess.run([CHAINSIM, *args], check=check, capture_output=True, text=True)


def smallest_cutoff(problem, f):
    """The smallest --eps the reduced command accepts, read from its refusal of eps = 1e-15."""
    err = chainsim("reduced", problem, "--f", str(f), "--eps", "1e-15", "--out", os.devnull, check=False).stderr
    return float(err.split("allowed ")[1].split(" <=")[0])


def power_laws(work, out):
    fig, axes = plt.subplots(2, 2, figsize=(11, 7.5))
    for col, problem in enumerate(["falling", "folded"]):
        for f in [0.0, 0.1, 0.5]:
            eps = smallest_cutoff(problem, f)
            d = os.path.join(work, f"{problem}_{f}")
            chainsim("reduced", problem, "--f", str(f), "--eps", repr(eps), "--out", d)
            s = read(os.path.join(d, "series.csv"))
            eta, etap, P = s["eta"][1:], s["eta_p"][1:], s["P_over_P0"][1:]
            if problem == "falling":  # eta0 = 1: distance to the end is eta
                dist = eta
                sp2 = [4 / (3 - 2 * f) * (e ** (2 * f - 2) - e) for e in eta]
                Pe = [0.5 * f * v + 1 - e for v, e in zip(sp2, eta)]
                law = [4 / (3 - 2 * f) * x ** (2 * f - 2) for x in dist]
            else:  # eta0 = 0: distance to the end is 1 - eta
                dist = [1 - e for e in eta]
                sp2 = [2 / (2 - f) * (z ** (f - 1) - z) for z in dist]
                Pe = [0.5 * (1 + f) * v + e for v, e in zip(sp2, eta)]
                law = [2 / (2 - f) * z ** (f - 1) for z in dist]
            keep = [i for i, x in enumerate(dist) if 0 < x < 0.5]  # the approach to the singular end
            x = [dist[i] for i in keep]
            ax = axes[0][col]
            line, = ax.loglog(x, [etap[i] ** 2 for i in keep], "-", lw=1.5, label=f"ODE $f={f:g}$, $\\varepsilon={eps:.2g}$")
            ax.loglog(x, [law[i] for i in keep], "k:", lw=1,
                      label=f"leading power law $\\propto x^{{{2 * f - 2 if problem == 'falling' else f - 1:g}}}$")
            ax2 = axes[1][col]
            floor = 1e-17  # exact agreement (e.g. P = 1 − η for f = 0) is drawn at this floor
            ax2.loglog(x, [max(abs(P[i] - Pe[i]) / max(abs(Pe[i]), 1), floor) for i in keep], "-",
                       color=line.get_color(), label=f"$P/P_0$, $f={f:g}$")
            ax2.loglog(x, [max(abs(etap[i] ** 2 - sp2[i]) / max(sp2[i], 1), floor) for i in keep], "--",
                       color=line.get_color(), lw=0.8, label=f"$\\eta'^2$, $f={f:g}$")
        xlab = "$\\eta$ (height left)" if problem == "falling" else "$1-\\eta$ (free arm left)"
        axes[0][col].set_title(f"{problem} chain: squared speed $\\eta'^2$ up to the cutoff")
        axes[0][col].set_xlabel(xlab)
        axes[0][col].set_ylabel("$\\eta'^2$")
        axes[0][col].invert_xaxis()
        axes[0][col].legend(fontsize=7)
        axes[0][col].grid(alpha=0.3, which="both")
        ax2 = axes[1][col]
        if problem == "folded":
            z = [10 ** (-k / 4) for k in range(4, 40)]
            ax2.loglog(z, [1.1e-16 / v for v in z], "k:", lw=1, label="round-off of $1-\\eta$: $10^{-16}/(1-\\eta)$")
        ax2.set_title(f"{problem} chain: error against the exact first integral")
        ax2.set_xlabel(xlab)
        ax2.set_ylabel("error / max(|exact|, 1)")
        ax2.invert_xaxis()
        ax2.legend(fontsize=7)
        ax2.grid(alpha=0.3, which="both")
    fig.tight_layout()
    fig.savefig(os.path.join(out, "stability_power_laws.png"), dpi=120)
    plt.close(fig)


SMALL_CHAIN = """[string]
length = 1.0
density = 0.1
nodes = 7
[shape]
kind = "polyline"
points = [[0.0, 0.0], [0.0099998, -0.99995]]
[ends]
start = "fixed"
[effects.gravity]
g = [0.0, -9.81]
[solver]
rtol = 1e-10
atol = 1e-12
[output]
interval = {interval}
fields = ["energy", "stats"]
formats = ["csv"]
[stop]
t_end = {t_end}
"""


def ledger(work, out):
    period = 2 * math.pi / (1.2024 * math.sqrt(9.81))
    scene = os.path.join(work, "small_chain.toml")
    with open(scene, "w") as fh:
        fh.write(SMALL_CHAIN.format(interval=repr(2 * period), t_end=repr(1000 * period)))
    d = os.path.join(work, "small_chain")
    chainsim("run", scene, "--out", d)
    e = read(os.path.join(d, "energy.csv"))
    stats = json.load(open(os.path.join(d, "stats.json")))
    scale = stats["energy_scale"]
    fig, (a1, a2) = plt.subplots(1, 2, figsize=(11, 4))
    a1.semilogy([t / period for t in e["t"][1:]], [abs(v) / scale for v in e["drift"][1:]], "-")
    a1.set_xlabel("periods of the first mode")
    a1.set_ylabel("|drift| / energy scale")
    a1.set_title("6-link hanging chain, 1000 periods (erk8, rtol $10^{-10}$)")
    a1.grid(alpha=0.3, which="both")
    d2 = os.path.join(work, "pulled_fold")
    chainsim("reduced", "folded", "--f", "0.5", "--force", "6", "--out", d2)
    s = read(os.path.join(d2, "series.csv"))
    summary = json.load(open(os.path.join(d2, "summary.json")))
    escale = max(abs(k) + abs(v) + abs(a) + abs(b) + abs(c) for k, v, a, b, c in
                 zip(s["K"], s["V"], s["E_shock"], s["E_heap"], s["E_force"]))
    a2.semilogy(s["xi"][1:], [max(abs(v) / escale, 1e-18) for v in s["ledger"][1:]], "-", lw=0.6)
    a2.set_xlabel("$t/t_0$")
    a2.set_ylabel("|ledger| / energy scale")
    a2.set_title(f"pulled fold, $f=0.5$, $F=6$ N, {summary['turning_points']} turning points (rtol $10^{{-13}}$)")
    a2.grid(alpha=0.3, which="both")
    fig.tight_layout()
    fig.savefig(os.path.join(out, "stability_ledger.png"), dpi=120)
    plt.close(fig)


PUSHED = """[string]
length = 1.0
density = 0.1
nodes = 21
[shape]
kind = "polyline"
points = [[0.0, 0.0], [1.0, 0.0]]
[velocity]
kind = "uniform"
value = [{v}, 0.0]
[ends]
start = {{ kind = "driven", path = "sine", amplitude = [{A}, 0.0], omega = {w} }}
[solver]
check_slack = true
max_step = 1e-4
[output]
interval = 0.01
fields = ["tension", "stats"]
formats = ["csv"]
[stop]
t_end = 2.0
"""


def slack(work, out):
    A, w = 0.1, 5.0
    scene = os.path.join(work, "pushed.toml")
    with open(scene, "w") as fh:
        fh.write(PUSHED.format(v=A * w, A=A, w=w))
    d = os.path.join(work, "pushed")
    run = chainsim("run", scene, "--out", d, "--json", check=False)
    summary = json.loads(run.stdout)
    t_fail = summary["t_stop"] if "t_stop" in summary else summary["t_end"]
    T = read(os.path.join(d, "tension.csv"))
    t0 = [t for t, j in zip(T["t"], T["link"]) if j == 0]
    T0 = [v for v, j in zip(T["T"], T["link"]) if j == 0]
    beyond = 0.1 * (1 - 0.5 / 20)
    tt = [k * 0.7 / 400 for k in range(401)]
    fig, ax = plt.subplots(figsize=(7, 4))
    ax.plot(tt, [beyond * A * w * w * math.sin(w * t) for t in tt], "-", label="rigid motion: $m^+A\\omega^2\\sin\\omega t$")
    ax.plot(t0, T0, "o", ms=3, label="string solver, link 0")
    ax.axvline(math.pi / w, color="k", ls=":", label="$t^*=\\pi/\\omega$ (the end starts to push)")
    ax.axvline(t_fail, color="r", ls="--", lw=0.8, label=f"slack detected, t = {t_fail:.6f} s")
    ax.axhline(0, color="grey", lw=0.5)
    ax.set_xlabel("t (s)")
    ax.set_ylabel("tension of link 0 (N)")
    ax.set_title("a string driven along itself by $x_0+A\\sin\\omega t$, no gravity")
    ax.legend(fontsize=8)
    ax.grid(alpha=0.3)
    fig.tight_layout()
    fig.savefig(os.path.join(out, "stability_slack.png"), dpi=120)
    plt.close(fig)
    print(f"slack: t* = {math.pi / w:.6f} s, detected at {t_fail:.6f} s: {summary.get('error', '')[:120]}")


def main():
    out = sys.argv[1] if len(sys.argv) > 1 else os.path.join(ROOT, "docs", "figures")
    os.makedirs(out, exist_ok=True)
    with tempfile.TemporaryDirectory() as work:
        power_laws(work, out)
        ledger(work, out)
        slack(work, out)
    print(f"wrote {out}/stability_{{power_laws,ledger,slack}}.png")


if __name__ == "__main__":
    main()
