#!/usr/bin/env python3
r"""Runs every command the docs quote with its output, and compares what it prints now with the quote.

A quoted output is a fenced block whose info string is `sh checked` (GitHub and the site show it as `sh`; the
words after `sh` are ignored by both):

    ```sh checked
    $ build/chainsim reduced falling --f 1.5
    chainsim: error: --f = 1.5 is out of range: allowed 0 <= f <= 1
    ```

- A line starting with `$ ` is a command (a line ending in `\` continues it); the lines up to the next command
  are its expected output (stdout and stderr together, as a terminal shows them). A line `...` stands for any
  number of lines (a quote may leave out the middle of a report).
- The commands of one file run in order, with bash, in one scratch directory per file (so a command may use
  what an earlier one of the same file wrote, `results/...`), which holds links to the repository's `cases/`,
  `examples/`, `python/`, `scripts/` and to the build tree as `build/`; `build/` is also first on PATH (a quote
  may say `chainsim ...`).
- The output is compared line by line: the text between numbers must be equal (runs of blanks count as one),
  and each number must match within the tolerance: relative 1e-3 (`rtol=...` after `checked` sets another for
  a block), and a number of magnitude below 1e-8 (round-off: residuals, errors at the integrators' tolerance)
  within a factor of 3 of the quote, or both below 1e-15.
- Timings are not compared: they carry their machine and date. A timing is a number after `wall`, a number of
  seconds after `in` (`in 0.022 s`) or after `steps,` in a parenthesis (`238 steps, 0.00981 s)`), and a
  `wall_s` / `wall_time_s` value; so is the count of threads (`on 2 threads`: the machine's cores). A block
  whose output has timings in other places says where: `timings=REGEX` (no blanks: `\s`) after `checked`,
  and the numbers inside a match of REGEX in a quoted line are not compared (`timings=(\s+[\d.]+){3}$`: the
  last three numbers of a line).

Usage: /usr/bin/python3 scripts/check_doc_numbers.py [--build BUILD_DIR] [FILE.md ...]
(default: README.md and docs/*.md). Exit 0 if every quote matches, 1 otherwise (each difference printed with
its file and line), 2 for bad usage.
"""
import argparse
import math
import os
import pathlib
import re
import shutil
import subprocess
import sys
import tempfile
import time

ROOT = pathlib.Path(__file__).resolve().parent.parent
NUMBER = re.compile(r"(?<![A-Za-z_\d.])(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?")
RTOL = 1e-3
ROUNDOFF = 1e-8       # below this, a number is round-off: compared within a factor FACTOR
FACTOR = 3.0
ZERO = 1e-15
# (text before, text after) of a number that is a timing or a count of the machine's cores.
EXCLUDED = [(re.compile(r"wall\s*$"), None),
            (re.compile(r"\bin\s*$"), re.compile(r"^\s*s\b")),
            (re.compile(r"steps,\s*$"), re.compile(r"^\s*s\)")),
            (re.compile(r"\"wall(_time)?_s\":\s*$"), None),
            (None, re.compile(r"^\s*threads\b"))]
LINKS = ("cases", "examples", "python", "scripts", "docs")


class Block:
    def __init__(self, path, line, options):
        self.path, self.line, self.options = path, line, options
        self.commands = []  # (line, command, expected lines)


def blocks(path):
    """The checked blocks of a Markdown file."""
    out, block, command = [], None, None
    for number, text in enumerate(path.read_text().splitlines(), 1):
        stripped = text.strip()
        if block is None:
            words = stripped[3:].split() if stripped.startswith("```") else []
            if words[:2] == ["sh", "checked"]:
                options = dict(w.split("=", 1) for w in words[2:] if "=" in w)
                block = Block(path, number, options)
                indent = len(text) - len(text.lstrip())
            continue
        if stripped.startswith("```"):
            out.append(block)
            block, command = None, None
            continue
        text = text[indent:] if text[:indent].strip() == "" else text
        if command is not None and command[1].endswith("\\"):
            command[1] += "\n" + text
        elif text.startswith("$ "):
            command = [number, text[2:], []]
            block.commands.append(command)
        elif command is not None:
            command[2].append(text)
        else:
            raise SystemExit(f"{path}:{number}: a checked block must start with a command ('$ ...')")
    if block is not None:
        raise SystemExit(f"{path}:{block.line}: the checked block is not closed")
    return out


def split(line):
    """A line as (texts, numbers): texts[i] precedes numbers[i]; blanks collapsed."""
    texts, numbers, last = [], [], 0
    for m in NUMBER.finditer(line):
        texts.append(line[last:m.start()])
        numbers.append((m.group(), m.start(), m.end()))
        last = m.end()
    texts.append(line[last:])
    return [" ".join(t.split()) if t.strip() else (" " if t else "") for t in texts], numbers


