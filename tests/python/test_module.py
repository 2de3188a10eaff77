"""The Python module chainsim (docs/python.md) against the command-line tool and exact references.

Run by CTest (tests/CMakeLists.txt) with pytest, PYTHONPATH=build/python:python and CHAINSIM_BINARY set:
    PYTHONPATH=build/python:python CHAINSIM_BINARY=build/chainsim /usr/bin/python3 -m pytest tests/python/test_module.py
"""
import csv
import json
import math
import os
import signal
import subprocess
import sys
import tempfile
import textwrap
import time
import warnings

import numpy as np
import pytest

import chainsim

HERE = os.path.dirname(os.path.abspath(__file__))
SOURCE = os.path.abspath(os.path.join(HERE, "..", ".."))
BINARY = os.environ.get("CHAINSIM_BINARY", os.path.join(SOURCE, "build", "chainsim"))
SCENES = os.path.join(SOURCE, "cases", "scenes")

# Timing and counter keys of the summary: the same run, but not the same wall clock.
WALL_KEYS = {"wall_s"}


def cli(*args, check=True):
    r = subprocess.run([BINARY, *args], capture_output=True, text=True)
    if check and r.returncode != 0:
        raise AssertionError(f"chainsim {' '.join(args)} exited {r.returncode}: {r.stderr}")
    return r


def read_csv(path):
    with open(path) as f:
        rows = list(csv.reader(f))
    return rows[0], np.array([[float(v) for v in row] for row in rows[1:]])


def without_wall(summary):
    return {k: v for k, v in summary.items() if k not in WALL_KEYS and k != "integrator_wall_s"}


# ------------------------------------------------------------------------------------------------------------------
# Bit-for-bit equality with `chainsim run`

@pytest.mark.parametrize("name,t_end,sets", [
    ("falling_chain", 0.2, ["string.nodes=41"]),     # fronts: series.csv, forces.csv, W_shocks, ...
    ("hanging_chain", 0.3, ["string.nodes=21"]),     # a plain string with a fixed end
])
def test_results_equal_the_cli_to_the_last_bit(tmp_path, name, t_end, sets):
    scene_file = os.path.join(SCENES, name + ".toml")
    cli_dir = tmp_path / "cli"
    cli("run", scene_file, "--out", str(cli_dir), "--t-end", str(t_end), "--quiet", *sum((["--set", s] for s in sets), []))
    scene = chainsim.Scene.from_file(scene_file)
    for s in sets:
        key, value = s.split("=")
        scene = scene.set(key, int(value))
    result = scene.run(t_end=t_end)

    # every array against the CLI's CSV, exactly
    cols, nodes = read_csv(cli_dir / "nodes.csv")
    frame = {t: k for k, t in enumerate(result.nodes["t"])}
    assert len(frame) == result.summary["frames"]
    for row in nodes:
        k, i = frame[row[0]], int(row[1])
        for c, name_ in enumerate(cols[2:], start=2):
            value = result.nodes[name_][i] if name_ == "s" else result.nodes[name_][k, i]
            assert value == row[c], (name_, k, i)
    assert len(nodes) == int(result.nodes["moving"].sum())
    cols, tension = read_csv(cli_dir / "tension.csv")
    for row in tension:
        k, j = frame[row[0]], int(row[1])
        assert result.tension["s_mid"][j] == row[2] and result.tension["T"][k, j] == row[3]
    assert len(tension) == int(np.isfinite(result.tension["T"]).sum())
    for file, table in (("energy.csv", result.energy), ("forces.csv", result.forces), ("series.csv", result.series)):
        if not (cli_dir / file).exists():
            assert file != "energy.csv" and (file != "series.csv" or not table)
            continue
        cols, data = read_csv(cli_dir / file)
        assert sorted(cols) == sorted(table), file
        for c, col in enumerate(cols):
            np.testing.assert_array_equal(table[col], data[:, c], err_msg=f"{file}: {col}")
    with open(cli_dir / "stats.json") as f:
        stats = json.load(f)
    assert without_wall(result.summary) == without_wall(stats)

    # the same writer: the files of result.write() are the CLI's, byte for byte (stats.json but its wall time)
    py_dir = result.write(tmp_path / "py")
    for file in sorted(os.listdir(cli_dir)):
        if file in ("stats.json", "frames"):
            continue
        assert (py_dir / file).read_bytes() == (cli_dir / file).read_bytes(), file
    assert sorted(os.listdir(py_dir / "frames")) == sorted(os.listdir(cli_dir / "frames"))
    with open(py_dir / "stats.json") as f:
        assert without_wall(json.load(f)) == without_wall(stats)


