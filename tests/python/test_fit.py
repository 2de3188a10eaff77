"""chainsim.fit and `chainsim fit` (docs/fit.md): statistical validation on synthetic data of known f, agreement of
the reduced and the string model, and the located errors of bad data.

Synthetic data: the falling chain (reduced ODE at its default, tight settings: erk8, rtol 1e-13, steps of t0/500)
at a known f, sampled at N times, plus Gaussian noise of a stated standard deviation from a seeded generator. The
fits use other numerics (rtol 1e-10, no step limit), so the model of the fit is not the generator of the data.

Run by CTest with PYTHONPATH=build/python:python and CHAINSIM_BINARY set:
    PYTHONPATH=build/python:python CHAINSIM_BINARY=build/chainsim /usr/bin/python3 -m pytest tests/python/test_fit.py
CHAINSIM_FIT_REPLICATES=1000 CHAINSIM_FIT_TOLERANCE=0.02 runs the long coverage test (CHAINSIM_LONG_TESTS).
"""
import json
import math
import os
import subprocess
from concurrent.futures import ThreadPoolExecutor

import numpy as np
import pytest

import chainsim
from chainsim.fitting import _interpolate, _table

HERE = os.path.dirname(os.path.abspath(__file__))
SOURCE = os.path.abspath(os.path.join(HERE, "..", ".."))
BINARY = os.environ.get("CHAINSIM_BINARY", os.path.join(SOURCE, "build", "chainsim"))
SCENES = os.path.join(SOURCE, "cases", "scenes")

F_TRUE = 0.7
FAST = {"max_step": 1.0, "rtol": 1e-10, "atol": 1e-12}   # the fits' reduced ODE: quick, 1e-10 accurate


def truth(observable="y", f=F_TRUE, n=50, fraction=0.9, **kw):
    """(t, exact values) of the reduced falling chain at its reference settings, n times up to fraction*t_stop."""
    r = chainsim.reduced("falling", f=f, **kw)
    t = np.linspace(0.0, fraction * r.summary["t_stop"], n)
    return t, _interpolate(*_table(r, observable), t)


def noisy(t, y, sigma, seed, observable="y", **kw):
    rng = np.random.default_rng(seed)
    return chainsim.Data(t, y + sigma * rng.standard_normal(len(t)), observable, **kw)


def write_csv(path, header, rows, comment=None):
    with open(path, "w") as f:
        if comment:
            f.write(f"# {comment}\n")
        f.write(",".join(header) + "\n")
        for row in rows:
            f.write(",".join(str(v) for v in row) + "\n")
    return str(path)


# ------------------------------------------------------------------------------------------------------------------
# Recovery, coverage, linear agreement

def test_f_and_a_time_offset_are_recovered_within_their_intervals():
    t, y = truth(n=80)
    t_offset = 0.0123   # the release on the data's clock
    data = noisy(t + t_offset, y, 0.005, seed=11)
    fit = chainsim.fit("falling", data, {"f": 0.5, "t_offset": (0.0, -0.05, 0.05)}, fixed=FAST)
    for name, true in (("f", F_TRUE), ("t_offset", t_offset)):
        lo, hi = fit.interval[name]
        assert lo <= true <= hi, (name, fit.value[name], fit.interval[name])
    plo, phi = fit.profile_interval["f"]
    assert plo <= F_TRUE <= phi
    # the noise estimate recovers the stated 5 mm (chi-square with 78 dof: relative sd 8%)
    assert fit.series[0]["noise"] == pytest.approx(0.005, rel=0.25)
    assert fit.points == 80 and fit.dof == 78 and not fit.on_bound


def _replicate(seed, t, y, sigma):
    fit = chainsim.fit("falling", noisy(t, y, sigma, seed), {"f": 0.5}, fixed=FAST, profile_points=0, workers=1)
    return fit.value["f"], fit.sd["f"], fit.interval["f"], fit.profile_interval["f"]


