"""`chainsim plot RUN_DIR [--animate [--html]] [--speed X] [--times t1,t2,...] [--fps N] [--format mp4|gif|html]`.

Draws the run in RUN_DIR into RUN_DIR/figures/ and prints the path of every file it writes. Exit codes as
for every chainsim command: 0 success, 2 bad input (an option, a missing or unreadable run directory, a
malformed output file), 1 anything else.
"""
import argparse
import math
import os
import sys


class _Parser(argparse.ArgumentParser):
    def error(self, message):
        # "argument --speed: --speed = -1 is out of range ..." -> "--speed = -1 is out of range ..."
        head, _, rest = message.partition(": ")
        if head.startswith("argument ") and rest.startswith(head[len("argument "):].split("/")[0]):
            message = rest
        sys.stderr.write(f"chainsim: error: {message} (see 'chainsim plot --help')\n")
        sys.exit(2)


def _positive(name, kind):
    def parse(text):
        try:
            value = kind(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"{name} = '{text}' is not a{'n integer' if kind is int else ' number'}")
        if not (value > 0 and math.isfinite(value)):
            raise argparse.ArgumentTypeError(f"{name} = {text} is out of range: allowed {name[2:]} > 0")
        return value
    return parse


def _times(text):
    out = []
    for part in text.split(","):
        try:
            value = float(part)
        except ValueError:
            raise argparse.ArgumentTypeError(f"--times = '{text}': '{part}' is not a number (give t1,t2,... in s)")
        if not math.isfinite(value):
            raise argparse.ArgumentTypeError(f"--times = '{text}': '{part}' is not a finite time")
        out.append(value)
    return out


def _format(text):
    if text not in ("mp4", "gif", "html"):
        raise argparse.ArgumentTypeError(f"--format = '{text}' is not a known format: allowed mp4, gif, html")
    return text


def parser():
    p = _Parser(prog="chainsim plot", description="Draw the outputs of a chainsim run (run, compare, reduced, "
                "canonical) into RUN_DIR/figures/ and print the paths of the files written.")
    p.add_argument("run_dir", metavar="RUN_DIR", help="a directory written by chainsim run|compare|reduced|canonical")
    p.add_argument("--animate", action="store_true", help="also write RUN_DIR/figures/animation.mp4 (ffmpeg) or "
                   ".gif (without ffmpeg) of the string in motion")
    p.add_argument("--speed", type=_positive("--speed", float), default=1.0,
                   help="animation speed, in units of real time (default 1: real time), > 0")
    p.add_argument("--fps", type=_positive("--fps", int), default=25, help="animation frames per second (default 25)")
    p.add_argument("--format", type=_format, default=None,
                   help="animation format: mp4, gif or html (default: mp4 if ffmpeg is installed, else gif)")
    p.add_argument("--html", action="store_true",
                   help="with --animate: RUN_DIR/figures/animation.html, one self-contained page with play and scrub "
                        "controls that any browser opens (the same as --format html)")
    p.add_argument("--times", type=_times, default=None,
                   help="times (s) of the snapshots and tension profiles, e.g. 0,0.1,0.2 (default: 6 spread "
                        "over the run)")
    return p


def plot_run(run_dir, times=None, animate=False, speed=1.0, fps=25, fmt=None, out_dir=None):
    """Draws one run; returns the paths written. Raises RunError for what cannot be drawn."""
    from .readers import holding

    with holding(run_dir):  # no chainsim command writes the directory meanwhile
        return _plot_held(run_dir, times, animate, speed, fps, fmt, out_dir)


def _plot_held(run_dir, times, animate, speed, fps, fmt, out_dir):
    from .readers import RunError, is_canonical, load_run

    out_dir = out_dir or os.path.join(run_dir, "figures")
    if is_canonical(run_dir):
        if times or animate:
            raise RunError(f"{'--times' if times else '--animate'} needs node frames, and {run_dir} is the output "
                           f"of `chainsim canonical` (its figures have their own times; draw a run of "
                           f"`chainsim run` for snapshots at chosen times or an animation)")
        from .canonical import canonical_figures
        return canonical_figures(run_dir, out_dir)
    run = load_run(run_dir)
    if times and run.nodes is None and run.tension is None:
        raise RunError(f"--times needs node frames or tensions, and {run_dir} has neither (a {run.kind} run)")
    if animate and run.nodes is None:
        raise RunError(f"--animate needs nodes.csv, and {run_dir} has none (a {run.kind} run)")
    written = list(draw(run, out_dir, times).values())
    if animate:
        from .animate import animate as make_animation
        path, _ = make_animation(run, os.path.join(out_dir, "animation"), speed=speed, fps=fps, fmt=fmt)
        written.append(path)
    return written


def draw(run, out_dir=None, times=None):
    """The figures of a run read by `readers.load_run` (or made by chainsim.Result): {name: path written} into
    out_dir, or with out_dir None {name: matplotlib Figure}, nothing written (closed to pyplot, so that a
    notebook shows only what it displays)."""
    from . import figures

    drawn = {}
    if run.kind == "reduced":
        drawn["reduced"] = figures.reduced_figure(run, out_dir)
    if run.kind == "compare":
        compare = figures.compare_figure if run.reduced is not None else figures.exact_compare_figure
        drawn["compare"] = compare(run, out_dir)
    if run.nodes is not None:
        drawn["snapshots"] = figures.snapshots_figure(run, out_dir, times)
    drawn["energy"] = figures.energy_figure(run, out_dir)
    drawn["tension"] = figures.tension_figure(run, out_dir, times)
    drawn["fronts"] = figures.fronts_figure(run, out_dir)
    drawn = {name: item for name, item in drawn.items() if item}
    if out_dir is None:
        import matplotlib.pyplot as plt
        for fig in drawn.values():
            plt.close(fig)
    return drawn


def main(argv=None):
    p = parser()
    args = p.parse_args(argv)
    if args.html:
        if args.format not in (None, "html"):
            p.error(f"--html writes an HTML page, and --format = '{args.format}' asks for another format: give one")
        if not args.animate:
            p.error("--html is the format of the animation: give it with --animate")
        args.format = "html"
    try:
        import matplotlib  # noqa: F401
        import numpy  # noqa: F401
    except ImportError as e:
        sys.stderr.write(f"chainsim: error: plot needs numpy and matplotlib ({e}): install the Debian packages "
                         f"python3-numpy python3-matplotlib, or run with /usr/bin/python3\n")
        return 1
    from .readers import RunError
    try:
        for path in plot_run(args.run_dir, args.times, args.animate, args.speed, args.fps, args.format):
            print(path)
    except RunError as e:
        sys.stderr.write(f"chainsim: error: {e}\n")
        return 2
    return 0
