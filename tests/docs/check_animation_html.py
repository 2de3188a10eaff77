#!/usr/bin/python3
"""The HTML animation of `chainsim plot --animate --html` in a real browser: headless Chromium (Debian's chromium)
opens the page from the file system, offline, then a probe added to a copy of the page plays it and scrubs it.
Checked: the Animation object holds every frame (floor((t_last - t_first) * fps / speed) + 1, from nodes.csv),
every frame decodes as an image, the slider spans them, Play runs to the last frame and stops there (mode
"once"), and setting the slider to 0 shows the first frame again. Exit 0 when all hold, 1 otherwise.

Run by the docs stage of CI (`bash scripts/quickstart.sh docs` runs every tests/docs/check_*), or by hand:
    CHAINSIM_BINARY=build/chainsim /usr/bin/python3 tests/docs/check_animation_html.py
"""
import csv
import math
import os
import re
import shutil
import subprocess
import sys
import tempfile

HERE = os.path.dirname(os.path.abspath(__file__))
SOURCE = os.path.abspath(os.path.join(HERE, "..", ".."))
BINARY = os.environ.get("CHAINSIM_BINARY", os.path.join(SOURCE, "build", "chainsim"))
FPS, SPEED = 10, 0.5

PROBE = """
<script>
window.addEventListener("load", function () {
  setTimeout(function () {
    var name = Object.keys(window).filter(function (k) { return /^anim[0-9a-f]+$/.test(k); })[0];
    var a = window[name], body = document.body, img = document.getElementById(a.img_id);
    var slider = document.getElementById(a.slider_id);
    body.setAttribute("data-frames", a.frames.length);
    body.setAttribute("data-decoded", a.frames.filter(function (f) { return f.complete && f.naturalWidth > 0; }).length);
    body.setAttribute("data-slider-max", slider.max);
    a.play_animation();
    setTimeout(function () {
      body.setAttribute("data-played-to", a.current_frame);
      body.setAttribute("data-shows-last", img.src === a.frames[a.frames.length - 1].src ? "yes" : "no");
      slider.value = 0;
      slider.dispatchEvent(new Event("input"));
      body.setAttribute("data-scrubbed", img.src === a.frames[0].src && a.current_frame === 0 ? "yes" : "no");
      body.setAttribute("data-probe", "done");
    }, 4000);
  }, 1000);
});
</script>
"""


def fail(message):
    print(f"check_animation_html: FAILED: {message}")
    return 1


def main():
    chromium = shutil.which("chromium") or shutil.which("chromium-browser")
    if chromium is None:
        return fail("Chromium is not installed (Debian package chromium)")
    with tempfile.TemporaryDirectory() as tmp:
        run = os.path.join(tmp, "run")
        subprocess.run([BINARY, "run", os.path.join(SOURCE, "cases", "scenes", "hanging_chain.toml"), "--set",
                        "string.nodes=11", "--t-end", "0.4", "--out", run, "--quiet"], check=True)
        subprocess.run([BINARY, "plot", run, "--animate", "--html", "--fps", str(FPS), "--speed", str(SPEED)],
                       check=True, stdout=subprocess.DEVNULL)
        with open(os.path.join(run, "nodes.csv")) as fh:
            times = sorted({float(row["t"]) for row in csv.DictReader(fh)})
        expected = math.floor((times[-1] - times[0]) * FPS / SPEED + 1e-9) + 1
        with open(os.path.join(run, "figures", "animation.html")) as fh:
            page = fh.read()
        probe = os.path.join(tmp, "probe.html")
        with open(probe, "w") as fh:
            fh.write(page.replace("</body>", PROBE + "</body>"))
        command = [chromium, "--headless", "--no-sandbox", "--disable-gpu", "--no-first-run",
                   f"--user-data-dir={os.path.join(tmp, 'profile')}", "--virtual-time-budget=30000", "--dump-dom",
                   "file://" + probe]
        r = subprocess.run(command, capture_output=True, text=True, timeout=180)
        body = re.search(r"<body([^>]*)>", r.stdout)
        if r.returncode != 0 or body is None:
            return fail(f"chromium exited {r.returncode}: {r.stderr[-2000:]}")
        found = dict(re.findall(r'data-([a-z-]+)="([^"]*)"', body.group(1)))
        want = {"probe": "done", "frames": str(expected), "decoded": str(expected),
                "slider-max": str(expected - 1), "played-to": str(expected - 1), "shows-last": "yes",
                "scrubbed": "yes"}
        wrong = {k: (found.get(k), v) for k, v in want.items() if found.get(k) != v}
        if wrong:
            return fail("in Chromium, " + "; ".join(f"{k} = {got} (expected {v})" for k, (got, v) in wrong.items()))
        print(f"check_animation_html: ok: Chromium ({chromium}) shows the {expected} frames of "
              f"{os.path.getsize(os.path.join(run, 'figures', 'animation.html'))} bytes of HTML, plays them to the "
              f"last and scrubs back to the first")
    return 0


if __name__ == "__main__":
    sys.exit(main())
