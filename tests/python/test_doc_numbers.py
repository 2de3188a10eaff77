"""scripts/check_doc_numbers.py, the check of the numbers the docs quote: it catches the drifted quotes of
issue 25 (cli.md's 0.562526 s and its 311 steps, read against what the program prints), lets timings and the
round-off of residuals through, and matches `...` to any lines.

    CHAINSIM_BINARY=build/chainsim /usr/bin/python3 -m pytest -q tests/python/test_doc_numbers.py
"""
import os
import subprocess
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
SOURCE = os.path.abspath(os.path.join(HERE, "..", ".."))
BINARY = os.environ.get("CHAINSIM_BINARY", os.path.join(SOURCE, "build", "chainsim"))
SCRIPT = os.path.join(SOURCE, "scripts", "check_doc_numbers.py")
sys.path.insert(0, os.path.join(SOURCE, "scripts"))

import check_doc_numbers as check  # noqa: E402


def run_on(tmp_path, text):
    doc = tmp_path / "doc.md"
    doc.write_text(text)
    return subprocess.run([sys.executable, SCRIPT, "--build", os.path.dirname(os.path.abspath(BINARY)), str(doc)],
                          capture_output=True, text=True, timeout=120)


# cli.md as it was on main 50675e6 (issue 25): the allowed range and the sliding chain's step count drifted.
DRIFTED = """
```sh checked
$ build/chainsim run cases/scenes/sliding_chain.toml --out results/sliding_chain | grep -E '^run '
run        stopped at t = 0.573895 s (t_end = 2 s) in 0.022 s wall: 311 steps, 3550 rhs evaluations, 3531 tension solves, 80 crossings
$ build/chainsim plot results/sliding_chain --times 0,5
chainsim: error: --times: t = 5 s is outside the run: allowed 0 <= t <= 0.562526 s
```
"""


def test_drifted_quotes_fail_naming_the_number(tmp_path):
    r = run_on(tmp_path, DRIFTED)
    assert r.returncode == 1, r.stdout + r.stderr
    assert "311 is now" in r.stdout
    assert "0.562526 is now 0.573895" in r.stdout


def test_current_quotes_pass(tmp_path):
    # The sliding chain's `run` line as docs/cli.md quotes it now (the same command's quote, kept current by the
    # check of cli.md itself), in place of the drifted one.
    with open(os.path.join(SOURCE, "docs", "cli.md")) as f:
        current = next(line.rstrip("\n") for line in f if line.startswith("run        stopped at t = 0.573895 s"))
    drifted = next(line for line in DRIFTED.splitlines() if line.startswith("run "))
    fixed = DRIFTED.replace("0.562526", "0.573895").replace(drifted, current)
    r = run_on(tmp_path, fixed)
    assert r.returncode == 0, r.stdout + r.stderr


def test_timings_are_not_compared():
    assert check.compare(["run in 0.022 s wall: 241 steps"], ["run in 3.5 s wall: 241 steps"], 1e-3) is None
    assert check.compare(["ARKODE (order 8): 494 steps, wall 0.001 s"], ["ARKODE (order 8): 494 steps, wall 2 s"],
                         1e-3) is None
    assert check.compare(["6 points on 2 threads in 0.321 s"], ["6 points on 8 threads in 1.2 s"], 1e-3) is None
    assert check.compare(["(39 crossings, 160 steps, 0.0372 s)"], ["(39 crossings, 160 steps, 0.5 s)"], 1e-3) is None
    # but a count of steps or a time of the run is
    assert check.compare(["(39 crossings, 160 steps, 0.0372 s)"], ["(39 crossings, 170 steps, 0.0372 s)"], 1e-3)
    assert check.compare(["stopped at t = 0.573895 s"], ["stopped at t = 0.562526 s"], 1e-3)


def test_round_off_within_a_factor_of_3_and_text_exactly():
    assert check.compare(["energy residual 5.9e-13"], ["energy residual 1.2e-12"], 1e-3) is None
    assert check.compare(["energy residual 5.9e-13"], ["energy residual 7e-12"], 1e-3)
    assert check.compare(["ARKODE_FEHLBERG_13_7_8 (order 8)"], ["ARKODE_FEHLBERG_13_7_7 (order 8)"], 1e-3)
    assert check.compare(["outputs    d: nodes.csv"], ["outputs    d: nodes.csv series.csv"], 1e-3)


def test_ellipsis_matches_any_lines_and_order_counts():
    actual = ["a 1", "b 2", "c 3", "d 4"]
    assert check.compare(["a 1", "...", "d 4"], actual, 1e-3) is None
    assert check.compare(["...", "c 3", "..."], actual, 1e-3) is None
    assert check.compare(["a 1", "c 3"], actual, 1e-3)          # no ellipsis: every line, in order
    assert check.compare(["...", "c 3", "b 2", "..."], actual, 1e-3)
    assert check.compare(["a 1", "..."], ["a 1"], 1e-3) is None
