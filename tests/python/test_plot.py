"""`chainsim plot` on a run of each kind: the files it lists exist and are images, the animation has the
frames its speed and rate ask for (read back with Pillow or ffprobe), bad paths exit 2.

Run by CTest (tests/CMakeLists.txt) in three parts, with pytest when installed, else as a plain script:
    CHAINSIM_BINARY=build/chainsim /usr/bin/python3 tests/python/test_plot.py [NAME_PART ...]
"""
import atexit
import csv
import math
import os
import re
import shutil
import signal
import subprocess
import sys
import tempfile
import time

HERE = os.path.dirname(os.path.abspath(__file__))
SOURCE = os.path.abspath(os.path.join(HERE, "..", ".."))
BINARY = os.environ.get("CHAINSIM_BINARY", os.path.join(SOURCE, "build", "chainsim"))
sys.path.insert(0, os.path.join(SOURCE, "python"))

import numpy as np  # noqa: E402
from PIL import Image  # noqa: E402

ROOT = tempfile.mkdtemp(prefix="chainsim_plot_test_")
atexit.register(shutil.rmtree, ROOT, True)
_runs = {}


def chainsim(*args):
    return subprocess.run([BINARY, *args], capture_output=True, text=True)


def scene(name, nodes, extra=None):
    """cases/scenes/<name>.toml with `nodes` nodes (and other lines replaced), written to the temp dir."""
    with open(os.path.join(SOURCE, "cases", "scenes", name + ".toml")) as fh:
        text = fh.read()
    text = re.sub(r"(?m)^nodes = \d+", f"nodes = {nodes}", text)
    for pattern, line in (extra or {}).items():
        text = re.sub(pattern, line, text)
    path = os.path.join(ROOT, f"{name}_{len(_runs)}.toml")
    with open(path, "w") as fh:
        fh.write(text)
    return path


SCENE_3D = """
[string]
length = 0.7
density = 0.1
nodes = 15
dimension = 3
[shape]
kind = "polyline"
points = [[0.0, 0.0, 0.0], [0.7, 0.0, 0.0]]
[velocity]
kind = "uniform"
value = [0.0, 0.0, 1.0]
[ends]
start = "fixed"
[effects.gravity]
g = [0.0, -9.81, 0.0]
[output]
interval = 0.02
[stop]
t_end = 0.2
"""


def run_dir(kind):
    """A run of each kind, made once."""
    if kind in _runs:
        return _runs[kind]
    out = os.path.join(ROOT, kind)
    if kind == "string":
        args = ["run", scene("whip_crack", 21, {r"(?m)^t_end = .*": "t_end = 0.3"}), "--out", out]
    elif kind == "fronts":
        args = ["run", scene("falling_chain", 21), "--out", out]
    elif kind == "fold":
        args = ["run", scene("folded_chain", 21), "--out", out]
    elif kind == "edge":
        args = ["run", scene("chain_off_table_edge", 21), "--out", out]
    elif kind == "edge3d":  # the same, in 3D: the edge along z
        args = ["run", scene("chain_off_table_edge", 21, {
            r"(?m)^nodes = 21": "nodes = 21\ndimension = 3",
            r"\[\[-0.8, 0.0\], \[0.0, 0.0\], \[0.0, -0.2\]\]": "[[-0.8, 0.0, 0.0], [0.0, 0.0, 0.0], [0.0, -0.2, 0.0]]",
            r"g = \[0.0, -9.81\]": "g = [0.0, -9.81, 0.0]",
            r"(?m)^point = \[0.0, 0.0\]": "point = [0.0, 0.0, 0.0]\ndirection = [0.0, 0.0, 1.0]"}), "--out", out]
    elif kind == "peg":  # 1 m over a peg at the origin, 0.4 m down one side and 0.6 m the other
        args = ["run", scene("chain_over_peg", 21, {r"(?m)^t_end = .*": "t_end = 0.1"}), "--out", out]
    elif kind == "pulley":
        args = ["run", scene("atwood_pulley", 21, {r"(?m)^t_end = .*": "t_end = 0.1"}), "--out", out]
    elif kind == "pulley3d":  # the same in 3D, the pulley's axis along z
        args = ["run", scene("atwood_pulley", 21, {
            r"(?m)^t_end = .*": "t_end = 0.1", r"(?m)^nodes = 21": "nodes = 21\ndimension = 3",
            r"(?m)^points = .*": "points = [[-0.1, -0.2929203673205103, 0.0], [-0.1, 0.1, 0.0], [0.1, 0.1, 0.0], "
                                 "[0.1, -0.3929203673205103, 0.0]]",
            r"g = \[0.0, -9.81\]": "g = [0.0, -9.81, 0.0]",
            r"(?m)^center = \[0.0, 0.0\]": "center = [0.0, 0.0, 0.0]\naxis = [0.0, 0.0, 1.0]"}), "--out", out]
    elif kind == "landing":
        args = ["run", scene("chain_landing_on_table", 11, {r"(?m)^t_end = .*": "t_end = 0.15"}), "--out", out]
    elif kind == "real_table":
        args = ["run", scene("chain_off_real_table", 21), "--out", out]
    elif kind == "string3d":
        path = os.path.join(ROOT, "pendulum3d.toml")
        with open(path, "w") as fh:
            fh.write(SCENE_3D)
        args = ["run", path, "--out", out]
    elif kind == "reduced_scene":
        args = ["run", scene("falling_chain", 21, {r"(?m)^model = \"string\"": 'model = "reduced"'}), "--out", out]
    elif kind == "reduced":
        args = ["reduced", "sliding", "--eta0", "0.25", "--out", out]
    elif kind == "compare":
        args = ["compare", "folded", "--nodes", "21", "--out", out]
    elif kind in ("compare_edge", "compare_peg"):  # the string solver against the exact solution
        args = ["compare", kind[len("compare_"):], "--nodes", "21", "--out", out]
    elif kind == "compare_pulley":  # below about 41 nodes the chain does not start held on the pulley
        args = ["compare", "pulley", "--nodes", "41", "--out", out]
    elif kind == "canonical":
        args = ["canonical", "--out", out, "--quick"]
    r = chainsim(*args)
    assert r.returncode == 0, r.stderr
    _runs[kind] = out
    return out


