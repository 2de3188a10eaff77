"""chainsim.compare() on the contact problems (edge, peg, pulley) against closed forms and against `chainsim
compare` (docs/python.md, docs/cli.md): the same runs, the same series and summary as the command's files; read_run
of the command's directory gives the same Comparison; Comparisons pickle.

Run by CTest (tests/CMakeLists.txt, "python: compare") with pytest, PYTHONPATH=build/python:python and
CHAINSIM_BINARY set:
    PYTHONPATH=build/python:python CHAINSIM_BINARY=build/chainsim \
        /usr/bin/python3 -m pytest tests/python/test_compare.py
"""
import math
import os
import pickle
import subprocess
import warnings

import numpy as np
import pytest

import chainsim

HERE = os.path.dirname(os.path.abspath(__file__))
SOURCE = os.path.abspath(os.path.join(HERE, "..", ".."))
BINARY = os.environ.get("CHAINSIM_BINARY", os.path.join(SOURCE, "build", "chainsim"))

G = 9.81  # the commands' default gravity (m/s^2); length 1 m, density 1 kg/m
WALL_KEYS = {"wall_s", "integrator_wall_s"}


def cli(*args):
    r = subprocess.run([BINARY, *args], capture_output=True, text=True)
    assert r.returncode == 0, f"chainsim {' '.join(args)} exited {r.returncode}: {r.stderr}"
    return r


def without_wall(summary):
    return {k: v for k, v in summary.items() if k not in WALL_KEYS}


def assert_same_arrays(a, b):
    assert set(a) == set(b)
    for k in a:
        np.testing.assert_array_equal(a[k], b[k], err_msg=k)


def string_x(c):
    """The string's x (the edge's hanging length, the peg's longer side) at its steps: l - s0 of the edge front."""
    return 1.0 - c.string_series["s0_0"]


# ------------------------------------------------------------------------------------------------------------------
# Closed forms

def test_edge_at_f0_lifts_off_at_the_closed_form():
    """f = 0: l x'' = g x, so x = x0 cosh(sqrt(g/l) t), and the chain leaves the edge at
    x* = (l + sqrt(l^2 + 8 x0^2))/4 (docs/cli.md, compare edge)."""
    x0 = 0.2
    c = chainsim.compare("edge", f=0.0, x0=x0, nodes=21)
    assert isinstance(c, chainsim.Comparison) and c.problem == "edge" and c.reduced_series == {}
    assert c.reference is c.exact_series
    x_star = (1.0 + math.sqrt(1.0 + 8 * x0 ** 2)) / 4
    t_star = math.acosh(x_star / x0) / math.sqrt(G)
    t = c.string_series["t"]
    assert len(t) > 10 and np.array_equal(c.exact_series["t"], t)
    # the run ends at its lift-off event: its last step is there
    assert c.summary["t_lift_off"] == pytest.approx(t_star, abs=1e-7)
    assert c.summary["x_lift_off"] == pytest.approx(x_star, abs=1e-7)
    assert string_x(c)[-1] == pytest.approx(x_star, abs=1e-7) and t[-1] == pytest.approx(t_star, abs=1e-7)
    assert c.summary["x_lift_off_exact"] == pytest.approx(x_star, rel=1e-13)
    # the whole motion, both the string's and the exact series, on the closed form
    cosh = x0 * np.cosh(math.sqrt(G) * t)
    np.testing.assert_allclose(string_x(c), cosh, rtol=0, atol=1e-7)
    np.testing.assert_allclose(c.exact_series["x"], cosh, rtol=0, atol=1e-12)
    # x_dot is the root of the energy balance's x_dot^2, whose round-off the root magnifies near rest: compare squares
    np.testing.assert_allclose(c.exact_series["x_dot"] ** 2, G * (x0 * np.sinh(math.sqrt(G) * t)) ** 2, rtol=0,
                               atol=1e-13)
    assert abs(c.summary["dissipated"]) < 1e-9 and c.summary["dissipated_exact"] == pytest.approx(0, abs=1e-14)


def test_peg_at_f0_lifts_off_where_its_reaction_vanishes():
    """f = 0: u = x - l/2 grows as u0 cosh(sqrt(2g/l) t); the peg's reaction 2 lambda (l - x)(g + x'') - 2 lambda x'^2
    vanishes at u*^2 = l^2/8 + u0^2/2."""
    x0 = 0.6
    c = chainsim.compare("peg", f=0.0, x0=x0, nodes=21)
    u0 = x0 - 0.5
    u_star = math.sqrt(1 / 8 + u0 ** 2 / 2)
    t_star = math.acosh(u_star / u0) / math.sqrt(2 * G)
    assert c.summary["x_lift_off_exact"] == pytest.approx(0.5 + u_star, rel=1e-12)
    assert c.summary["t_lift_off"] == pytest.approx(t_star, abs=1e-7)
    assert c.summary["x_lift_off"] == pytest.approx(0.5 + u_star, abs=1e-7)
    t = c.string_series["t"]
    np.testing.assert_allclose(string_x(c), 0.5 + u0 * np.cosh(math.sqrt(2 * G) * t), rtol=0, atol=1e-7)
    # the string's reaction on the peg, (0, tau- + tau+ - 2 lambda x'^2), against the closed form of x(t)
    x = 0.5 + u0 * np.cosh(math.sqrt(2 * G) * t)
    v2 = 2 * G * ((x - 0.5) ** 2 - u0 ** 2)
    reaction = 2 * (1 - x) * (G + 2 * G * (x - 0.5)) - 2 * v2
    np.testing.assert_allclose(c.string_series["R_front0_y"], reaction, rtol=0, atol=1e-5)
    assert abs(c.string_series["R_front0_y"][-1]) < 1e-5   # zero at the lift-off


