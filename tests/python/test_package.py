"""chainsim as a Python package (docs/python.md): results that pickle and export, one Result type for runs, read
runs and sweep points, the version, the type hints and docstrings, the HTML views, figures in memory, progress
bars, and the wheel that `pip wheel .` makes (packed from this build: no compilation).

Run by CTest (tests/CMakeLists.txt) with pytest, PYTHONPATH=build/python:python and CHAINSIM_BINARY set:
    PYTHONPATH=build/python:python CHAINSIM_BINARY=build/chainsim /usr/bin/python3 -m pytest tests/python/test_package.py
"""
import csv
import hashlib
import base64
import inspect
import io
import os
import pickle
import re
import subprocess
import sys
import typing
import zipfile

import numpy as np
import pytest

import chainsim

HERE = os.path.dirname(os.path.abspath(__file__))
SOURCE = os.path.abspath(os.path.join(HERE, "..", ".."))
BINARY = os.environ.get("CHAINSIM_BINARY", os.path.join(SOURCE, "build", "chainsim"))
BUILD = os.environ.get("CHAINSIM_BUILD_DIR", os.path.dirname(BINARY))
SCENES = os.path.join(SOURCE, "cases", "scenes")


def falling(nodes=21):
    return chainsim.Scene.from_file(os.path.join(SCENES, "falling_chain.toml")).set("string.nodes", nodes)