def test_reduced_equals_the_cli_and_the_quadrature(tmp_path):
    r = chainsim.reduced("falling", f=0.5)
    out = json.loads(cli("reduced", "falling", "--f", "0.5", "--json", "--out", str(tmp_path)).stdout)
    assert r.summary["t_stop"] == out["t_stop"]
    assert r.summary["t_stop_over_t0"] == pytest.approx(r.summary["t_stop_over_t0_exact"], rel=1e-9)
    cols, series = read_csv(tmp_path / "series.csv")
    np.testing.assert_array_equal(r.series["t"], series[:, cols.index("t")])


def test_compare_matches_the_reduced_model():
    c = chainsim.compare("falling", nodes=21, f=0.5)
    assert c.summary["rel_err_t_stop"] < 1e-9   # the straight falling chain is exact on any mesh
    assert len(c.string_series["t"]) > 2 and len(c.reduced_series["t"]) > 2


# ------------------------------------------------------------------------------------------------------------------
# Errors

def test_scene_errors_are_located(tmp_path):
    path = tmp_path / "bad.toml"
    text = open(os.path.join(SCENES, "hanging_chain.toml")).read().replace("nodes = 41", "nodes = 1")
    path.write_text(text)
    line = next(n for n, l in enumerate(text.splitlines(), start=1) if l.startswith("nodes = 1"))
    with pytest.raises(chainsim.ChainsimInputError, match=rf"{path}:{line}:9: .*string.nodes = 1.*allowed") as e:
        chainsim.Scene.from_file(path)
    assert isinstance(e.value, ValueError)
    with pytest.raises(ValueError, match=r"--set effects.gravity.g=\"down\""):
        chainsim.Scene.from_file(os.path.join(SCENES, "hanging_chain.toml")).set("effects.gravity.g", "down")
    with pytest.raises(chainsim.ChainsimInputError, match=r"<dict>:\d+:\d+: .*did you mean"):
        chainsim.Scene.from_dict({"string": {"lenght": 1.0}, "stop": {"t_end": 1.0}})
    with pytest.raises(chainsim.ChainsimInputError, match="f = 2 is out of range"):
        chainsim.reduced("falling", f=2.0)


def test_scene_from_dict_runs_like_its_file():
    d = {"string": {"length": 1.0, "density": 0.1, "nodes": 11},
         "shape": {"kind": "polyline", "points": [[0.0, 0.0], [0.04998, -0.99875]]},
         "ends": {"start": "fixed"}, "effects": {"gravity": {"g": [0.0, -9.81]}},
         "output": {"interval": 0.05}, "stop": {"t_end": 0.2}}
    r = chainsim.Scene.from_dict(d).run()
    # the pendulum's energy is conserved: the ledger closes to the integrator's tolerance
    assert r.status == "completed" and r.summary["relative_energy_drift"] < 1e-6
    assert r.t[-1] == 0.2 and r.positions.shape == (5, 11, 2)
    np.testing.assert_allclose(np.linalg.norm(np.diff(r.positions, axis=1), axis=2), 0.1, rtol=1e-7)


