"""Fit the dissipation f of a falling chain to its measured height and the force on the scale (docs/fit.md).

The data in examples/data/ are SYNTHETIC (made by scripts/make_fit_data.py: chainsim's reduced falling chain at
f = 0.83 plus Gaussian noise), imitating the set-up of Hamm & Géminard (Am. J. Phys. 78, 828, 2010): a 1 m chain
(0.1 kg/m) hanging with its lower end on a scale pan, released from rest at an unknown time of the recording. Put
your own CSV files (a header row, t in s, one column of values) in their place.

Fitted: f and the release time t_offset, jointly to the height of the top end (500 frames/s) and the force on the
pan (2,000 samples/s) of the one drop. The model is the reduced ODE (chainsim reduced falling). Writes fit.json,
fit_table.txt, fit_series.csv, fit.png and profile.png.

    PYTHONPATH=build/python:python /usr/bin/python3 examples/fit_falling_chain.py [--quick]
"""
import os

import chainsim
from _common import HERE, out_dir, quick

out = out_dir("fit_falling_chain")
data_dir = os.path.join(HERE, "data")
height = chainsim.Data.from_csv(os.path.join(data_dir, "falling_chain_height.csv"), run="drop")   # columns t, y
force = chainsim.Data.from_csv(os.path.join(data_dir, "falling_chain_force.csv"), run="drop")     # columns t, P
data = [height] if quick() else [height, force]

fit = chainsim.fit("falling", data,
                   free={"f": 0.5, "t_offset": (0.0, -0.1, 0.1)},      # start values; t_offset within +-0.1 s
                   fixed={"length": 1.0, "density": 0.1},              # the chain's length (m) and mass (kg/m)
                   profile_points=7 if quick() else 21)
print(fit.table())
for path in fit.write(out):
    print(path)

# The data are synthetic: the truth is known (scripts/make_fit_data.py), and the fit must find it.
for name, true in (("f", 0.83), ("t_offset", 0.030)):
    lo, hi = fit.interval[name]
    assert lo <= true <= hi, f"{name} = {true} is outside the 95% interval [{lo}, {hi}]"
lo, hi = fit.profile_interval["f"]
assert lo <= 0.83 <= hi