def plot(directory, *options):
    return chainsim("plot", directory, *options)


def plot_here(directory, *options, stdout=False):
    """The package's entry point in this process (what `chainsim plot` runs, without starting Python again):
    (exit code, stderr), or (exit code, stdout) with stdout=True."""
    import contextlib
    import io
    from chainsim_plot.cli import main
    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stderr(err), contextlib.redirect_stdout(out):
        try:
            code = main([directory, *options])
        except SystemExit as e:  # argparse
            code = e.code
    return code, (out if stdout else err).getvalue()


def check_plot(kind, expected, *options, here=False, directory=None):
    """chainsim plot exits 0, prints exactly the expected files of RUN_DIR/figures, and each is a PNG.
    here=True: the package's entry point in this process instead of the binary (quicker). RUN_DIR is
    the run of `kind`, or `directory`."""
    directory = directory or run_dir(kind)
    if here:
        code, out = plot_here(directory, *options, stdout=True)
        assert code == 0
        listed = out.split()
    else:
        r = plot(directory, *options)
        assert r.returncode == 0, r.stderr
        listed = r.stdout.split()
    assert sorted(os.path.basename(p) for p in listed) == sorted(expected)
    for path in listed:
        assert os.path.dirname(os.path.abspath(path)) == os.path.abspath(os.path.join(directory, "figures"))
        if path.endswith(".png"):
            with Image.open(path) as im:
                assert im.format == "PNG" and im.size[0] >= 400 and im.size[1] >= 300
    return listed


def frame_times(directory):
    """The recorded frame times of nodes.csv, read here with the csv module."""
    with open(os.path.join(directory, "nodes.csv"), newline="") as fh:
        return sorted({float(row["t"]) for row in csv.DictReader(fh)})


# --- each kind of run -----------------------------------------------------------------------------

def test_kind_string_run_at_chosen_times():
    check_plot("string", ["snapshots.png", "energy.png", "tension.png"], "--times", "0,0.1,0.25")


def test_kind_run_with_fronts():
    check_plot("fronts", ["snapshots.png", "energy.png", "tension.png", "fronts.png"], here=True)


def test_kind_run_with_a_fold():
    check_plot("fold", ["snapshots.png", "energy.png", "tension.png", "fronts.png"], here=True)


def test_kind_3d_run():
    listed = check_plot("string3d", ["snapshots.png", "energy.png", "tension.png"], here=True)
    with Image.open(next(p for p in listed if p.endswith("snapshots.png"))) as im:
        assert im.size[0] > 1.5 * im.size[1]  # two projections side by side