def test_dict_scenes_take_numpy_values_and_refuse_at_the_key_what_no_scene_holds():
    """Issue #21: numpy int64, float32, ndarray and np.bool_ raised a bare TypeError (scene.set took them);
    NaN, inf, 10**400 and lone surrogates raised RuntimeError "[json.exception.parse_error.101]"."""
    d = {"string": {"length": np.float32(1.0), "density": 0.1, "nodes": np.int64(11), "closed": np.bool_(False)},
         "shape": {"kind": "polyline", "points": np.array([[0.0, 0.0], [0.04998, -0.99875]])},
         "ends": {"start": "fixed"}, "effects": {"gravity": {"g": [np.float64(0.0), -9.81]}},
         "output": {"interval": 0.05}, "stop": {"t_end": 0.2}}
    scene = chainsim.Scene.from_dict(d)
    plain = chainsim.Scene.from_dict({**d, "string": {"length": 1.0, "density": 0.1, "nodes": 11, "closed": False},
                                      "shape": {"kind": "polyline", "points": [[0.0, 0.0], [0.04998, -0.99875]]},
                                      "effects": {"gravity": {"g": [0.0, -9.81]}}})
    assert scene.effective == plain.effective
    bad = [({"string": {"length": float("nan")}}, r"<dict>:\d+:\d+: string.length = nan must be a finite number"),
           ({"string": {"length": -math.inf}}, r"<dict>:\d+:\d+: string.length = -inf must be a finite number"),
           ({"effects": {"gravity": {"g": [0.0, math.inf]}}}, r"effects.gravity.g = .* finite"),
           ({"string": {"nodes": 10**400}}, r"string.nodes = 1000.*\(401 digits\) is out of range"),
           ({"solver": {"method": "erk\ud800"}}, r"solver.method = 'erk\\ud800' is not valid text"),
           ({"solver": {"\ud800": 1}}, r"solver has the key '\\ud800'"),
           ({"solver": {"rtol": None}}, r"solver.rtol = null cannot be written"),
           ({"solver": {"rtol": 1j}}, r"solver.rtol = 1j cannot be a scene value"),
           ({"solver": {3: 1}}, r"solver has the key 3")]
    for change, message in bad:
        with pytest.raises(chainsim.ChainsimInputError, match=message):
            chainsim.Scene.from_dict({**d, **change})


def test_reduced_and_compare_keywords_of_the_wrong_type_are_refused_as_input():
    """Issue #21: reduced(f="0.5") and compare(nodes=10**20) raised RuntimeError "Unable to cast"; inside a sweep
    that aborted the whole sweep instead of giving an error row."""
    with pytest.raises(chainsim.ChainsimInputError, match=r"reduced\(\): f = '0.5' must be a number"):
        chainsim.reduced("falling", f="0.5")
    with pytest.raises(chainsim.ChainsimInputError, match=r"compare\(\): nodes = 100000000000000000000 is out of range"):
        chainsim.compare("falling", nodes=10**20)
    with pytest.raises(chainsim.ChainsimInputError, match=r"compare\(\): nodes = 10.0 must be an integer"):
        chainsim.compare("falling", nodes=10.0)
    with pytest.raises(chainsim.ChainsimInputError, match=r"reduced\(\): method = 8 must be a string"):
        chainsim.reduced("falling", method=8)
    with pytest.raises(chainsim.ChainsimInputError, match=r"problem = 3 is not a known problem"):
        chainsim.reduced(3)
    # numpy scalars are numbers
    r = chainsim.reduced("falling", f=np.float32(0.5), max_steps=np.int64(100000))
    assert r.summary["parameters"]["f"] == 0.5
    df = chainsim.sweep("falling", {"f": ["x", 0.5]})
    assert list(df.status) == ["error", "completed"]
    assert "f = 'x' must be a number" in df.error[0]


