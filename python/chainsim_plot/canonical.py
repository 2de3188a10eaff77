"""The paper's figures from the data of `chainsim canonical --out DIR` (DIR/figure_data/).

Solid lines: the reduced ODE integrated by ARKODE; markers / dashed lines: the exact quadratures
(cases/reduced/exact_solutions). `paper_figures(DIR, OUT)` writes OUT/fall_time_vs_f.png and
OUT/{falling,folded,sliding}_chain.png.
"""
import os

import numpy as np

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

from .readers import RunError, read_table  # noqa: E402


def read(path):
    table = read_table(path)
    if table is None:
        raise RunError(f"{path}: missing (written by `chainsim canonical`)")
    return table


def curve_pair(data_dir, problem, f):
    stem = os.path.join(data_dir, f"{problem}_f{f:.2f}")
    return read(stem + "_ode.csv"), read(stem + "_exact.csv")


def fall_time_figure(data_dir, out_dir):
    d = read(os.path.join(data_dir, "fall_time_vs_f.csv"))
    fig, axes = plt.subplots(1, 3, figsize=(13, 3.8))
    panels = [
        ("(a) falling chain, $\\eta_0=1$", [("falling", "")]),
        ("(b) folded chain, $\\eta_0=0$", [("folded", "")]),
        ("(c) sliding chain", [("sliding0", "$\\eta_0=0$"), ("sliding25", "$\\eta_0=0.25$"),
                               ("sliding75", "$\\eta_0=0.75$")]),
    ]
    for ax, (title, series) in zip(axes, panels):
        for key, label in series:
            line, = ax.plot(d["f"], d[key + "_exact"], "-", label=f"quadrature {label}")
            ax.plot(d["f"], d[key + "_ode"], "o", ms=3.5, color=line.get_color(),
                    label=f"ODE ($\\varepsilon=10^{{-6}}$) {label}")
        ax.set_xlabel("$f$")
        ax.set_ylabel("$t_f/t_0$")
        ax.set_title(title)
        ax.grid(alpha=0.3)
        ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(os.path.join(out_dir, "fall_time_vs_f.png"), dpi=130)
    plt.close(fig)


def problem_figure(data_dir, out_dir, problem, f_eta, f_P, logP, title):
    fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(11, 4))
    for f in f_eta:
        ode, ref = curve_pair(data_dir, problem, f)
        line, = ax1.plot(ode["xi"], ode["eta"], "-", label=f"ODE $f={f:g}$")
        ax1.plot(ref["xi"][::12], ref["eta"][::12], "o", ms=3, mfc="none", color=line.get_color(),
                 label=f"quadrature $f={f:g}$")
    ax1.set_xlabel("$t/t_0$")
    ax1.set_ylabel("$y/\\ell$")
    ax1.grid(alpha=0.3)
    ax1.legend(fontsize=7)
    # The paper draws the folded chain's weight as ln(1 + P/P0) (its caption: P_f = 3 P0 <-> ln 4).
    transform = np.log1p if logP else (lambda p: p)
    for f in f_P:
        ode, ref = curve_pair(data_dir, problem, f)
        line, = ax2.plot(ode["xi"], transform(ode["P_over_P0"]), "-", label=f"ODE $f={f:g}$")
        ax2.plot(ref["xi"][::12], transform(ref["P_over_P0"][::12]), "o", ms=3, mfc="none",
                 color=line.get_color(), label=f"quadrature $f={f:g}$")
    ax2.set_xlabel("$t/t_0$")
    ax2.set_ylabel("$\\ln(1+P/P_0)$" if logP else "$P/P_0$")
    ax2.grid(alpha=0.3, which="both")
    ax2.legend(fontsize=7)
    fig.suptitle(title)
    fig.tight_layout()
    fig.savefig(os.path.join(out_dir, f"{problem}_chain.png"), dpi=130)
    plt.close(fig)


def paper_figures(root, out_dir):
    data_dir = os.path.join(root, "figure_data")
    os.makedirs(out_dir, exist_ok=True)
    fall_time_figure(data_dir, out_dir)
    problem_figure(data_dir, out_dir, "falling", [1.0, 0.5, 0.0], [0.0, 0.75, 0.85, 0.95, 1.0], False,
                   "Falling chain, $\\eta_0=1$, stop at $\\eta=\\varepsilon=0.01$")
    problem_figure(data_dir, out_dir, "folded", [0.0, 0.5, 1.0], [0.0, 0.5, 0.75, 1.0], True,
                   "Folded chain, $\\eta_0=0$, $F=0$, stop at $\\eta=1-\\varepsilon$")
    problem_figure(data_dir, out_dir, "sliding", [0.0, 0.5, 1.0], [0.0, 0.5, 1.0], False,
                   "Sliding chain, $\\eta_0=0.25$, stop at $\\eta=1$")
    return [os.path.join(out_dir, name) for name in
            ("fall_time_vs_f.png", "falling_chain.png", "folded_chain.png", "sliding_chain.png")]