def test_kind_reduced_runs():
    check_plot("reduced", ["reduced.png", "energy.png"], here=True)
    check_plot("reduced_scene", ["reduced.png", "energy.png"], here=True)


def test_kind_compare_run():
    check_plot("compare", ["compare.png", "energy.png", "fronts.png"], here=True)


def test_kind_compare_against_the_exact_solution():
    """chainsim compare edge|peg|pulley writes exact_series.csv, not reduced_series.csv: plot draws x(t) on the
    exact solution, the tensions and the reactions. Before, it refused them ("needs ... reduced_series.csv").
    The string's x drawn starts at the release's x0 and ends at the lift-off that summary.json records (the
    C++ side's measure), and the exact curve is exact_series.csv's x."""
    from chainsim_plot.cli import draw
    from chainsim_plot.readers import load_run, read_json
    import matplotlib.pyplot as plt
    for problem, x0, fronts in (("edge", 0.2, ["fronts.png"]), ("peg", 0.6, ["fronts.png"]), ("pulley", None, [])):
        directory = run_dir("compare_" + problem)
        check_plot(None, ["compare.png", "energy.png"] + fronts, here=True, directory=directory)
        summary = read_json(os.path.join(directory, "summary.json"))
        fig = draw(load_run(directory))["compare"]
        lines = {line.get_label(): line for line in fig.axes[0].lines}
        exact = lines["exact solution"].get_ydata()
        with open(os.path.join(directory, "exact_series.csv"), newline="") as fh:
            assert np.allclose(exact, [float(row["x"]) for row in csv.DictReader(fh)], rtol=0, atol=0)
        if x0 is not None:  # edge, peg: the edge front's s0 = l - x
            x = lines["string solver: l - s0 of the edge front"].get_ydata()
            assert abs(x[0] - x0) < 1e-8 and abs(x[-1] - summary["x_lift_off"]) < 1e-6
        assert any(label.startswith("lift-off, string solver: t = ") for label in lines)
        assert any(label.startswith("lift-off, exact: t = ") for label in lines)
        tensions = [line.get_label() for line in fig.axes[1].lines]
        assert any(label.startswith("tension_") for label in tensions)
        if problem != "pulley":
            assert "R_front0_y (string solver)" in tensions and "reaction F0_y (exact)" in tensions
        plt.close(fig)


def test_kind_canonical_run():
    # The figures scripts/plot_canonical.py draws (the same package function), as tests/problems/
    # test_canonical_job.cpp and the README name them.
    names = ["fall_time_vs_f.png", "agreement.png"]
    for problem in ("falling", "folded", "sliding"):
        names += [f"{problem}_chain.png", f"{problem}_snapshots.png"]
    check_plot("canonical", names, here=True)


def test_kind_run_after_compare_draws_only_the_run():
    # Before: compare's summary.json and series stayed beside the run's files, and plot drew compare.png and
    # fronts.png for a hanging chain. Now the run removes them (and the figures drawn of them), and plot
    # writes only under figures/.
    out = os.path.join(ROOT, "compare_then_run")
    assert chainsim("compare", "falling", "--nodes", "21", "--out", out).returncode == 0
    code, printed = plot_here(out, stdout=True)
    assert code == 0 and "compare.png" in printed
    r = chainsim("run", scene("hanging_chain", 21), "--out", out)
    assert r.returncode == 0, r.stderr
    before = sorted(os.listdir(out))
    assert "figures" not in before and "summary.json" not in before and "string_series.csv" not in before
    listed = check_plot(None, ["snapshots.png", "energy.png", "tension.png"], here=True, directory=out)
    assert sorted(os.listdir(os.path.join(out, "figures"))) == sorted(os.path.basename(p) for p in listed)
    assert sorted(f for f in os.listdir(out) if f != "figures") == before


# --- the animation --------------------------------------------------------------------------------

def expected_frames(directory, fps, speed):
    times = frame_times(directory)
    return int(math.floor((times[-1] - times[0]) * fps / speed + 1e-9)) + 1


def test_animation_gif_has_the_frames_of_its_speed_and_rate():
    directory = run_dir("string")
    r = plot(directory, "--animate", "--format", "gif", "--fps", "10", "--speed", "0.5")
    assert r.returncode == 0, r.stderr
    gif = os.path.join(directory, "figures", "animation.gif")
    assert gif in r.stdout.split()
    n = expected_frames(directory, 10, 0.5)
    assert n == 7  # 0.3 s at half speed, 10 frames per second: 0, 0.05, ..., 0.3 s
    with Image.open(gif) as im:
        assert im.n_frames == n
        assert abs(im.info["duration"] - 100) <= 10  # ms per frame at 10 fps


