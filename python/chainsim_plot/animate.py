"""The string in motion: an MP4 (ffmpeg) or, without ffmpeg, a GIF (Pillow), or one self-contained HTML page
with play and scrub controls (matplotlib's JavaScript HTML writer, the frames embedded as PNG: `--html`).

Video frame j shows the recorded frame nearest to t_j = t_first + j * speed / fps, so the video runs
at `speed` times real time: a run from t_first to t_last gives floor((t_last - t_first) * fps / speed) + 1
frames (`frame_count`).
"""
import html
import math
import re
import shutil

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
from matplotlib import animation  # noqa: E402

from .figures import FRONT_COLOR, HEAP_COLOR, Layout, space_axes  # noqa: E402
from .readers import RunError  # noqa: E402


def frame_count(t_first, t_last, fps, speed):
    return int(math.floor((t_last - t_first) * fps / speed + 1e-9)) + 1


def has_ffmpeg():
    return shutil.which("ffmpeg") is not None and animation.writers.is_available("ffmpeg")


# The HTML page's buttons: matplotlib's template draws their icons with Font Awesome from a CDN; the page
# carries its own glyphs instead, so that it opens anywhere, offline.
_FONT_AWESOME = re.compile(r'<link rel="stylesheet"\s+href="https://[^"]*font-awesome[^"]*">\s*')
_GLYPHS = """<style>
.anim-buttons button i { font-style: normal; }
.fa-minus::before { content: "\\2212"; } .fa-plus::before { content: "+"; }
.fa-fast-backward::before { content: "\\21E4"; } .fa-fast-forward::before { content: "\\21E5"; }
.fa-step-backward::before { content: "\\2190"; } .fa-step-forward::before { content: "\\2192"; }
.fa-play::before { content: "\\25B6"; } .fa-pause::before { content: "||"; }
.fa-flip-horizontal.fa-play::before { content: "\\25C0"; }
</style>
"""


def _self_contained(path, title):
    """Makes matplotlib's HTML animation a whole page that needs nothing from the network."""
    with open(path) as fh:
        body = _FONT_AWESOME.sub("", fh.read())
    with open(path, "w") as fh:
        fh.write(f"<!DOCTYPE html>\n<html><head><meta charset=\"utf-8\"><title>{html.escape(title)}</title>\n"
                 f"{_GLYPHS}</head><body>\n{body}\n</body></html>\n")


def animate(run, out_path, speed=1.0, fps=25, fmt=None):
    """Writes the animation of `run` to out_path (extension .mp4, .gif or .html, from `fmt`: "mp4", "gif",
    "html" or None = mp4 when ffmpeg is installed) and returns the path written and its frame count."""
    frames = run.nodes
    if frames is None:
        raise RunError(f"{run.path}: --animate needs nodes.csv (the run wrote no node frames)")
    fmt = fmt or ("mp4" if has_ffmpeg() else "gif")
    if fmt == "mp4" and not has_ffmpeg():
        raise RunError("--format mp4 needs ffmpeg (Debian package 'ffmpeg'); --format gif needs only Pillow")
    out_path = out_path + "." + fmt
    t_first, t_last = frames.times[0], frames.times[-1]
    n = frame_count(t_first, t_last, fps, speed)
    layout = Layout(run, stagger_ok=False)
    projections = layout.projections
    # An even pixel size (the H.264 encoder needs one): 100 dpi, whole inches.
    fig, axes = plt.subplots(1, len(projections), figsize=(8 * len(projections), 6), dpi=100, squeeze=False)
    axes = axes[0]
    lines, firsts, markers, heaps = [], [], [], []
    for ax, proj in zip(axes, projections):
        layout.limits(ax, proj)
        space_axes(ax, proj, adjustable="box")
        layout.draw_obstacles(ax, proj, label=False)
        heaps.append([ax.plot([], [], "o", color=HEAP_COLOR, alpha=0.6, mew=0)[0] for _ in layout.heaps(t_first)])
        (line,) = ax.plot([], [], "-", lw=1.6, color="tab:blue")
        # The first point drawn, a small dot as in the snapshots: it tells the ends apart, and shows the
        # shorter side of a chain over a peg, which hangs along the longer one.
        (first,) = ax.plot([], [], "o", ms=4, color="tab:blue", linestyle="none")
        firsts.append(first)
        (mark,) = ax.plot([], [], "o", ms=6, mfc="none", color=FRONT_COLOR, linestyle="none")
        lines.append(line)
        markers.append(mark)
    clock = fig.text(0.01, 0.97, "", fontsize=11, family="monospace", va="top")
    fig.suptitle(f"{run.name}" + (f"  ({speed:g} x real time)" if speed != 1 else "  (real time)"), fontsize=10)
    fig.tight_layout(rect=(0, 0, 1, 0.95))
    # Once more after a draw: the equal aspect shrinks each panel's box, its ticks then change, and the first
    # layout (made for the taller boxes) can leave a wider tick label's axis label outside the figure.
    fig.canvas.draw()
    fig.tight_layout(rect=(0, 0, 1, 0.95))

    def draw(j):
        t = min(t_first + j * speed / fps, t_last)
        k = frames.nearest(t)
        tk = frames.times[k]
        pts = layout.curve(k)
        fronts = layout.front_markers(tk)
        for q, proj in enumerate(projections):
            a, b = proj
            lines[q].set_data(pts[:, a], pts[:, b])
            firsts[q].set_data(pts[:1, a], pts[:1, b])
            markers[q].set_data([p[a] for _, p in fronts], [p[b] for _, p in fronts])
            for artist, (_, p, size) in zip(heaps[q], layout.heaps(tk)):
                artist.set_data([p[a]], [p[b]])
                artist.set_markersize(size)
        clock.set_text(f"t = {tk:8.4f} s")
        return lines + firsts + markers

    if fmt == "html":
        # Every frame embedded (no limit: the writer would drop the frames beyond animation.embed_limit).
        writer = animation.HTMLWriter(fps=fps, embed_frames=True, default_mode="once", embed_limit=float("inf"))
    elif fmt == "mp4":
        writer = animation.FFMpegWriter(fps=fps, codec="libx264", extra_args=["-pix_fmt", "yuv420p"])
    else:
        writer = animation.PillowWriter(fps=fps)
    anim = animation.FuncAnimation(fig, draw, frames=n, blit=False)
    anim.save(out_path, writer=writer)
    plt.close(fig)
    if fmt == "html":
        _self_contained(out_path, f"{run.name}: the string in motion")
    return out_path, n


def count_frames_gif(path):
    from PIL import Image
    with Image.open(path) as im:
        return im.n_frames


def probe_frames(path):
    """Frames of a video file as ffprobe counts them (None without ffprobe)."""
    import subprocess
    if shutil.which("ffprobe") is None:
        return None
    out = subprocess.run(["ffprobe", "-v", "error", "-count_frames", "-select_streams", "v:0", "-show_entries",
                          "stream=nb_read_frames", "-of", "csv=p=0", path], capture_output=True, text=True,
                         check=True)
    return int(out.stdout.strip())