def test_reduced_runs_stop_at_t_max_of_any_size():
    """Issue #21: `chainsim reduced sliding --t-max 1e-6` reported "stop: t_max" at t/t0 = 0.00216."""
    for problem in ("falling", "folded", "sliding"):
        r = chainsim.reduced(problem, t_max=1e-6)
        assert r.summary["stop_reason"] == "t_max" and r.summary["t_stop_over_t0"] == 1e-6
        assert r.series["t"][-1] == pytest.approx(1e-6 * r.summary["t0"], rel=1e-15)
    # the sliding chain on its branch eta = tau^2/(3 + 2f), f = 0.83 by default
    assert r.summary["eta_stop"] == pytest.approx(1e-12 / (3 + 2 * 0.83), rel=1e-9)


def test_numerical_failure_raises_with_the_partial_result():
    scene = chainsim.Scene.from_file(os.path.join(SCENES, "hanging_chain.toml")).set(
        **{"string.nodes": 11, "solver.max_steps": 5})
    with pytest.raises(chainsim.NumericalError) as e:
        scene.run(t_end=1.0)
    assert e.value.result.status == "failed" and len(e.value.result.t) >= 1


def test_ctrl_c_stops_a_run_and_raises_keyboard_interrupt(tmp_path):
    script = textwrap.dedent(f"""
        import sys, chainsim
        scene = chainsim.Scene.from_file({os.path.join(SCENES, 'hanging_chain.toml')!r}).set("string.nodes", 201)
        print("running", flush=True)
        try:
            scene.run(t_end=1000.0)
        except KeyboardInterrupt as e:
            print("KeyboardInterrupt:", e, flush=True)
            sys.exit(7)
        sys.exit(0)
    """)
    p = subprocess.Popen([sys.executable, "-c", script], stdout=subprocess.PIPE, text=True, env=os.environ)
    assert p.stdout.readline().strip() == "running"
    time.sleep(1.0)
    p.send_signal(signal.SIGINT)
    start = time.monotonic()
    out, _ = p.communicate(timeout=60)
    assert p.returncode == 7, out
    assert "interrupted by the user at t =" in out
    assert time.monotonic() - start < 10


# ------------------------------------------------------------------------------------------------------------------
# Sweeps

def test_sweep_of_the_reduced_model_against_the_quadrature():
    df = chainsim.sweep("falling", {"f": [0.0, 0.5, 1.0], "eta0": [1.0, 0.5]}, workers=2)
    assert len(df) == 6 and list(df.columns[:2]) == ["f", "eta0"] and (df.status == "completed").all()
    np.testing.assert_allclose(df["t_stop_over_t0"], df["t_stop_over_t0_exact"], rtol=1e-9)


def test_sweep_threads_give_the_serial_rows_bit_for_bit():
    scene = chainsim.Scene.from_file(os.path.join(SCENES, "falling_chain.toml"))
    grid = {"f": [0.0, 1.0], "string.nodes": [11, 21]}
    one = chainsim.sweep(scene, grid, t_end=0.1, workers=1)
    two = chainsim.sweep(scene, grid, t_end=0.1, workers=2)
    cols = [c for c in one.columns if "wall" not in c]
    assert one[cols].equals(two[cols])
    for _, row in one.iterrows():   # and each row is the run itself
        r = scene.set(**{"effects.heap[0].f": row["f"], "string.nodes": row["string.nodes"]}).run(t_end=0.1)
        assert r.summary["t_stop"] == row["t_stop"] and r.summary["energy_drift"] == row["energy_drift"]


def test_sweep_on_a_local_dask_cluster_with_a_bad_point():
    from dask.distributed import Client, LocalCluster
    scene = chainsim.Scene.from_file(os.path.join(SCENES, "hanging_chain.toml"))
    grid = {"string.nodes": [11, 21, 31, 1], "solver.method": ["erk5", "erk8"]}   # nodes = 1: refused
    with LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=":0") as cluster, \
            Client(cluster) as client:
        df = chainsim.sweep(scene, grid, t_end=0.2, client=client)
    assert len(df) == 8
    bad = df[df["string.nodes"] == 1]
    assert (bad.status == "error").all() and bad.error.str.contains(r"--set string.nodes=1.*out of range").all()
    good = df[df["string.nodes"] != 1]
    assert (good.status == "completed").all() and (good.t_stop == 0.2).all()
    assert (good.nodes == good["string.nodes"]).all()
    assert (good.relative_energy_drift < 1e-6).all()   # the ledger closes on every mesh