def test_the_95_percent_intervals_cover_the_true_f_in_95_percent_of_replicates():
    """Seeded replicates of 50 points with sigma = 1 cm (1% of the chain's length): the covariance and the profile
    intervals cover f = 0.7 in 95% +- 4.5% of 200 replicates (binomial sd 1.5%); the estimates are unbiased and
    their scatter is the reported sd."""
    replicates = int(os.environ.get("CHAINSIM_FIT_REPLICATES", "200"))
    tolerance = float(os.environ.get("CHAINSIM_FIT_TOLERANCE", "0.045"))
    t, y = truth(n=50)
    sigma = 0.01
    with ThreadPoolExecutor(max_workers=2) as pool:
        out = list(pool.map(lambda s: _replicate(s, t, y, sigma), range(1000, 1000 + replicates)))
    values = np.array([o[0] for o in out])
    sds = np.array([o[1] for o in out])
    cover_cov = np.mean([lo <= F_TRUE <= hi for _, _, (lo, hi), _ in out])
    cover_prof = np.mean([lo <= F_TRUE <= hi for _, _, _, (lo, hi) in out])
    print(f"{replicates} replicates: covariance covers {cover_cov:.3f}, profile {cover_prof:.3f}, "
          f"mean f {values.mean():.5f}, scatter {values.std(ddof=1):.5f}, median sd {np.median(sds):.5f}")
    assert abs(cover_cov - 0.95) <= tolerance
    assert abs(cover_prof - 0.95) <= tolerance
    assert abs(values.mean() - F_TRUE) < 3 * values.std(ddof=1) / math.sqrt(replicates)
    # the relative sd of a sample sd is 1/sqrt(2(n-1)): 5% for 200 replicates; allow 3 of them
    assert values.std(ddof=1) == pytest.approx(np.median(sds), rel=3 / math.sqrt(2 * (replicates - 1)))


def test_profile_and_covariance_intervals_agree_where_the_problem_is_nearly_linear():
    t, y = truth(n=60)
    fit = chainsim.fit("falling", noisy(t, y, 1e-4, seed=5), {"f": 0.5, "t_offset": (0.0, -0.05, 0.05)},
                       fixed=FAST, profile_points=0)
    (clo, chi), (plo, phi) = fit.interval["f"], fit.profile_interval["f"]
    width = chi - clo
    assert abs(plo - clo) < 0.02 * width and abs(phi - chi) < 0.02 * width, (fit.interval, fit.profile_interval)
    # and where it is not (a large noise), the profile is asymmetric about the estimate while the covariance is not
    wide = chainsim.fit("falling", noisy(t, y, 0.05, seed=5), {"f": 0.5}, fixed=FAST, profile_points=0)
    plo, phi = wide.profile_interval["f"]
    v = wide.value["f"]
    assert abs((phi - v) - (v - plo)) > 0.01 * (phi - plo)


def test_the_reduced_and_the_string_model_fit_the_same_data_alike():
    """The height of the falling chain's top: y of the reduced ODE, s0_0 (the heap front's material coordinate, the
    length still above the table) of the string solver with front tracking (21 nodes: the straight fall is exact on
    any mesh)."""
    t, y = truth(n=40, fraction=0.85)
    rng = np.random.default_rng(3)
    values = y + 0.004 * rng.standard_normal(len(t))
    reduced = chainsim.fit("falling", chainsim.Data(t, values, "y"), {"f": 0.5}, fixed=FAST, profile_points=0)
    scene = chainsim.Scene.from_file(os.path.join(SCENES, "falling_chain.toml"))
    string = chainsim.fit(scene, chainsim.Data(t, values, "s0_0"), {"f": 0.5},
                          fixed={"string.nodes": 21, "output.interval": 0.1}, profile_points=0)
    for fit in (reduced, string):
        lo, hi = fit.interval["f"]
        assert lo <= F_TRUE <= hi
    half = min(reduced.sd["f"], string.sd["f"]) * 1.96
    assert abs(reduced.value["f"] - string.value["f"]) < half
    # the two models agree to the string solver's tolerance (1e-9), and the fits to 1% of their intervals
    # (measured: 2.5e-5 apart, 1.2e-3 of the half-width: the string's series interpolated between its steps)
    assert abs(reduced.value["f"] - string.value["f"]) < 1e-2 * half
    assert string.sd["f"] == pytest.approx(reduced.sd["f"], rel=1e-2)