def test_animation_mp4_of_a_run_with_fronts():
    if shutil.which("ffmpeg") is None or shutil.which("ffprobe") is None:
        print("skipped: no ffmpeg")
        return
    directory = run_dir("fronts")
    r = plot(directory, "--animate", "--fps", "20")
    assert r.returncode == 0, r.stderr
    mp4 = os.path.join(directory, "figures", "animation.mp4")
    assert mp4 in r.stdout.split()
    probe = subprocess.run(["ffprobe", "-v", "error", "-count_frames", "-select_streams", "v:0", "-show_entries",
                            "stream=nb_read_frames,r_frame_rate", "-of", "csv=p=0", mp4],
                           capture_output=True, text=True, check=True)
    rate, frames = probe.stdout.strip().split(",")
    assert rate == "20/1"
    assert int(frames) == expected_frames(directory, 20, 1.0)


# --- bad input ------------------------------------------------------------------------------------

def test_error_bad_paths_exit_2():
    # Through the binary once (the exit code passes through), then in this process.
    missing = os.path.join(ROOT, "no_such_run")
    r = plot(missing)
    assert r.returncode == 2 and r.stderr.startswith(f"chainsim: error: RUN_DIR '{missing}' does not exist")
    a_file = os.path.join(ROOT, "a_file")
    open(a_file, "w").close()
    code, err = plot_here(a_file)
    assert code == 2 and f"RUN_DIR '{a_file}' is not a directory" in err
    empty = os.path.join(ROOT, "empty_dir")
    os.makedirs(empty, exist_ok=True)
    code, err = plot_here(empty)
    assert code == 2 and "holds none of the files chainsim writes" in err
    assert not os.path.exists(os.path.join(empty, "figures"))


def test_error_malformed_file_exits_2_naming_the_line():
    broken = os.path.join(ROOT, "broken")
    shutil.copytree(run_dir("string"), broken, ignore=shutil.ignore_patterns("figures"))
    with open(os.path.join(broken, "energy.csv")) as fh:
        lines = fh.readlines()
    lines[3] = lines[3].split(",")[0] + ",oops\n"
    with open(os.path.join(broken, "energy.csv"), "w") as fh:
        fh.writelines(lines)
    code, err = plot_here(broken)
    assert code == 2
    assert f"{os.path.join(broken, 'energy.csv')}:4: 2 fields, but the header has 5" in err
    assert not os.path.exists(os.path.join(broken, "figures"))


def test_error_canonical_directory_missing_a_file_exits_2():
    fake = os.path.join(ROOT, "fake_canonical")
    os.makedirs(os.path.join(fake, "figure_data"), exist_ok=True)
    with open(os.path.join(fake, "summary.csv"), "w") as fh:
        fh.write("problem,f,nodes\nfalling,0.5,41\n")
    code, err = plot_here(fake)
    assert code == 2 and f"{os.path.join(fake, 'figure_data', 'fall_time_vs_f.csv')}: missing" in err
    assert not os.path.exists(os.path.join(fake, "figures"))
    code, err = plot_here(fake, "--animate")
    assert code == 2 and "--animate needs node frames" in err


def test_error_compare_directory_without_a_reference_exits_2_naming_what_plots():
    """string_series.csv with neither reduced_series.csv nor exact_series.csv: exit 2, the message naming
    both references and what each compare draws."""
    out = os.path.join(ROOT, "compare_no_reference")
    shutil.copytree(run_dir("compare_edge"), out)
    os.remove(os.path.join(out, "exact_series.csv"))
    code, err = plot_here(out)
    assert code == 2
    for word in ("reduced_series.csv", "exact_series.csv", "edge|peg|pulley", "falling|folded|sliding",
                 "it has only string_series.csv"):
        assert word in err, err


def test_error_mixed_directory_exits_2():
    # A directory an older chainsim left mixed: a run's stats.json beside compare's summary.json.
    out = os.path.join(ROOT, "mixed")
    shutil.copytree(run_dir("compare"), out)
    shutil.copy(os.path.join(run_dir("string"), "stats.json"), out)
    code, err = plot_here(out)
    assert code == 2
    assert "mixes the outputs of two commands: stats.json of `chainsim run` beside summary.json" in err