def test_sweep_refuses_an_alias_and_its_full_key_before_any_run(tmp_path):
    """Issue #21: --grid f=0.1 --grid effects.heap[0].f=0.9 ran f = 0.9 in a row labelled f = 0.1."""
    scene_file = os.path.join(SCENES, "falling_chain.toml")
    r = cli("sweep", scene_file, "--grid", "f=0.1", "--grid", "effects.heap[0].f=0.9", "--out", str(tmp_path / "s"),
            check=False)
    assert r.returncode == 2 and not (tmp_path / "s").exists()
    assert "the grid key f and the grid key effects.heap[0].f both set effects.heap[0].f" in r.stderr
    scene = chainsim.Scene.from_file(scene_file)
    with pytest.raises(chainsim.ChainsimInputError, match=r"grid key f and the grid key effects.heap\[0\].f"):
        chainsim.sweep(scene, {"f": [0.1], "effects.heap[0].f": [0.9]})
    with pytest.raises(chainsim.ChainsimInputError, match=r"grid key stop.t_end and the sweep's t_end"):
        chainsim.sweep(scene, {"stop.t_end": [0.1]}, t_end=0.2)
    with pytest.raises(chainsim.ChainsimInputError, match=r"the grid axis f = 0.5 is not a list"):
        chainsim.sweep(scene, {"f": 0.5})
    with pytest.raises(chainsim.ChainsimInputError, match=r"has no values"):
        chainsim.sweep("falling", {"f": []})
    with pytest.raises(chainsim.ChainsimInputError, match=r"not a keyword of reduced\(\)"):
        chainsim.sweep("falling", {"nodes": [3]})
    # each row shows the value that ran: the alias and the full key give the same stop
    a = chainsim.sweep(scene, {"f": [0.9]}, t_end=0.1)
    b = chainsim.sweep(scene, {"effects.heap[0].f": [0.9]}, t_end=0.1)
    assert a.t_stop[0] == b.t_stop[0] and a.f[0] == 0.9


def test_cli_sweep_writes_one_row_per_point(tmp_path):
    r = cli("sweep", os.path.join(SCENES, "falling_chain.toml"), "--grid", "f=0,1,1.5", "--grid",
            "string.nodes=11,21", "--t-end", "0.1", "--jobs", "2", "--out", str(tmp_path))
    assert "6 points on 2 threads" in r.stdout
    import pandas as pd
    df = pd.read_csv(tmp_path / "sweep.csv", float_precision="round_trip")  # reads back exactly
    assert len(df) == 6 and list(df.columns[:5]) == ["f", "string.nodes", "status", "error", "wall_time_s"]
    assert (df[df.f == 1.5].status == "error").all()
    assert df[df.f == 1.5].error.str.contains(r"effects.heap\[0\].f=1.5").all()
    ok = df[df.f != 1.5]
    assert set(ok.status) == {"completed"}
    py = chainsim.sweep(chainsim.Scene.from_file(os.path.join(SCENES, "falling_chain.toml")),
                        {"f": [0, 1], "string.nodes": [11, 21]}, t_end=0.1)
    np.testing.assert_array_equal(ok.t_stop.to_numpy(), py.t_stop.to_numpy())
    np.testing.assert_array_equal(ok.energy_drift.to_numpy(), py.energy_drift.to_numpy())