def test_any_scene_key_fitted_to_a_node_coordinate_on_the_string_solver():
    """A scene without fronts: the damped catenary released from its V shape, the drag coefficient (3/s) fitted to
    the height of its middle node (1 mm noise), with its profile."""
    scene = chainsim.Scene.from_file(os.path.join(SCENES, "damped_catenary.toml")).set(
        **{"string.nodes": 21, "stop.t_end": 1.0, "output.interval": 0.01})
    t = np.linspace(0.0, 1.0, 50)
    y = _interpolate(*_table(scene.set("effects.drag.coefficient", 3.0).run(), "node[10].y"), t)
    key = "effects.drag.coefficient"
    fit = chainsim.fit(scene, noisy(t, y, 0.001, seed=0, observable="node[10].y"), {key: (4.0, 0.1, 10.0)},
                       profile=key, profile_points=0)
    assert fit.interval[key][0] <= 3.0 <= fit.interval[key][1]
    assert fit.profile_interval[key][0] <= 3.0 <= fit.profile_interval[key][1]


def test_a_joint_fit_of_two_drops_shares_f_and_narrows_its_interval():
    """Two drops, from the full height and from eta0 = 0.6 (the chain held partly on the table), each released at
    its own time on the data's clock (t_offset per run)."""
    t1, y1 = truth(n=40)
    t2, y2 = truth(n=40, eta0=0.6)
    d1 = noisy(t1 + 0.01, y1, 0.005, seed=21, run="drop1")
    d2 = noisy(t2 + 0.03, y2, 0.005, seed=22, run="drop2", settings={"eta0": 0.6})
    free = {"f": 0.5, "t_offset": (0.0, -0.1, 0.1)}
    joint = chainsim.fit("falling", [d1, d2], free, per_run=["t_offset"], fixed=FAST, profile_points=0)
    assert joint.names == ["f", "t_offset[drop1]", "t_offset[drop2]"]
    assert joint.interval["f"][0] <= F_TRUE <= joint.interval["f"][1]
    assert joint.value["t_offset[drop1]"] == pytest.approx(0.01, abs=3 * joint.sd["t_offset[drop1]"])
    assert joint.value["t_offset[drop2]"] == pytest.approx(0.03, abs=3 * joint.sd["t_offset[drop2]"])
    single = [chainsim.fit("falling", d, free, fixed={**FAST, **d.settings}, profile=None) for d in (d1, d2)]
    assert joint.sd["f"] < min(s.sd["f"] for s in single)


def test_the_finite_differences_do_not_depend_on_their_step():
    """The derivatives of the force P (no time-derivative column) at steps 1e-4 and 1e-5 agree to 1e-3: the model's
    interpolation between its steps does not move with the parameters (linear interpolation: 1% apart)."""
    from chainsim.fitting import _Problem
    t, p = truth("P", n=200, fraction=0.95)
    problem = _Problem("falling", [chainsim.Data(t, p, "P")], {"f": F_TRUE, "t_offset": 0.0}, None, [], {}, 1, None)
    x = np.array([F_TRUE, 0.0])
    coarse, fine = problem.jacobian(x, 1e-4), problem.jacobian(x, 1e-5)
    assert np.linalg.norm(fine - coarse) < 1e-3 * np.linalg.norm(coarse)


def test_data_without_noise_are_fitted_exactly():
    """The model's own values (chi2 = 0): f exactly, a zero sd, no division by zero, JSON without NaN."""
    r = chainsim.reduced("falling", f=F_TRUE, **FAST)
    t = np.linspace(0.0, 0.35, 30)
    fit = chainsim.fit("falling", chainsim.Data(t, _interpolate(*_table(r, "y"), t), "y"), {"f": F_TRUE}, fixed=FAST,
                       profile_points=5)
    assert fit.value["f"] == F_TRUE and fit.chi2 == 0.0 and fit.sd["f"] == 0.0
    assert fit.interval["f"] == (F_TRUE, F_TRUE) and fit.profile_interval["f"] == (F_TRUE, F_TRUE)
    assert "NaN" not in json.dumps(fit.to_dict())