def test_error_directory_in_use_exits_2_and_plot_holds_it_as_runs_do():
    # plot takes the lock every command that writes a run takes: refused while a run writes the directory,
    # and a run is refused while plot draws.
    from chainsim_plot.readers import holding
    out = os.path.join(ROOT, "in_use")
    run = subprocess.Popen([BINARY, "run", scene("hanging_chain", 21), "--out", out, "--quiet", "--t-end", "1000",
                            "--max-wall", "60"], stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    try:
        lock = os.path.join(out, ".chainsim.lock")
        for _ in range(1000):
            if os.path.exists(lock) and open(lock).read() == f"{run.pid}\n":
                break
            time.sleep(0.01)
        code, err = plot_here(out)
        assert code == 2
        assert f"RUN_DIR '{out}' is in use by another chainsim process (pid {run.pid})" in err
    finally:
        run.send_signal(signal.SIGINT)
        assert run.wait(timeout=60) == 130
    with holding(out):
        r = chainsim("run", scene("hanging_chain", 21), "--out", out)
        assert r.returncode == 2
        assert f"is in use by another chainsim process (pid {os.getpid()})" in r.stderr
    assert not os.path.exists(os.path.join(out, ".chainsim.lock"))
    assert plot_here(out)[0] == 0


def test_error_bad_options_exit_2():
    directory = run_dir("string")
    for options, message in [(["--speed", "0"], "--speed = 0 is out of range: allowed speed > 0"),
                             (["--fps", "x"], "--fps = 'x' is not an integer"),
                             (["--times", "0,9"], "--times: t = 9 s is outside the run: allowed 0 <= t <= 0.3 s"),
                             (["--format", "avi"], "--format = 'avi' is not a known format: allowed mp4, gif")]:
        code, err = plot_here(directory, *options)
        assert code == 2, options
        assert err.startswith("chainsim: error: " + message), err
    code, err = plot_here(run_dir("reduced"), "--animate")
    assert code == 2 and "--animate needs nodes.csv" in err


# --- the readers and the interpolation against independent references ----------------------------

def test_reader_frames_match_the_csv_rows():
    from chainsim_plot.readers import load_run
    directory = run_dir("fronts")
    run = load_run(directory)
    with open(os.path.join(directory, "nodes.csv"), newline="") as fh:
        rows = list(csv.DictReader(fh))
    assert list(run.nodes.times) == frame_times(directory)
    k = len(run.nodes) // 2
    t = run.nodes.times[k]
    mine = [r for r in rows if float(r["t"]) == t]
    assert list(run.nodes.nodes(k)) == [int(r["node"]) for r in mine]
    assert np.array_equal(run.nodes.positions(k), [[float(r["x"]), float(r["y"])] for r in mine])
    assert [f.name for f in run.fronts] == ["heap_end"] and run.fronts[0].on_plane


def csv_frames(directory):
    """nodes.csv read here with the csv module: {t: [row, ...]} in file order."""
    frames = {}
    with open(os.path.join(directory, "nodes.csv"), newline="") as fh:
        for row in csv.DictReader(fh):
            frames.setdefault(float(row["t"]), []).append(row)
    return frames


def csv_series(directory):
    """series.csv read here with the csv module: {t: row} (a frame's time is one of its rows)."""
    with open(os.path.join(directory, "series.csv"), newline="") as fh:
        return {float(row["t"]): row for row in csv.DictReader(fh)}


def test_reader_frames_carry_s_and_velocities():
    from chainsim_plot.readers import load_run
    directory = run_dir("fronts")
    frames = load_run(directory).nodes
    rows = csv_frames(directory)
    assert frames.has_s and frames.has_velocity
    for k in (0, len(frames) // 2, len(frames) - 1):
        mine = rows[frames.times[k]]
        assert np.array_equal(frames.s(k), [float(r["s"]) for r in mine])
        assert np.array_equal(frames.velocities(k), [[float(r["vx"]), float(r["vy"])] for r in mine])


def test_reader_heap_drawn_at_the_contact_of_the_series():
    """The falling chain's snapshots: the string drawn from nodes.csv ends at the contact of series.csv,
    on the table of stats.json, by a partial link as long as the material between the last moving node
    and the front (the link is straight and inextensible); the heap sits at the contact and grows."""
    from chainsim_plot.figures import Layout
    from chainsim_plot.readers import load_run
    import json
    directory = run_dir("fronts")
    run = load_run(directory)
    layout = Layout(run)
    with open(os.path.join(directory, "stats.json")) as fh:
        info = json.load(fh)["fronts"][0]
    point, normal = np.array(info["point"]), np.array(info["plane_normal"])
    rows, series = csv_frames(directory), csv_series(directory)
    sizes = []
    for k, t in enumerate(run.nodes.times):
        row, last = series[t], rows[t][-1]
        contact = np.array([float(row["front_0_x"]), float(row["front_0_y"])])
        node = np.array([float(last["x"]), float(last["y"])])
        curve = layout.curve(k)
        assert np.array_equal(curve[-1], contact) and np.array_equal(curve[-2], node)
        assert abs(np.dot(contact - point, normal)) < 1e-12
        assert abs(np.linalg.norm(contact - node) - (float(row["s0_0"]) - float(last["s"]))) < 1e-10
        [(front, where, size)] = layout.heaps(t)
        assert front.name == info["name"] and np.array_equal(where, contact)
        sizes.append(size)
    assert sizes == sorted(sizes) and sizes[-1] > sizes[0]


def test_reader_fold_drawn_between_its_arms():
    """The folded chain's snapshots: the fold of series.csv is the corner of the drawn string, between
    the nodes either side of s0 (each at its material distance from the fold), the arm past it drawn
    aside by the amount the figure states."""
    from chainsim_plot.figures import Layout
    from chainsim_plot.readers import load_run
    directory = run_dir("fold")
    run = load_run(directory)
    layout = Layout(run)
    assert layout.aside > 0
    rows, series = csv_frames(directory), csv_series(directory)
    for k, t in enumerate(run.nodes.times):
        s0 = float(series[t]["s0_0"])
        fold = np.array([float(series[t]["front_0_x"]), float(series[t]["front_0_y"])])
        s = np.array([float(r["s"]) for r in rows[t]])
        x = np.array([[float(r["x"]), float(r["y"])] for r in rows[t]])
        j = int(np.sum(s <= s0))  # nodes 0..j-1: the resting arm; j..: the moving arm
        if j == len(s):
            continue
        if j > 0:
            assert abs(np.linalg.norm(x[j - 1] - fold) - (s0 - s[j - 1])) < 1e-10
        assert abs(np.linalg.norm(x[j] - fold) - (s[j] - s0)) < 1e-10
        drawn = x.copy()
        drawn[j:, 0] += layout.aside
        bar = [fold, fold + [layout.aside, 0]]  # from the resting arm's side to the moving arm's
        assert np.allclose(layout.curve(k), np.vstack([drawn[:j], bar, drawn[j:]]), rtol=0, atol=1e-15)
        [(front, marker)] = layout.front_markers(t)
        assert front.kind == "fold" and np.allclose(marker, fold + [layout.aside / 2, 0], rtol=0, atol=1e-15)


def test_reader_hermite_interpolation_is_exact_for_cubics():
    from chainsim_plot.figures import hermite
    t = np.array([0.0, 0.3, 0.35, 1.0])
    q = 2 * t**3 - t**2 + 0.5 * t - 1
    dq = 6 * t**2 - 2 * t + 0.5
    at = np.linspace(0, 1, 41)
    assert np.max(np.abs(hermite(t, q, dq, at) - (2 * at**3 - at**2 + 0.5 * at - 1))) < 1e-14


if __name__ == "__main__":
    # Without pytest: every test, or those whose name contains one of the arguments.
    failures = 0
    for name, test in sorted((n, f) for n, f in globals().items() if n.startswith("test_") and callable(f)):
        if len(sys.argv) > 1 and not any(word in name for word in sys.argv[1:]):
            continue
        try:
            test()
            print("ok  ", name)
        except Exception as e:  # noqa: BLE001
            failures += 1
            print("FAIL", name, repr(e))
    sys.exit(1 if failures else 0)


# --- the obstacles: one drawing for the snapshots and the animation ---------------------------------

def obstacle_artists(fig):
    """{gid: artist} of the obstacles drawn on the figure's first axes (gids "obstacle NAME", "table NAME")."""
    ax = fig.axes[0]
    return {a.get_gid(): a for a in list(ax.patches) + list(ax.lines)
            if a.get_gid() and a.get_gid().split()[0] in ("obstacle", "table")}


def drawn_figures(directory):
    """(snapshots figure, animation figure) of the run, drawn in this process (the animation to a GIF at
    1 frame per second), kept open to read their artists."""
    import matplotlib.pyplot as plt
    from chainsim_plot import animate as anim_module
    from chainsim_plot.figures import draw_snapshots
    from chainsim_plot.readers import load_run
    run = load_run(directory)
    fig, ax = plt.subplots()
    draw_snapshots([ax], run, [0, len(run.nodes) - 1])
    kept = []
    close = anim_module.plt.close
    anim_module.plt.close = kept.append
    try:
        anim_module.animate(run, os.path.join(ROOT, os.path.basename(directory) + "_obstacles"), fps=1, fmt="gif")
    finally:
        anim_module.plt.close = close
    return fig, kept[0]


def test_reader_edge_drawn_as_an_obstacle_in_snapshots_and_animation():
    """The chain off the table's edge (edge at the origin, the table before it along -x, the string hanging
    along -y from it, cases/scenes/chain_off_table_edge.toml): a grey wedge at the origin between -x and -y,
    and the table's face from the origin along -x past the chain's far end (x = -0.8 m), the same in the
    snapshots and in the animation's frames."""
    import matplotlib.pyplot as plt
    for fig in drawn_figures(run_dir("edge")):
        drawn = obstacle_artists(fig)
        assert sorted(drawn) == ["obstacle edge0", "table edge0"]
        wedge = drawn["obstacle edge0"].get_xy()[:3]
        assert np.allclose(wedge[0], [0, 0], atol=1e-9)
        r = np.linalg.norm(wedge[1])
        assert r > 0 and np.allclose(wedge[1:], [[-r, 0], [0, -r]], atol=1e-9 * r + 1e-12)
        x, y = drawn["table edge0"].get_data()
        assert np.allclose([x[0], y[0]], [0, 0], atol=1e-12) and np.allclose(y, 0, atol=1e-12)
        assert x[1] < -0.8
        plt.close(fig)


def test_reader_3d_edge_drawn_where_the_projection_sees_it():
    """The chain off the table's edge in 3D, the edge along z: on x-y as in 2D (wedge between -x and -y, the
    table along -x); on x-z the hanging side and the table (the plane y = 0) are seen face-on: a marker at
    the edge, no table line."""
    import matplotlib.pyplot as plt
    from chainsim_plot.figures import Layout
    from chainsim_plot.readers import load_run
    run = load_run(run_dir("edge3d"))
    layout = Layout(run)
    fig, axes = plt.subplots(1, 2)
    for ax, proj in zip(axes, layout.projections):
        layout.draw_obstacles(ax, proj)
    xy = {a.get_gid(): a for a in list(axes[0].patches) + list(axes[0].lines) if a.get_gid()}
    xz = {a.get_gid(): a for a in list(axes[1].patches) + list(axes[1].lines) if a.get_gid()}
    assert sorted(xy) == ["obstacle edge0", "table edge0"] and sorted(xz) == ["obstacle edge0"]
    wedge = xy["obstacle edge0"].get_xy()[:3]
    r = np.linalg.norm(wedge[1])
    assert np.allclose(wedge, [[0, 0], [-r, 0], [0, -r]], atol=1e-9)
    assert np.allclose(np.ravel(xz["obstacle edge0"].get_data()), 0, atol=1e-12)
    plt.close(fig)


def test_reader_peg_drawn_as_a_disc_inside_the_bend():
    """The chain over a peg (cases/scenes/chain_over_peg.toml: both sides hang straight down from the origin,
    a 180 degree turn) would have a wedge of no area between its arms: the peg is a disc below the point,
    touching it, in the snapshots and in the animation's frames; staggered snapshots draw one over each copy,
    at the same offsets as the string's (where the front markers are)."""
    import matplotlib.pyplot as plt
    from chainsim_plot.figures import Layout, choose_times, draw_snapshots
    from chainsim_plot.readers import load_run
    for fig in drawn_figures(run_dir("peg")):
        assert sorted(obstacle_artists(fig)) == ["obstacle edge0"]
        discs = sorted((p for p in fig.axes[0].patches if p.get_gid() == "obstacle edge0"), key=lambda d: d.center[0])
        r = discs[0].radius
        assert r > 0 and np.allclose(discs[0].center, [0, -r], atol=1e-9 * r)
        assert all(d.radius == r and abs(d.center[1] + r) < 1e-9 * r for d in discs)
        plt.close(fig)
    run = load_run(run_dir("peg"))
    layout = Layout(run)
    assert layout.stagger > 0
    fig, ax = plt.subplots()
    picks = choose_times(run.nodes.times, count=3)
    draw_snapshots([ax], run, picks, layout)
    discs = [p for p in ax.patches if p.get_gid() == "obstacle edge0"]
    assert len(discs) == len(picks)
    assert np.allclose(sorted(d.center[0] for d in discs), [q * layout.stagger for q in range(len(picks))])
    plt.close(fig)


def test_reader_surface_and_cylinder_drawn_as_obstacles():
    """Contact along arcs: the pulley of cases/scenes/atwood_pulley.toml (centre at the origin, radius 0.1 m)
    is a disc, the table of cases/scenes/chain_landing_on_table.toml (y = 0) a grey line along it, in the
    snapshots and in the animation's frames."""
    import matplotlib.pyplot as plt
    for fig in drawn_figures(run_dir("pulley")):
        drawn = obstacle_artists(fig)
        assert sorted(drawn) == ["obstacle cylinder0"]
        disc = drawn["obstacle cylinder0"]
        assert np.allclose(disc.center, [0, 0], atol=1e-12) and abs(disc.radius - 0.1) < 1e-12
        plt.close(fig)
    for fig in drawn_figures(run_dir("landing")):
        drawn = obstacle_artists(fig)
        assert sorted(drawn) == ["obstacle surface0"]
        x, y = drawn["obstacle surface0"].get_data()
        assert np.allclose(y, 0, atol=1e-12) and x[0] < 0 and x[1] > 1.0
        plt.close(fig)


def test_reader_3d_cylinder_drawn_in_every_view():
    """The Atwood pulley in 3D, its axis along z: a disc on x-y (the axis normal to the view); on x-z, where the
    axis lies in the view, its silhouette, the band |x| <= R along z across the picture (it used to be left out)."""
    import matplotlib.pyplot as plt
    from chainsim_plot.figures import Layout
    from chainsim_plot.readers import load_run
    run = load_run(run_dir("pulley3d"))
    layout = Layout(run)
    fig, axes = plt.subplots(1, 2)
    for ax, proj in zip(axes, layout.projections):
        layout.draw_obstacles(ax, proj)
    xy = {a.get_gid(): a for a in axes[0].patches if a.get_gid()}
    xz = {a.get_gid(): a for a in axes[1].patches if a.get_gid()}
    assert sorted(xy) == ["obstacle cylinder0"] and sorted(xz) == ["obstacle cylinder0"]
    assert np.allclose(xy["obstacle cylinder0"].center, [0, 0], atol=1e-12)
    band = xz["obstacle cylinder0"].get_xy()
    assert np.allclose(sorted(set(np.round(band[:, 0], 12))), [-0.1, 0.1])
    assert band[:, 1].min() < -0.2 and band[:, 1].max() > 0.2
    plt.close(fig)


def test_reader_table_ending_at_its_edge_drawn_up_to_the_edge():
    """A table that ends at its edge (cases/scenes/chain_off_real_table.toml: the plane y = 0 for x < 0, its
    edge at the origin): the surface is drawn from the edge along -x only, never past the edge (x > 0)."""
    import matplotlib.pyplot as plt
    for fig in drawn_figures(run_dir("real_table")):
        drawn = obstacle_artists(fig)
        assert "obstacle surface0" in drawn and "obstacle edge0" in drawn
        x, y = drawn["obstacle surface0"].get_data()
        assert np.allclose(y, 0, atol=1e-12)
        assert np.allclose(x[0], 0, atol=1e-12) and x[1] < -0.8 and max(x) <= 1e-12
        plt.close(fig)


def test_reader_run_without_obstacles_draws_none():
    """A run with no edge draws no obstacle: the free whip draws nothing but the string and its markers;
    the falling chain draws its plane (table) as before, and no edge."""
    import matplotlib.pyplot as plt
    for fig in drawn_figures(run_dir("string")):
        assert obstacle_artists(fig) == {}
        assert not fig.axes[0].patches
        plt.close(fig)
    fig, anim_fig = drawn_figures(run_dir("fronts"))
    for f in (fig, anim_fig):
        assert obstacle_artists(f) == {} and not f.axes[0].patches
    assert "plane (table)" in [line.get_label() for line in fig.axes[0].lines]
    plt.close(fig)
    plt.close(anim_fig)
