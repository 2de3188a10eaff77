"""Makes the SYNTHETIC data set of the fit tutorial (docs/fit.md, examples/fit_falling_chain.py).

It imitates the set-up of Hamm & Géminard (Am. J. Phys. 78, 828, 2010): a chain hangs vertically, its lower end
just touching a scale pan, and is released from rest; it falls onto the pan. Two series of one drop are recorded:
the height of the chain's top end (as from a video) and the force on the pan (the scale). The numbers are ours,
chosen of a table-top experiment's size, not taken from their paper:

    chain      length 1.0 m (the drop height of the top end: 1.0 m above the pan, eta0 = 1), 0.1 kg/m, g = 9.81 m/s^2
    f          0.83 (the value Hamm & Géminard's measurements gave, the paper's gamma)
    release    at t = 0.030 s on the recording's clock (the recordings start before the release)
    height     500 frames/s, Gaussian noise of sigma = 1.5 mm
    force      2,000 samples/s, Gaussian noise of sigma = 0.02 N
    cut        both end when the top is 5 cm above the pan (the last 5 cm is a pile of links, not a string)

The values come from chainsim's reduced falling chain at its reference settings (erk8, rtol 1e-13), cubic-Hermite
interpolated at the sample times, plus noise from numpy's default generator with seed 2010.

    PYTHONPATH=build/python:python /usr/bin/python3 scripts/make_fit_data.py [OUT_DIR]   (default examples/data)
"""
import os
import sys

import numpy as np

import chainsim
from chainsim.fitting import _interpolate, _table

LENGTH, DENSITY, GRAVITY, F = 1.0, 0.1, 9.81, 0.83
RELEASE, CUT = 0.030, 0.05
SERIES = [("falling_chain_height.csv", "y", 500.0, 0.0015, "height of the top end above the pan (m)"),
          ("falling_chain_force.csv", "P", 2000.0, 0.02, "force on the pan (N)")]


def main(out_dir):
    os.makedirs(out_dir, exist_ok=True)
    run = chainsim.reduced("falling", f=F, length=LENGTH, density=DENSITY, gravity=GRAVITY)
    t_model, y_model = run.series["t"], run.series["y"]
    t_cut = RELEASE + float(np.interp(-CUT, -y_model, t_model))   # y decreases: the time it passes CUT
    rng = np.random.default_rng(2010)
    paths = []
    for name, observable, rate, sigma, meaning in SERIES:
        t = np.arange(0.0, t_cut, 1.0 / rate)
        exact = _interpolate(*_table(run, observable), t - RELEASE)
        values = exact + sigma * rng.standard_normal(len(t))
        path = os.path.join(out_dir, name)
        with open(path, "w") as f:
            f.write(f"# SYNTHETIC DATA, not a measurement: made by scripts/make_fit_data.py with chainsim's reduced\n"
                    f"# falling chain (f = {F}, length {LENGTH} m, {DENSITY} kg/m, g = {GRAVITY} m/s^2, released from "
                    f"rest at t = {RELEASE} s\n# with its lower end on the pan), imitating the set-up of Hamm & "
                    f"Geminard, Am. J. Phys. 78, 828 (2010).\n# {observable}: {meaning}; {rate:g} samples/s; "
                    f"Gaussian noise sigma = {sigma}; t in s.\n")
            f.write(f"t,{observable}\n")
            for ti, vi in zip(t, values):
                f.write(f"{ti:.6f},{vi:.6f}\n")
        paths.append(path)
        print(os.path.normpath(path), len(t), "points")
    return paths


if __name__ == "__main__":
    main(sys.argv[1] if len(sys.argv) > 1 else os.path.join(os.path.dirname(os.path.abspath(__file__)), "..",
                                                             "examples", "data"))