def test_pulley_lifts_off_at_the_root_of_its_quadratic():
    """u = u0 cosh(sqrt(2g/l) t); the shorter side leaves the pulley at the root u* of
    4u^2 + pi R u - (l l_free/2 + 2 u0^2) = 0, l_free = l - pi R (docs/cli.md, compare pulley)."""
    u0, R = 0.05, 0.1
    with warnings.catch_warnings():
        warnings.simplefilter("error")   # 51 nodes resolve R = 0.1 (4 links per radius): no ResolutionWarning
        c = chainsim.compare("pulley", u0=u0, R=R, nodes=51)
    free = 1 - math.pi * R
    u_star = max(np.roots([4, math.pi * R, -(free / 2 + 2 * u0 ** 2)]))
    t_star = math.acosh(u_star / u0) / math.sqrt(2 * G)
    assert c.summary["u_lift_off_exact"] == pytest.approx(u_star, rel=1e-12)
    assert c.summary["t_lift_off_exact"] == pytest.approx(t_star, rel=1e-12)
    assert c.summary["t_lift_off"] == pytest.approx(t_star, abs=1e-5)   # measured 2.1e-6 s at 51 nodes
    t = c.exact_series["t"]
    np.testing.assert_allclose(c.exact_series["u"], u0 * np.cosh(math.sqrt(2 * G) * t), rtol=1e-12, atol=0)
    # the margin (tau2 - lambda x'^2)/R changes sign at t*
    margin = c.exact_series["lift_off_margin"]
    assert (margin[t < t_star] > 0).all() and (margin[t > t_star] < 0).all()


# ------------------------------------------------------------------------------------------------------------------
# The command's files: the same run

@pytest.mark.parametrize("problem,options", [
    ("edge", {"nodes": 21, "f": 0.5, "x0": 0.3}),
    ("peg", {"nodes": 21, "f": 0.5, "x0": 0.7, "rtol": 1e-8}),
    ("pulley", {"nodes": 41, "u0": 0.04, "R": 0.12, "method": "erk8"}),
])
def test_compare_and_read_run_equal_the_command_files(tmp_path, problem, options):
    c = chainsim.compare(problem, **options)
    args = []
    for k, v in options.items():
        args += ["--" + k.replace("_", "-"), str(v)]
    out = tmp_path / problem
    cli("compare", problem, *args, "--out", str(out))
    read = chainsim.read_run(out)
    assert isinstance(read, chainsim.Comparison) and read.path == str(out) and read.kind == "compare"
    assert read.reduced_series == {} and read.problem == problem
    # CSV numbers are printed in their shortest round-trip form: the series equal to the last bit
    assert_same_arrays(read.string_series, c.string_series)
    assert_same_arrays(read.exact_series, c.exact_series)
    assert without_wall(read.summary) == without_wall(c.summary)
    for k, v in options.items():   # the options reached the run
        if k in ("f", "x0", "u0", "R", "nodes"):
            assert c.summary[k] == v


def test_read_run_of_a_reduced_comparison_has_no_exact_series(tmp_path):
    cli("compare", "falling", "--nodes", "11", "--t-max", "0.3", "--out", str(tmp_path))
    read = chainsim.read_run(tmp_path)
    c = chainsim.compare("falling", nodes=11, t_max=0.3)
    assert read.exact_series == {} == c.exact_series and read.reference is read.reduced_series
    assert_same_arrays(read.reduced_series, c.reduced_series)
    assert_same_arrays(read.string_series, c.string_series)


# ------------------------------------------------------------------------------------------------------------------
# Pickling, failures, bad input

def test_contact_comparisons_pickle(tmp_path):
    c = chainsim.compare("edge", nodes=11)
    back = pickle.loads(pickle.dumps(c))
    assert type(back) is chainsim.Comparison and back.summary == c.summary and back.problem == "edge"
    assert_same_arrays(back.string_series, c.string_series)
    assert_same_arrays(back.exact_series, c.exact_series)
    assert back.reduced_series == {} and back.path is None
    cli("compare", "peg", "--nodes", "11", "--out", str(tmp_path))
    read = chainsim.read_run(tmp_path)
    again = pickle.loads(pickle.dumps(read))
    assert again.path == str(tmp_path) and again.summary == read.summary
    assert_same_arrays(again.exact_series, read.exact_series)
    # a Comparison pickled before it had exact_series unpickles with none
    old = chainsim.Comparison.__new__(chainsim.Comparison)
    old.__setstate__({"string_series": {}, "reduced_series": {}, "summary": {"problem": "falling"}, "path": None})
    assert old.exact_series == {} and old.reference == {}