def cli(*args):
    r = subprocess.run([BINARY, *args], capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    return r.stdout


def assert_same_arrays(a, b):
    assert set(a) == set(b)
    for k in a:
        np.testing.assert_array_equal(a[k], b[k], err_msg=k)  # NaN equals NaN here


def assert_same_result(a, b):
    for field in ("nodes", "tension", "energy", "forces", "series", "fronts"):
        assert_same_arrays(getattr(a, field), getattr(b, field))
    assert a.summary == b.summary and a.kind == b.kind


# ------------------------------------------------------------------------------------------------------------------
# The version

def test_version_is_the_text_of_chainsim_version():
    text = cli("--version").strip()
    assert chainsim._core.version_text == text
    with open(os.path.join(SOURCE, "CMakeLists.txt")) as fh:
        declared = re.search(r"project\(chainsim VERSION ([0-9.]+)", fh.read()).group(1)
    assert chainsim.__version__ == declared and text.startswith(f"chainsim {declared} ")


# ------------------------------------------------------------------------------------------------------------------
# Pickling: results, scenes and errors, as Dask sends them

def test_results_scenes_and_errors_pickle():
    scene = falling()
    result = scene.run(t_end=0.1)
    back = pickle.loads(pickle.dumps(result))
    assert_same_result(result, back)
    assert back.nodes["x"].shape == (result.summary["frames"], 21)
    with pytest.raises(chainsim.ChainsimInputError, match="unpickled"):   # the C++ run stays behind
        back.write("never-written")
    assert not os.path.exists("never-written")
    s = pickle.loads(pickle.dumps(scene))
    assert (s.text, s.source, s.overrides, s.effective) == (scene.text, scene.source, scene.overrides, scene.effective)
    reduced = chainsim.reduced("falling", f=0.5)
    r = pickle.loads(pickle.dumps(reduced))
    assert r.summary == reduced.summary
    assert_same_arrays(r.series, reduced.series)
    comparison = chainsim.compare("falling", nodes=11, f=0.5, t_max=0.3)
    c = pickle.loads(pickle.dumps(comparison))
    assert c.summary == comparison.summary
    assert_same_arrays(c.string_series, comparison.string_series)


def test_errors_pickle_with_their_fields():
    with pytest.raises(chainsim.ChainsimInputError) as bad:
        falling().set("string.nodes", 1)
    bad.value.key = "string.nodes"   # any located field an error carries goes along
    e = pickle.loads(pickle.dumps(bad.value))
    assert type(e) is chainsim.ChainsimInputError and str(e) == str(bad.value) and e.key == "string.nodes"
    assert "string.nodes = 1 is out of range" in str(e)
    scene = chainsim.Scene.from_file(os.path.join(SCENES, "hanging_chain.toml")).set(
        **{"string.nodes": 11, "solver.max_steps": 5})
    with pytest.raises(chainsim.NumericalError) as failed:
        scene.run(t_end=1.0)
    e = pickle.loads(pickle.dumps(failed.value))   # failed before: the Result held the C++ run
    assert type(e) is chainsim.NumericalError and str(e) == str(failed.value)
    assert e.result.status == "failed"
    assert_same_result(e.result, failed.value.result)


# ------------------------------------------------------------------------------------------------------------------
# One Result type: runs, read runs, sweep points

def test_read_run_gives_the_result_of_the_run_bit_for_bit(tmp_path):
    result = falling().run(t_end=0.1)
    result.write(tmp_path / "run")
    read = chainsim.read_run(tmp_path / "run")
    assert isinstance(read, chainsim.Result) and read.kind == result.kind == "fronts"
    assert read.path == str(tmp_path / "run") and read.summary["t_stop"] == result.summary["t_stop"]
    moving = result.nodes["moving"]
    np.testing.assert_array_equal(read.nodes["moving"], moving)   # the CSV lists the moving nodes
    for k in ("x", "y", "vx", "vy"):
        np.testing.assert_array_equal(read.nodes[k][moving], result.nodes[k][moving])
        assert np.isnan(read.nodes[k][~moving]).all()
    np.testing.assert_array_equal(read.tension["T"], result.tension["T"])   # NaN: a link in no arc
    written = np.isfinite(read.tension["s_mid"])   # a link that is in no arc at any frame is in no row
    np.testing.assert_array_equal(read.tension["s_mid"][written], result.tension["s_mid"][written])
    assert written.sum() == np.isfinite(result.tension["T"]).any(axis=0).sum()
    for field in ("energy", "forces", "series"):
        assert_same_arrays(getattr(read, field), getattr(result, field))
    # the other commands' directories: the types the module returns for them
    cli("reduced", "falling", "--f", "0.5", "--out", str(tmp_path / "reduced"))
    red = chainsim.read_run(tmp_path / "reduced")
    direct = chainsim.reduced("falling", f=0.5)
    assert isinstance(red, chainsim.ReducedResult) and red.kind == "reduced"
    np.testing.assert_array_equal(red.series["eta"], direct.series["eta"])
    cli("compare", "falling", "--nodes", "11", "--t-max", "0.3", "--out", str(tmp_path / "compare"))
    assert isinstance(chainsim.read_run(tmp_path / "compare"), chainsim.Comparison)


def test_sweep_returns_whole_results_on_threads():
    scene = falling(11)
    df = chainsim.sweep(scene, {"f": [0.0, 1.0], "string.nodes": [11, 1]}, t_end=0.1, workers=2, results=True)
    assert list(df.columns[:5]) == ["f", "string.nodes", "status", "error", "wall_time_s"]
    assert df.columns[-1] == "result"
    plain = chainsim.sweep(scene, {"f": [0.0, 1.0], "string.nodes": [11, 1]}, t_end=0.1, workers=2)
    cols = [c for c in plain.columns if "wall" not in c]
    assert df[cols].equals(plain[cols])   # the same rows as without results
    for _, row in df.iterrows():
        if row["string.nodes"] == 1:
            assert row.status == "error" and row.result is None
            continue
        direct = scene.set(**{"effects.heap[0].f": row["f"]}).run(t_end=0.1)
        assert isinstance(row.result, chainsim.Result)
        assert row.result.summary["t_stop"] == row.t_stop
        assert_same_arrays(row.result.nodes, direct.nodes)


def test_sweep_on_dask_worker_processes_returns_pickled_results():
    from dask.distributed import Client, LocalCluster
    scene = falling(11)
    with LocalCluster(n_workers=1, threads_per_worker=2, processes=True, dashboard_address=":0") as cluster, \
            Client(cluster) as client:
        df = chainsim.sweep(scene, {"f": [0.0, 0.5, 1.0]}, t_end=0.1, client=client, results=True)
        assert (df.status == "completed").all()
        reduced = chainsim.sweep("falling", {"f": [0.5]}, client=client, results=True)
    for _, row in df.iterrows():
        r = row.result
        assert r._run is None   # it came through pickle from another process
        direct = scene.set(**{"effects.heap[0].f": row["f"]}).run(t_end=0.1)
        assert_same_arrays(r.nodes, direct.nodes)
        assert_same_arrays(r.series, direct.series)
    assert isinstance(reduced.result[0], chainsim.ReducedResult)
    np.testing.assert_array_equal(reduced.result[0].series["eta"], chainsim.reduced("falling", f=0.5).series["eta"])


# ------------------------------------------------------------------------------------------------------------------
# pandas, xarray, netCDF

def test_to_dataframe_is_the_cli_s_tables(tmp_path):
    import pandas as pd
    scene_file = os.path.join(SCENES, "falling_chain.toml")
    cli("run", scene_file, "--set", "string.nodes=21", "--t-end", "0.1", "--out", str(tmp_path), "--quiet")
    result = falling().run(t_end=0.1)
    energy = pd.read_csv(tmp_path / "energy.csv", float_precision="round_trip", dtype=float).set_index("t")
    pd.testing.assert_frame_equal(result.to_dataframe("energy"), energy)
    nodes = pd.read_csv(tmp_path / "nodes.csv", float_precision="round_trip").set_index(["t", "node"])
    df = result.to_dataframe("nodes")
    assert len(df) == result.summary["frames"] * 21
    moving = df[df.moving]
    assert len(moving) == len(nodes)
    for c in nodes.columns:
        np.testing.assert_array_equal(moving[c].to_numpy(), nodes[c].to_numpy(), err_msg=c)
    tension = pd.read_csv(tmp_path / "tension.csv", float_precision="round_trip").set_index(["t", "link"])
    t = result.to_dataframe("tension").dropna()
    np.testing.assert_array_equal(t["T"].to_numpy(), tension["T"].to_numpy())
    assert len(result.to_dataframe("fronts")) == result.summary["frames"]   # one front
    with pytest.raises(chainsim.ChainsimInputError, match="allowed nodes, tension"):
        result.to_dataframe("nope")


def test_to_xarray_has_dims_units_and_round_trips_through_netcdf(tmp_path):
    import xarray as xr
    result = falling().run(t_end=0.1)
    ds = result.to_xarray()
    frames = result.summary["frames"]
    assert ds.dims["time"] == frames and ds.dims["node"] == 21 and ds.dims["link"] == 20
    assert ds["x"].dims == ("time", "node") and ds["T"].dims == ("time", "link")
    units = {"x": "m", "vy": "m/s", "T": "N", "K": "J", "drift": "J", "s0": "m", "time": "s", "s": "m"}
    for name, unit in units.items():
        assert ds[name].attrs["units"] == unit, name
    # the energy ledger closes in the exported data: drift = K + V - (K0 + V0) - the works
    works = ds["W_applied"] + ds["W_shocks"] + ds["W_heaps"] + ds["W_remesh"]
    ledger = ds["K"] + ds["V"] - (ds["K"][0] + ds["V"][0]) - works
    np.testing.assert_allclose(ledger, ds["drift"], atol=1e-12)
    path = result.to_netcdf(tmp_path / "run.nc")
    with xr.open_dataset(path) as back:
        for name in ("x", "vx", "T", "K", "s0", "front_position"):
            np.testing.assert_array_equal(back[name].values, ds[name].values, err_msg=name)
        np.testing.assert_array_equal(back["moving"].values, result.nodes["moving"])
        assert back["T"].attrs["units"] == "N"
        assert eval_json(back.attrs["summary"]) == result.summary
    reduced = chainsim.reduced("falling", f=0.5)
    rds = reduced.to_xarray()
    np.testing.assert_array_equal(rds["eta"].values, reduced.series["eta"])
    np.testing.assert_array_equal(reduced.to_dataframe()["eta"].to_numpy(), reduced.series["eta"])


def eval_json(text):
    import json
    return json.loads(text)


# ------------------------------------------------------------------------------------------------------------------
# Type hints, stubs and docstrings

def test_type_hints_and_the_stub_of_core():
    hints = typing.get_type_hints(chainsim.sweep)
    assert {"target", "grid", "t_end", "workers", "results", "progress", "return"} <= set(hints)
    assert typing.get_type_hints(chainsim.Scene.run)
    package = os.path.dirname(chainsim.__file__)
    assert os.path.exists(os.path.join(package, "py.typed")) and os.path.exists(os.path.join(package, "_core.pyi"))
    # the stub declares every public function of the compiled module, and nothing it lacks
    with open(os.path.join(package, "_core.pyi")) as fh:
        stub = set(re.findall(r"^def (\w+)", fh.read(), re.M))
    compiled = {n for n, v in vars(chainsim._core).items() if callable(v) and not n.startswith("_")
                and not isinstance(v, type)}
    assert stub == compiled


def public_callables():
    for name in chainsim.__all__:
        obj = getattr(chainsim, name)
        if name.startswith("__") or isinstance(obj, type) and issubclass(obj, Exception):
            continue
        yield name, obj
        if isinstance(obj, type):
            for attr, member in vars(obj).items():
                if not attr.startswith("_") and (callable(member) or isinstance(member, (property, classmethod))):
                    yield f"{name}.{attr}", getattr(obj, attr)


def test_every_public_name_has_a_numpydoc_docstring():
    docscrape = pytest.importorskip("numpydoc.docscrape")
    missing = []
    for name, obj in public_callables():
        doc = inspect.getdoc(obj)
        if not doc:
            missing.append(f"{name}: no docstring")
            continue
        if isinstance(obj, property) or not callable(obj):
            continue
        try:
            params = [p for p in inspect.signature(obj).parameters.values() if p.name not in ("self", "cls")]
        except (TypeError, ValueError):
            continue
        if not params:
            continue
        parsed = docscrape.FunctionDoc(obj) if not isinstance(obj, type) else docscrape.ClassDoc(obj)
        documented = {n.strip().lstrip("*") for p in parsed["Parameters"] for n in p.name.split(",")}
        undocumented = [p.name for p in params if p.name not in documented]
        if undocumented:
            missing.append(f"{name}: parameters without a numpydoc entry: {', '.join(undocumented)}")
    assert not missing, "\n".join(missing)


# ------------------------------------------------------------------------------------------------------------------
# Notebooks: HTML views, figures in memory

def test_html_views_of_scenes_and_results():
    scene = falling().set("stop.t_end", 0.1)
    view = scene._repr_html_()
    assert "falling_chain.toml" in view and "string.nodes=21" in view and "<table>" in view
    assert "<td>nodes</td><td>21</td>" in view
    result = scene.run()
    view = result._repr_html_()
    assert "completed" in view and str(result.summary["t_stop"]) in view and "nodes (" in view
    odd = chainsim.Scene(scene.text, source="<a & b>")
    assert "&lt;a &amp; b&gt;" in odd._repr_html_()


def test_plot_returns_figures_and_writes_only_when_asked(tmp_path, monkeypatch):
    from matplotlib.figure import Figure
    import matplotlib.pyplot as plt
    monkeypatch.chdir(tmp_path)
    result = falling().run(t_end=0.1)
    figures = result.plot()
    assert set(figures) == {"snapshots", "energy", "tension", "fronts"}
    assert all(isinstance(f, Figure) for f in figures.values())
    assert os.listdir(tmp_path) == [] and plt.get_fignums() == []   # nothing written, nothing left open
    result.plot(save="figs")
    assert sorted(os.listdir("figs")) == ["energy.png", "fronts.png", "snapshots.png", "tension.png"]
    paths = result.plot("run")   # the older form: the run directory and `chainsim plot`'s files
    assert os.path.exists("run/stats.json") and sorted(os.path.basename(p) for p in paths) == \
        ["energy.png", "fronts.png", "snapshots.png", "tension.png"]
    paths = chainsim.plot("run", animate=True, html=True, fps=10)   # `chainsim plot run --animate --html`
    assert paths[-1] == os.path.join("run", "figures", "animation.html") and os.path.exists(paths[-1])


# ------------------------------------------------------------------------------------------------------------------
# Progress bars

def test_progress_bars_on_request_and_off_when_not_a_terminal(capfd):
    pytest.importorskip("tqdm")
    scene = falling(11)
    grid = {"f": [0.0, 0.5, 1.0]}
    chainsim.sweep(scene, grid, t_end=0.05, workers=2)   # stderr is no terminal here: no bar
    chainsim.sweep(scene, grid, t_end=0.05, workers=2, progress=False)
    assert capfd.readouterr().err == ""
    chainsim.sweep(scene, grid, t_end=0.05, workers=2, progress=True)
    assert re.search(r"sweep: 100%.*3/3", capfd.readouterr().err)
    chainsim.sweep(scene, grid, t_end=0.05, workers=2, progress=True, results=True)
    assert re.search(r"sweep: 100%.*3/3", capfd.readouterr().err)
    chainsim.sweep("falling", grid, progress=True)
    assert re.search(r"sweep: 100%.*3/3", capfd.readouterr().err)
    with pytest.raises(chainsim.ChainsimInputError, match="progress = 'yes' must be True or False"):
        chainsim.sweep(scene, grid, progress="yes")


# ------------------------------------------------------------------------------------------------------------------
# The wheel, packed from this build (the slow test that compiles it from scratch: tests/docs/check_pip_install.sh)

def test_wheel_holds_the_module_the_plotting_tool_and_the_executable(tmp_path):
    sys.path.insert(0, os.path.join(SOURCE, "python", "build_backend"))
    try:
        import chainsim_build
    finally:
        sys.path.pop(0)
    if not os.path.exists(os.path.join(BUILD, "CMakeCache.txt")):
        pytest.skip(f"no build tree at {BUILD}")
    prefix = tmp_path / "prefix"
    packages = chainsim_build.install(BUILD, str(prefix))
    name = chainsim_build.pack_wheel(str(prefix), packages, str(tmp_path))
    version = chainsim.__version__
    assert name == f"chainsim-{version}-{chainsim_build.wheel_tag()}.whl"
    with zipfile.ZipFile(tmp_path / name) as zf:
        names = set(zf.namelist())
        core = [n for n in names if re.fullmatch(r"chainsim/_core\..*\.so", n)]
        assert len(core) == 1
        for n in ("chainsim/__init__.py", "chainsim/_results.py", "chainsim/py.typed", "chainsim/_core.pyi",
                  "chainsim_plot/cli.py", "chainsim_plot/animate.py", f"chainsim-{version}.data/scripts/chainsim",
                  f"chainsim-{version}.dist-info/METADATA", f"chainsim-{version}.dist-info/RECORD"):
            assert n in names, n
        assert (zf.getinfo(f"chainsim-{version}.data/scripts/chainsim").external_attr >> 16) & 0o111
        metadata = zf.read(f"chainsim-{version}.dist-info/METADATA").decode()
        assert f"\nVersion: {version}\n" in metadata and "\nName: chainsim\n" in metadata
        wheel = zf.read(f"chainsim-{version}.dist-info/WHEEL").decode()
        assert "Root-Is-Purelib: false" in wheel and f"Tag: {chainsim_build.wheel_tag()}" in wheel
        # RECORD: every file with its sha256 and size
        rows = list(csv.reader(io.StringIO(zf.read(f"chainsim-{version}.dist-info/RECORD").decode())))
        assert {r[0] for r in rows} == names
        for path, digest, size in rows:
            if digest:
                data = zf.read(path)
                expected = base64.urlsafe_b64encode(hashlib.sha256(data).digest()).rstrip(b"=").decode()
                assert digest == f"sha256={expected}" and int(size) == len(data), path
    # pip installs it into a fresh virtual environment, offline; the installed chainsim runs
    venv = tmp_path / "venv"
    subprocess.run([sys.executable, "-m", "venv", "--system-site-packages", str(venv)], check=True)
    env = {k: v for k, v in os.environ.items() if k != "PYTHONPATH"}
    subprocess.run([str(venv / "bin" / "python"), "-m", "pip", "install", "--no-index", "--no-deps", "-q",
                    str(tmp_path / name)], check=True, env=env)
    out = subprocess.run([str(venv / "bin" / "chainsim"), "--version"], capture_output=True, text=True, env=env)
    assert out.stdout.strip() == chainsim._core.version_text
    code = ("import chainsim, chainsim_plot; print(chainsim.__file__); "
            "print(chainsim.reduced('falling', f=0.5).summary['t_stop_over_t0_exact'])")
    out = subprocess.run([str(venv / "bin" / "python"), "-c", code], capture_output=True, text=True, env=env,
                         cwd=tmp_path, check=True)
    assert out.stdout.startswith(str(venv)), out.stdout
    run = tmp_path / "run"
    subprocess.run([str(venv / "bin" / "chainsim"), "run", os.path.join(SCENES, "hanging_chain.toml"), "--set",
                    "string.nodes=11", "--t-end", "0.05", "--out", str(run), "--quiet"], check=True, env=env)
    # the installed `chainsim plot` runs the installed plotting tool with the environment's interpreter
    out = subprocess.run([str(venv / "bin" / "chainsim"), "plot", str(run)], capture_output=True, text=True, env=env)
    assert out.returncode == 0 and os.path.exists(run / "figures" / "energy.png"), out.stderr