def test_read_run_reads_a_cli_directory(tmp_path):
    cli("run", os.path.join(SCENES, "hanging_chain.toml"), "--out", str(tmp_path), "--t-end", "0.1", "--quiet")
    run = chainsim.read_run(tmp_path)
    assert run.kind == "string" and run.summary["t_stop"] == 0.1


# ------------------------------------------------------------------------------------------------------------------
# A run directory belongs to one run: Result.write takes the lock `chainsim run` takes (the same C++ code)

def test_write_is_refused_while_a_run_holds_the_directory_and_clears_other_commands_outputs(tmp_path):
    scene_file = os.path.join(SCENES, "hanging_chain.toml")
    result = chainsim.Scene.from_file(scene_file).set("string.nodes", 11).run(t_end=0.05)
    out = tmp_path / "d"
    # A run of 1000 s (ended below) holds the directory.
    run = subprocess.Popen([BINARY, "run", scene_file, "--out", str(out), "--quiet", "--t-end", "1000",
                            "--max-wall", "60"], stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    try:
        lock = out / ".chainsim.lock"
        for _ in range(1000):
            if lock.exists() and lock.read_text() == f"{run.pid}\n":
                break
            time.sleep(0.01)
        with pytest.raises(chainsim.ChainsimInputError, match=rf"is in use by another chainsim process \(pid {run.pid}\)"):
            result.write(out)
    finally:
        run.send_signal(signal.SIGINT)
        assert run.wait(timeout=60) == 130
    # Free again: write() replaces the run's set and removes what compare wrote there.
    cli("compare", "falling", "--nodes", "11", "--out", str(tmp_path / "c"))
    (tmp_path / "c" / "notes.txt").write_text("mine\n")
    result.write(tmp_path / "c")
    assert sorted(os.listdir(tmp_path / "c")) == ["energy.csv", "forces.csv", "frames", "nodes.csv", "notes.txt",
                                                 "stats.json", "string.pvd", "tension.csv"]


def test_a_coarse_atol_warns_with_the_value_to_set():
    # The hanging chain on its first mode, amplitude 1e-5 m: atol 1e-6 m is 5 % of its 2e-5 m swing, far
    # coarser than rtol = 1e-4 (issue 24, item 4); the advised atol runs without the warning.
    scene = chainsim.Scene.from_file(os.path.join(SOURCE, "docs", "data", "hanging_chain_mode1.toml")).set(**{
        "solver.method": "auto", "solver.rtol": 1e-4, "solver.atol": 1e-6, "stop.t_end": 1.8,
        "output.interval": 0.05})
    with pytest.warns(chainsim.ToleranceWarning, match=r"set solver.atol <= ") as caught:
        result = scene.run()
    assert str(caught[0].message) == result.summary["tolerance_warning"]
    advised = float(result.summary["tolerance_warning"].rsplit("<= ", 1)[1])
    with warnings.catch_warnings():
        warnings.simplefilter("error", chainsim.ToleranceWarning)
        assert "tolerance_warning" not in scene.set(**{"solver.atol": advised}).run().summary


def test_a_cylinder_thinner_than_the_links_warns_with_the_nodes_to_set():
    # The heavy Atwood chain over a pulley of radius 0.1 m on 5 nodes (links of 0.25 m): the pulley is a polygon
    # of one or two nodes; the advised mesh does not warn (issue 23).
    scene = chainsim.Scene.from_file(os.path.join(SOURCE, "cases", "scenes", "atwood_pulley.toml")).set(**{
        "string.nodes": 5, "stop.t_end": 0.01})
    with pytest.warns(chainsim.ResolutionWarning, match=r"set string.nodes >= 11 ") as caught:
        result = scene.run()
    assert [str(w.message) for w in caught if w.category is chainsim.ResolutionWarning] == \
        [result.summary["resolution_warning"]]
    with warnings.catch_warnings():
        warnings.simplefilter("error", chainsim.ResolutionWarning)
        assert "resolution_warning" not in scene.set(**{"string.nodes": 11}).run().summary
