"""Where the time of a fit goes (docs/fit.md, "Why SciPy"): the model runs against the optimizer's own work.

Fits the tutorial's synthetic drop (examples/data/) twice: with the reduced ODE (f and t_offset, height and force,
1,120 points) and with the string solver (cases/scenes/falling_chain.toml, 41 nodes, the height only). Each fit
runs under cProfile; the time inside chainsim.fitting._predict (one model run and its interpolation at the data
times, of which summary["wall_s"] is the integration itself) is compared with the whole fit, profile included.

    PYTHONPATH=build/python:python /usr/bin/python3 scripts/bench_fit.py
"""
import cProfile
import os
import pstats
import time

import chainsim
from chainsim import fitting

SOURCE = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..")
DATA = os.path.join(SOURCE, "examples", "data")

integration = []
_run_model = fitting._run_model


def timed_run_model(target, settings):
    result = _run_model(target, settings)
    integration.append(result.summary["wall_s"])
    return result


fitting._run_model = timed_run_model
height = chainsim.Data.from_csv(os.path.join(DATA, "falling_chain_height.csv"), run="drop")
force = chainsim.Data.from_csv(os.path.join(DATA, "falling_chain_force.csv"), run="drop")
scene = chainsim.Scene.from_file(os.path.join(SOURCE, "cases", "scenes", "falling_chain.toml"))
cases = [
    ("reduced ODE, height + force", lambda: chainsim.fit("falling", [height, force], {"f": 0.5, "t_offset": (0, -.1, .1)},
                                                         fixed={"length": 1.0, "density": 0.1}, workers=1)),
    ("string solver, 41 nodes, height", lambda: chainsim.fit(
        scene, chainsim.Data.from_csv(os.path.join(DATA, "falling_chain_height.csv"), observable="s0_0", column="y"),
        {"f": 0.5, "t_offset": (0, -.1, .1)}, fixed={"string.density": 0.1, "string.nodes": 41}, workers=1)),
]
print(f"{'fit':<34} {'runs':>5} {'wall s':>7} {'in model runs':>14} {'integration':>12} {'per run ms':>11}")
for name, run in cases:
    integration.clear()
    profiler = cProfile.Profile()
    start = time.perf_counter()
    profiler.enable()
    fit = run()
    profiler.disable()
    wall = time.perf_counter() - start
    stats = pstats.Stats(profiler)
    predict = next(v[3] for k, v in stats.stats.items() if k[2] == "_predict")
    print(f"{name:<34} {fit.evaluations:>5} {wall:>7.2f} {predict / wall:>13.1%} {sum(integration) / wall:>11.1%} "
          f"{1e3 * predict / max(fit.evaluations, 1):>11.2f}")