def excluded(line, start, end, ignore=None):
    if ignore is not None and any(m.start() <= start and end <= m.end() for m in ignore.finditer(line)):
        return True
    before, after = line[:start], line[end:]
    for b, a in EXCLUDED:
        if (b is None or b.search(before)) and (a is None or a.search(after)):
            return True
    return False


def close(quoted, now, rtol):
    a, b = float(quoted), float(now)
    if abs(a) < ZERO and abs(b) < ZERO:
        return True
    if abs(a) < ROUNDOFF:
        return b > 0 and a / FACTOR <= b <= a * FACTOR if a > 0 else abs(b) < ZERO
    return abs(a - b) <= rtol * max(abs(a), abs(b))


def line_difference(quoted, now, rtol, ignore=None):
    """None if the lines match, else what differs."""
    qt, qn = split(quoted)
    nt, nn = split(now)
    if qt != nt or len(qn) != len(nn):
        return "the text differs"
    for (q, qs, qe), (n, _, _) in zip(qn, nn):
        if excluded(quoted, qs, qe, ignore):
            continue
        if not close(q, n, rtol):
            return f"{q} is now {n}"
    return None


def compare(expected, actual, rtol, ignore=None):
    """None if the actual lines match the expected ones (a line `...` matching any lines), else a message."""
    actual = [a.rstrip() for a in actual]
    expected = [e.rstrip() for e in expected]
    while actual and not actual[-1]:
        actual.pop()
    while expected and not expected[-1]:
        expected.pop()
    # Greedy, in order: each quoted line matches the next actual line, or after a `...` the first that fits.
    at, gap = 0, False
    for q in expected:
        if q.strip() == "...":
            gap = True
            continue
        tried = at
        while at < len(actual) and line_difference(q, actual[at], rtol, ignore) is not None:
            if not gap:
                return f"quoted: {q}\n      now:    {actual[at]}\n      ({line_difference(q, actual[at], rtol, ignore)})"
            at += 1
        if at == len(actual):
            return f"quoted: {q}\n      now:    " + ("(no more lines)" if tried == len(actual) else
                                                      "(no line matches after " + repr(actual[tried]) + ")")
        at, gap = at + 1, False
    if at < len(actual) and not gap:
        return f"the output has more lines than quoted: {actual[at]}"
    return None


def scratch(build):
    d = pathlib.Path(tempfile.mkdtemp(prefix="chainsim-docs-"))
    for name in LINKS:
        (d / name).symlink_to(ROOT / name)
    (d / "build").symlink_to(build)
    return d


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("--build", default=str(ROOT / "build"), help="the build tree (default: build)")
    p.add_argument("--keep", action="store_true", help="keep the scratch directories")
    p.add_argument("files", nargs="*", help="Markdown files (default: README.md and docs/*.md)")
    args = p.parse_args(argv)
    build = pathlib.Path(args.build).resolve()
    if not (build / "chainsim").is_file():
        print(f"check_doc_numbers: {build}/chainsim does not exist: build it first", file=sys.stderr)
        return 2
    files = [pathlib.Path(f) for f in args.files] or [ROOT / "README.md"] + sorted((ROOT / "docs").glob("*.md"))
    env = dict(os.environ, PATH=f"{build}:{os.environ.get('PATH', '/usr/bin:/bin')}", COLUMNS="120",
               PYTHONPATH=f"{build / 'python'}:{ROOT / 'python'}")
    failures, count, begin = 0, 0, time.time()
    for path in files:
        checked = blocks(path)
        if not checked:
            continue
        work = scratch(build)
        try:
            for block in checked:
                rtol = float(block.options.get("rtol", RTOL))
                ignore = re.compile(block.options["timings"]) if "timings" in block.options else None
                for line, command, expected in block.commands:
                    count += 1
                    t0 = time.time()
                    run = subprocess.run(["bash", "-c", command], cwd=work, env=env, stdout=subprocess.PIPE,
                                         stderr=subprocess.STDOUT, stdin=subprocess.DEVNULL, timeout=300)
                    actual = run.stdout.decode("utf-8", "replace").splitlines()
                    why = compare(expected, actual, rtol, ignore)
                    rel = os.path.relpath(path.resolve(), ROOT)
                    if why:
                        failures += 1
                        print(f"{rel}:{line}: FAIL  $ {command.splitlines()[0]}\n      {why}")
                    else:
                        print(f"{rel}:{line}: ok ({time.time() - t0:.1f} s)  $ {command.splitlines()[0]}")
        finally:
            if args.keep:
                print(f"  (scratch directory {work})")
            else:
                shutil.rmtree(work, ignore_errors=True)
    print(f"check_doc_numbers: {count} quoted commands, {failures} differ "
          f"(tolerance: relative {RTOL}, round-off below {ROUNDOFF} within a factor {FACTOR:g}; timings "
          f"excluded), {time.time() - begin:.0f} s")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
