"""The figure defects of issue 25, each measured on the drawn figure (not on the code that draws it):
the fall-time legend hides no curve, the agreement figure does not put the energy ledger beside the stop-time
bound, a snapshot figure's last colour is visible on white and its axis fits the chain, a constant front speed
shows no offset notation, and a tension map keeps its colours when a little slack or a spike is present.

    CHAINSIM_PLOT_PYTHON=python /usr/bin/python3 -m pytest -q tests/python/test_figures.py
"""
import os
import sys

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.environ.get("CHAINSIM_PLOT_PYTHON", os.path.join(HERE, "..", "..", "python")))

import matplotlib  # noqa: E402

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
from matplotlib.colors import to_rgb  # noqa: E402

from chainsim_plot import canonical, figures  # noqa: E402


class Table(dict):
    """Enough of readers.Table for the figure functions: columns by name, len() the rows."""

    def __len__(self):
        return len(next(iter(self.values())))

    @property
    def columns(self):
        return list(self)


def kept(monkeypatch):
    """Makes save() hand back the figure instead of writing it."""
    out = []
    monkeypatch.setattr(canonical, "save", lambda fig, *a, **k: out.append(fig) or fig)
    return out


def fall_times():
    f = np.linspace(0, 1, 21)
    d = Table(f=f)
    # the sliding chain's three starts (tf/t0 as in the paper's Fig. 5b), the others arbitrary but smooth
    for key, base in (("falling", 0.75), ("folded", 1.2), ("sliding0", 1.73), ("sliding25", 1.08),
                      ("sliding75", 0.52)):
        slope = 0.5 if key == "sliding0" else 0.2 if key == "sliding25" else 0.03 if key == "sliding75" else 0.25
        d[key + "_exact"] = base + slope * f
        d[key + "_ode"] = base + slope * f
    fs = np.linspace(0, 1, 11)
    s = Table(f=fs, falling_string=0.75 + 0.25 * fs, folded_string=1.2 + 0.25 * fs, sliding0_string=1.73 + 0.5 * fs)
    return d, s


def test_fall_time_legend_covers_no_point_of_any_curve(monkeypatch):
    figs = kept(monkeypatch)
    canonical.fall_time_figure(fall_times(), "unused")
    fig = figs[0]
    fig.canvas.draw()
    renderer = fig.canvas.get_renderer()
    for ax in fig.axes:
        box = ax.get_legend().get_window_extent(renderer)
        for line in ax.get_lines():
            xy = ax.transData.transform(np.column_stack(line.get_data()))
            inside = box.contains_points(xy) if hasattr(box, "contains_points") else \
                [(box.x0 <= x <= box.x1 and box.y0 <= y <= box.y1) for x, y in xy]
            assert not np.any(inside), f"{ax.get_title()}: the legend hides points of {line.get_label()}"
    plt.close(fig)


def agreement_rows():
    rows = []
    for problem in ("falling", "folded", "sliding"):
        for f in (0.0, 0.5, 0.83, 1.0):
            rows.append(dict(problem=problem, f=f, nodes=41, rel_diff_string_reduced=2e-12,
                             rel_diff_reduced_quadrature=6e-14, rel_diff_string_quadrature=2e-12,
                             energy_residual_string=2e-8 if (problem, f) == ("folded", 0.0) else 1e-10))
    return rows


def test_agreement_energy_ledger_is_not_drawn_against_the_stop_time_bound(monkeypatch):
    figs = kept(monkeypatch)
    canonical.agreement_figure(agreement_rows(), "unused")
    fig = figs[0]
    for ax in fig.axes:
        labels = [line.get_label() for line in ax.get_lines()]
        texts = " ".join(t.get_text() for t in ax.texts)
        if any("energy ledger" in label for label in labels):
            assert "string vs ODE" not in texts, "the ledger's squares share an axis with the stop-time bound"
            # the folded f = 0 residual, 2e-8, lies below the bound drawn on its axis
            bounds = [line.get_ydata()[0] for line in ax.get_lines() if line.get_linestyle() == "--"]
            assert bounds and all(b > 2e-8 for b in bounds)
    plt.close(fig)


def luminance(color):
    r, g, b = to_rgb(color)
    return 0.2126 * r + 0.7152 * g + 0.0722 * b


def test_time_colors_end_visible_on_white():
    colors = figures.time_colors(7)
    assert max(luminance(c) for c in colors) < 0.75  # viridis's yellow end is 0.87: hardly visible on white


def test_snapshot_times_are_spread_evenly():
    times = np.r_[np.arange(0, 0.36, 0.005), 0.3612, 0.3624]  # frames, then the stop just after the last one
    picks = figures.choose_times(times, count=6)
    gaps = np.diff(times[picks])
    assert gaps.min() > 0.5 * gaps.max(), f"snapshots at {times[picks]}: two nearly the same"


def test_fronts_constant_speed_shows_no_offset_and_no_round_off():
    fig, ax = plt.subplots()
    t = np.linspace(0, 1, 200)
    speed = -1.0 + 1e-13 * np.sin(40 * t)  # a front moving at -1 m/s, to round-off
    ax.plot(t, speed)
    figures.plain_axis(ax, speed)
    fig.canvas.draw()
    assert ax.yaxis.get_offset_text().get_text() == ""
    lo, hi = ax.get_ylim()
    assert hi - lo > 0.01, f"the axis spans {hi - lo:g}: round-off drawn as an oscillation"
    plt.close(fig)


def test_tension_map_keeps_its_colours_with_a_little_slack_and_a_spike():
    s = np.linspace(0, 1, 40)
    times = np.linspace(0, 0.5, 51)
    grid = np.outer(np.ones_like(times), 1.0 - s) * 0.8  # tension 0 .. 0.8 N over most of the run
    grid[45, :4] = 3.5      # a short, local spike (the whip)
    grid[:, -1] = -0.02     # a little slack at the tip
    fig, ax = plt.subplots()
    mesh, neg, clipped = figures.tension_map(ax, s, times, grid)
    assert neg and clipped
    # the typical tension (the median of the positive values) is far from the scale's middle (white)
    typical = np.median(grid[grid > 0])
    assert mesh.norm(typical) > 0.75, f"the median tension maps to {mesh.norm(typical):.2f}: washed out"
    assert mesh.norm(-0.02) < 0.1  # the slack is clearly blue
    plt.close(fig)


def test_tension_map_round_off_below_zero_is_not_slack():
    s = np.linspace(0, 1, 10)
    times = np.linspace(0, 1, 5)
    grid = np.outer(np.ones_like(times), 1.0 - s)
    grid[:, -1] = -1e-12
    fig, ax = plt.subplots()
    _, neg, _ = figures.tension_map(ax, s, times, grid)
    assert not neg
    plt.close(fig)
