"""`chainsim plot RUN_DIR --animate --html`: one self-contained HTML page with play and scrub controls, every
frame embedded (docs/plotting.md). Parsed here without a browser (CTest "plot: html animation", seconds);
tests/docs/check_animation_html.py opens the page in headless Chromium.

    CHAINSIM_BINARY=build/chainsim /usr/bin/python3 -m pytest tests/python/test_animation_html.py
"""
import base64
import csv
import io
import math
import os
import re
import subprocess

HERE = os.path.dirname(os.path.abspath(__file__))
SOURCE = os.path.abspath(os.path.join(HERE, "..", ".."))
BINARY = os.environ.get("CHAINSIM_BINARY", os.path.join(SOURCE, "build", "chainsim"))
SCENE = os.path.join(SOURCE, "cases", "scenes", "hanging_chain.toml")


def frame_times(run_dir):
    with open(os.path.join(run_dir, "nodes.csv")) as fh:
        return sorted({float(row["t"]) for row in csv.DictReader(fh)})


def embedded_frames(text):
    """The PNG frames of the page, in the order of their indices (frames[k] = "data:image/png;base64,...")."""
    found = re.findall(r'frames\[(\d+)\] = "data:image/png;base64,([^"]*)"', text)
    assert [int(k) for k, _ in found] == list(range(len(found))), "frames not numbered 0, 1, 2, ..."
    return [base64.b64decode(data.replace("\\n", "")) for _, data in found]


def test_html_animation_embeds_every_frame_and_needs_no_network(tmp_path):
    from PIL import Image
    run = tmp_path / "run"
    subprocess.run([BINARY, "run", SCENE, "--set", "string.nodes=11", "--t-end", "0.4", "--out", str(run),
                    "--quiet"], check=True)
    fps, speed = 10, 0.5
    out = subprocess.run([BINARY, "plot", str(run), "--animate", "--html", "--fps", str(fps), "--speed", str(speed)],
                         capture_output=True, text=True)
    assert out.returncode == 0, out.stderr
    page = run / "figures" / "animation.html"
    assert str(page) in out.stdout.split()
    text = page.read_text()
    assert text.startswith("<!DOCTYPE html>") and text.rstrip().endswith("</html>")
    assert "http://" not in text and "https://" not in text   # nothing fetched: it opens offline
    for control in ('type="range"', "play_animation", "pause_animation", "set_frame"):
        assert control in text, control
    # the video's frame j shows t_first + j * speed / fps: floor((t_last - t_first) * fps / speed) + 1 frames
    times = frame_times(run)
    expected = math.floor((times[-1] - times[0]) * fps / speed + 1e-9) + 1
    frames = embedded_frames(text)
    assert len(frames) == expected == 9
    sizes = set()
    for png in frames:
        with Image.open(io.BytesIO(png)) as im:
            im.load()
            sizes.add(im.size)
    assert len(sizes) == 1
    assert frames[0] != frames[-1]   # the chain swings: the first and last frames differ


def test_html_is_a_format_of_the_animation(tmp_path):
    run = tmp_path / "run"
    subprocess.run([BINARY, "run", SCENE, "--set", "string.nodes=11", "--t-end", "0.05", "--out", str(run),
                    "--quiet"], check=True)
    alone = subprocess.run([BINARY, "plot", str(run), "--html"], capture_output=True, text=True)
    assert alone.returncode == 2 and "give it with --animate" in alone.stderr
    both = subprocess.run([BINARY, "plot", str(run), "--animate", "--html", "--format", "gif"], capture_output=True,
                          text=True)
    assert both.returncode == 2 and "--format = 'gif'" in both.stderr
    assert not os.path.exists(run / "figures")   # refused before anything is drawn
    same = subprocess.run([BINARY, "plot", str(run), "--animate", "--format", "html"], capture_output=True, text=True)
    assert same.returncode == 0 and (run / "figures" / "animation.html").exists(), same.stderr