def test_a_stop_time_is_an_observable():
    """Ten measured fall times (to eta = eps) with 2 ms noise: f from t_stop alone."""
    t_stop = chainsim.reduced("falling", f=F_TRUE).summary["t_stop"]
    data = noisy(np.zeros(10), np.full(10, t_stop), 0.002, seed=8, observable="t_stop")
    fit = chainsim.fit("falling", data, {"f": 0.5}, fixed=FAST, profile_points=0)
    assert fit.interval["f"][0] <= F_TRUE <= fit.interval["f"][1]


def test_points_after_the_models_stop_are_reported_and_the_other_problems_fit():
    """Data past the landing: the model is held at its final state there, and the fit says so. The folded and the
    sliding chain (their y and the force P) recover f = 0.4 within their intervals."""
    t, y = truth(n=60, fraction=1.2)
    fit = chainsim.fit("falling", noisy(t, y, 0.003, seed=1), {"f": 0.5}, fixed=FAST, profile_points=0)
    assert any("10 points after the model's end" in w for w in fit.warnings), fit.warnings
    for problem, observable, eta0 in (("folded", "y", None), ("folded", "P", None), ("sliding", "y", 0.25),
                                      ("sliding", "P", 0.25)):
        r = chainsim.reduced(problem, f=0.4, eta0=eta0)
        t = np.linspace(0.0, 0.9 * r.summary["t_stop"], 60)
        y = _interpolate(*_table(r, observable), t)
        data = noisy(t, y, 0.003 * np.abs(y).max(), seed=1, observable=observable)
        # P has no time-derivative column: its spline through the steps needs the reduced ODE's default steps
        # (t0/500); with FAST's long steps its derivatives in f are noisy (docs/fit.md)
        fixed = dict(FAST if observable == "y" else {}, **({"eta0": eta0} if eta0 else {}))
        fit = chainsim.fit(problem, data, {"f": 0.5}, fixed=fixed, profile_points=0)
        assert fit.interval["f"][0] <= 0.4 <= fit.interval["f"][1], (problem, observable, fit)
        assert not fit.warnings


def test_a_fit_on_a_dask_client_gives_the_local_fit():
    pytest.importorskip("dask.distributed")
    from dask.distributed import Client, LocalCluster
    t, y = truth(n=30)
    data = noisy(t, y, 0.005, seed=2)
    local = chainsim.fit("falling", data, {"f": 0.5}, fixed=FAST, profile=None)
    with LocalCluster(n_workers=1, threads_per_worker=2, processes=True, dashboard_address=":0") as cluster, \
            Client(cluster) as client:
        remote = chainsim.fit("falling", data, {"f": 0.5}, fixed=FAST, profile=None, client=client)
    assert remote.value["f"] == local.value["f"]


def test_a_parameter_on_its_bound_is_reported():
    """Data of a chain slower than any f <= 1 allows (the clock stretched by 3%): f ends on its upper bound."""
    t, y = truth(f=1.0, n=40)
    fit = chainsim.fit("falling", noisy(t * 1.03, y, 0.002, seed=1), {"f": 0.5}, fixed=FAST, profile_points=0)
    assert fit.value["f"] == pytest.approx(1.0)
    assert fit.on_bound == {"f": "upper"}
    assert any("on its upper bound" in w for w in fit.warnings)
    assert fit.profile_interval["f"][1] == 1.0
    assert "on its upper bound" in fit.table()


# ------------------------------------------------------------------------------------------------------------------
# Bad data: located messages