def test_a_failed_contact_run_keeps_its_comparison():
    with pytest.raises(chainsim.NumericalError, match="the string solver failed") as failed:
        chainsim.compare("edge", nodes=11, max_steps=3)
    c = failed.value.comparison
    assert c.summary["status"] == "failed" and c.summary["t_lift_off"] is None
    assert len(c.exact_series["t"]) == len(c.string_series["t"]) > 0


def test_a_pulley_thinner_than_its_links_warns():
    with pytest.warns(chainsim.ResolutionWarning, match="nodes"):
        c = chainsim.compare("pulley", nodes=41, R=0.05, u0=0.05)
    assert "resolution_warning" in c.summary


@pytest.mark.parametrize("problem,options,message", [
    ("edge", {"x0": 1.5}, r"--x0 = 1.5 is out of range: allowed 0 < x0 < 1"),
    ("peg", {"x0": 0.4}, r"--x0 = 0.4 is out of range: allowed 0.5 < x0 < 1"),
    ("pulley", {"R": 0.5}, r"--R = 0.5 is out of range: allowed 0 < R < 0.318"),
    ("pulley", {"u0": 0.5}, r"--u0 = 0.5 is out of range: allowed 0 < u0 < 0.34"),
    ("edge", {"nodes": 2}, r"--nodes = 2 is out of range: allowed 3 <= nodes <= 200001"),
    ("edge", {"f": 1.5}, r"f = 1.5 is out of range"),
    ("edge", {"t_max": 0}, r"--t-max = 0 is out of range: allowed t_max > 0"),   # was t_max_over_t0 = 0
    ("edge", {"t_max": 5e-324}, r"--t-max = 5e-324 is out of range: the safety stop t_max t0 = 0 s"),
    ("edge", {"x0": 1e-100}, r"--x0 = 1e-100 is out of range with --length = 1 and --nodes = 101: the hanging "
                             r"length x0 l = 1e-100 m puts the edge within 2e-10 m"),
    ("pulley", {"R": 1e-160}, r"--R = 1e-160 is out of range with --length = 1: the pulley's radius R = 1e-160 m "
                              r"is below 1.49e-154 m"),
    ("pulley", {"t_max": -1}, r"--t-max = -1 is out of range: allowed t_max > 0"),
    ("pulley", {"f": 0.5}, r"--f = 0.5: compare pulley has no f"),
    ("pulley", {"f": 0.83}, r"--f = 0.83: compare pulley has no f"),   # the default, given: refused as the command's
    ("pulley", {"eps": 0.01}, r"--eps = 0.01: compare pulley stops at the lift-off and has no cutoff"),
    ("edge", {"eps": 0.01}, r"--eps = 0.01: compare edge stops at the lift-off and has no cutoff"),
    ("pulley", {"x0": 0.3}, r"--x0 = 0.3: compare pulley starts from --u0"),
    ("edge", {"u0": 0.1}, r"--u0 = 0.1: only compare pulley takes --u0 \(compare edge\)"),
    ("peg", {"R": 0.1}, r"--R = 0.1: only compare pulley takes --R \(compare peg\)"),
    ("edge", {"eta0": 0.5}, r"--eta0 = 0.5: compare edge starts from --x0"),
    ("edge", {"method": "dirk3"}, r"--method = dirk3 is implicit"),
    ("edge", {"tilt_deg": 5}, r"compare\(\): tilt_deg = 5: compare edge releases the chain straight"),
    ("pulley", {"bend_deg": 1.0}, r"compare\(\): bend_deg = 1.0: compare pulley releases the chain straight"),
    ("falling", {"x0": 0.2}, r"--x0 = 0.2: only compare edge takes --x0"),
    ("sliding", {"u0": 0.2}, r"--u0 = 0.2: only compare pulley takes --u0"),
    ("edge", {"x0": "0.2"}, r"compare\(\): x0 = '0.2' must be a number"),
    ("pulley", {"R": True}, r"compare\(\): R = True must be a number"),
    ("table", {}, r"problem = \"table\" is not a known problem: allowed falling, folded, sliding, edge, peg, pulley"),
    (3, {}, r"compare\(\): problem = 3 is not a known problem: allowed falling, folded, sliding, edge, peg, pulley"),
])
def test_bad_contact_options_are_refused_naming_them(problem, options, message):
    with pytest.raises(chainsim.ChainsimInputError, match=message):
        chainsim.compare(problem, **options)


def test_the_command_refuses_what_compare_refuses(tmp_path):
    """One check for both front doors: the command's messages are the keyword's."""
    r = subprocess.run([BINARY, "compare", "pulley", "--f", "0.5", "--out", str(tmp_path)], capture_output=True,
                       text=True)
    assert r.returncode == 2
    with pytest.raises(chainsim.ChainsimInputError) as e:
        chainsim.compare("pulley", f=0.5)
    assert str(e.value) in r.stderr