def test_bad_csv_files_are_refused_with_the_file_line_column_and_value(tmp_path):
    cases = [
        ([("0.0", "1.0"), ("0.02", "0.99"), ("0.01", "0.98")], "unsorted.csv:5: column t = 0.01 is not after the "
         "previous time 0.02: allowed strictly increasing times"),
        ([("0.0", "1.0"), ("0.01", "nan"), ("0.02", "0.98")], "nan.csv:4: column y = nan is not a finite number"),
        ([("0.0", "1.0"), ("0.01", "abc")], "word.csv:4: column y = 'abc' is not a number"),
        ([("0.0", "1.0")], "one.csv: 1 data point: too few (allowed: at least 2 points"),
    ]
    for rows, message in cases:
        name = message.split(":")[0]
        path = write_csv(tmp_path / name, ["t", "y"], rows, comment="a comment line")
        with pytest.raises(chainsim.ChainsimInputError) as e:
            chainsim.Data.from_csv(path)
        assert message in str(e.value)
        assert str(tmp_path) in str(e.value)
    path = write_csv(tmp_path / "sigma.csv", ["t", "y", "sigma"], [(0, 1, 0.01), (0.01, 0.99, 0)])
    with pytest.raises(chainsim.ChainsimInputError, match=r"sigma.csv:3: column sigma = 0.0 is out of range: "
                                                          r"allowed sigma > 0"):
        chainsim.Data.from_csv(path)
    path = write_csv(tmp_path / "cols.csv", ["time", "y"], [(0, 1), (0.01, 0.99)])
    with pytest.raises(chainsim.ChainsimInputError, match=r"cols.csv:1: no column 't' in the header"):
        chainsim.Data.from_csv(path)


def test_a_pots_f_is_free_down_to_minus_one_half():
    """The default bounds of a scene's front dissipation are the scene format's: a pot's f in [-1/2, 1]."""
    from chainsim.fitting import _allowed_range
    fountain = chainsim.Scene.from_file(os.path.join(SCENES, "chain_fountain.toml"))
    assert _allowed_range(fountain, "effects.heap[0].f") == (-0.5, 1.0)
    assert _allowed_range(fountain, "effects.heap[1].f") == (0.0, 1.0)
    falling = chainsim.Scene.from_file(os.path.join(SCENES, "falling_chain.toml"))
    assert _allowed_range(falling, "f") == (0.0, 1.0)
    assert _allowed_range(falling, "t_offset") == (-np.inf, np.inf)
    assert _allowed_range(falling, "string.length") is None
    assert _allowed_range("falling", "eta0") == (0.0, 1.0)


def test_bad_fits_are_refused_with_the_reason():
    t, y = truth(n=20)
    data = noisy(t, y, 0.005, seed=1)
    refusals = [
        (dict(target="falling", data=noisy(t, y, 0.005, 1, observable="height"), free={"f": 0.5}),
         "observable 'height' is not an output of this model: allowed t_stop, E_force"),
        (dict(target="falling", data=data, free={"f": 1.5}), "free parameter f = 1.5 is out of range: allowed 0.0 <= f <= 1.0"),
        (dict(target="falling", data=data, free={"f": (0.5, -1, 1)}),
         "free parameter f: bounds [-1.0, 1.0] are out of range: allowed 0.0 <= f <= 1.0"),
        (dict(target="falling", data=data, free={"f": 0.5, "eps": 0.01}, fixed={"stiffness": 2}),
         "'stiffness' is not a parameter of the reduced falling chain"),
        (dict(target="falling", data=chainsim.Data(t[:2], y[:2], "y"), free={"f": 0.5, "t_offset": 0, "eta0": 1}),
         "2 data points for 3 free parameters (f, t_offset, eta0): too few"),
        (dict(target="falling", data=data, free={"f": 0.5}, max_nfev=1), "the fit did not converge in 1 evaluations"),
        (dict(target="falling", data=data, free={"f": 0.5}, fixed={"eps": 2.0}), "eps"),
        (dict(target=os.path.join(SCENES, "falling_chain.toml"), data=data, free={"f": 0.5},
              fixed={"string.nodes": 1}), "--set string.nodes=1: string.nodes = 1 is out of range"),
        # A pot's f may push (-1/2 <= f <= 1, docs/model.md), the floor heap's may not (0 <= f <= 1).
        (dict(target=os.path.join(SCENES, "chain_fountain.toml"), data=data,
              free={"effects.heap[0].f": (-0.2, -0.7, 1.0)}),
         "free parameter effects.heap[0].f: bounds [-0.7, 1.0] are out of range: allowed -0.5 <= effects.heap[0].f <= 1.0"),
        (dict(target=os.path.join(SCENES, "chain_fountain.toml"), data=data,
              free={"effects.heap[1].f": (0.5, -0.1, 1.0)}),
         "free parameter effects.heap[1].f: bounds [-0.1, 1.0] are out of range: allowed 0.0 <= effects.heap[1].f <= 1.0"),
    ]
    for kwargs, message in refusals:
        with pytest.raises(chainsim.ChainsimInputError) as e:
            chainsim.fit(kwargs.pop("target"), kwargs.pop("data"), kwargs.pop("free"), **kwargs)
        assert message in str(e.value), str(e.value)


# ------------------------------------------------------------------------------------------------------------------
# The command line

def cli(*args):
    return subprocess.run([BINARY, "fit", *args], capture_output=True, text=True)


def test_chainsim_fit_on_the_command_line(tmp_path):
    t, y = truth(n=40)
    rng = np.random.default_rng(4)
    path = write_csv(tmp_path / "drop.csv", ["t", "y"], zip(t + 0.02, y + 0.003 * rng.standard_normal(len(t))),
                     comment="synthetic: the reduced falling chain at f = 0.7, sigma = 3 mm")
    out = tmp_path / "fit"
    r = cli("falling", path, "--free", "f=0.5", "--free", "t_offset=0:-0.1:0.1", "--set", "max_step=1",
            "--out", str(out), "--json")
    assert r.returncode == 0, r.stderr
    result = json.loads(r.stdout)
    assert result["interval"]["f"][0] <= F_TRUE <= result["interval"]["f"][1]
    assert result["profile_interval"]["f"][0] <= F_TRUE <= result["profile_interval"]["f"][1]
    assert sorted(os.listdir(out)) == ["fit.json", "fit.png", "fit_series.csv", "fit_table.txt", "profile.png"]
    assert json.loads((out / "fit.json").read_text())["value"] == result["value"]
    # the same fit from Python, the file given by its path
    same = chainsim.fit("falling", path, {"f": 0.5, "t_offset": (0, -0.1, 0.1)}, fixed={"max_step": 1}, profile=None)
    assert same.value == result["value"]
    # the table
    r = cli("falling", path, "--free", "f=0.5", "--free", "t_offset=0:-0.1:0.1", "--out", str(out), "--no-figures")
    assert r.returncode == 0 and "95% (profile)" in r.stdout and "t_offset" in r.stdout
    # bad input: exit 2 with the located message
    bad = write_csv(tmp_path / "bad.csv", ["t", "y"], [(0, 1), (0.02, 0.9), (0.01, 0.8)])
    r = cli("falling", bad, "--out", str(tmp_path / "bad"))
    assert r.returncode == 2 and f"{bad}:4: column t = 0.01 is not after the previous time 0.02" in r.stderr
    r = cli("falling", path, "--free", "f=2", "--json")
    assert r.returncode == 2 and json.loads(r.stdout)["status"] == "failed"
    assert "f = 2.0 is out of range" in r.stderr
    r = cli("falling", path, "--observable", "height", "--column", "y")
    assert r.returncode == 2 and f"{path}:2: column y: observable 'height' is not an output of this model" in r.stderr
    r = cli("falling", path, "--jobs", "x")
    assert r.returncode == 2 and "--jobs" in r.stderr


def test_chainsim_fit_help_describes_every_option():
    r = cli("--help")
    assert r.returncode == 0
    for option in ("--observable", "--column", "--time-column", "--sigma", "--free", "--per-run", "--set", "--profile",
                   "--absolute-sigma", "--jobs", "--max-nfev", "--out", "--no-figures", "--json"):
        assert option in r.stdout, option


def test_f_names_an_edge_when_the_edge_is_the_only_front():
    """`--free f` on a scene whose only front is an edge (the peg) names effects.edge[0].f, as `chainsim sweep`'s
    `f` does; it said "the scene has 0 fronts" (an edge was not counted)."""
    from chainsim.fitting import _scene_key
    scene = chainsim.Scene.from_file(os.path.join(SCENES, "chain_over_peg.toml"))
    assert _scene_key(scene, "f") == "effects.edge[0].f"
    assert _scene_key(chainsim.Scene.from_file(os.path.join(SCENES, "falling_chain.toml")), "f") == "effects.heap[0].f"
