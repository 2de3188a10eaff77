#!/usr/bin/env python3
"""Executes the notebooks of examples/notebooks/ with nbclient (each in its own directory, as Jupyter runs
it) and writes them with their outputs to BUILD/notebooks/, where the site's gallery takes them (docs/conf.py).

Usage: /usr/bin/python3 scripts/run_notebooks.py [--build BUILD_DIR] [NOTEBOOK.ipynb ...]
The kernel is this interpreter's ipykernel (Debian's python3-ipykernel), with the module of the build tree on
its path (PYTHONPATH=BUILD/python:python). Exit 0 if every notebook ran; 1 with the failing cell's error.
"""
import argparse
import os
import pathlib
import sys
import time

import nbformat
from nbclient import NotebookClient
from nbclient.exceptions import CellExecutionError

ROOT = pathlib.Path(__file__).resolve().parent.parent
CELL_TIMEOUT = 120  # s; each notebook takes seconds (measured in the report of the docs target)


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("--build", default=str(ROOT / "build"))
    p.add_argument("notebooks", nargs="*")
    args = p.parse_args(argv)
    build = pathlib.Path(args.build).resolve()
    out = build / "notebooks"
    out.mkdir(parents=True, exist_ok=True)
    paths = [pathlib.Path(n).resolve() for n in args.notebooks] or sorted((ROOT / "examples" / "notebooks").glob("*.ipynb"))
    os.environ["PYTHONPATH"] = os.pathsep.join([str(build / "python"), str(ROOT / "python")] +
                                               ([os.environ["PYTHONPATH"]] if os.environ.get("PYTHONPATH") else []))
    os.environ.setdefault("MPLBACKEND", "module://matplotlib_inline.backend_inline")
    os.environ.setdefault("PYDEVD_DISABLE_FILE_VALIDATION", "1")  # quiets the kernel debugger's note
    failed = 0
    for path in paths:
        nb = nbformat.read(path, as_version=4)
        client = NotebookClient(nb, timeout=CELL_TIMEOUT, kernel_name="python3",
                                resources={"metadata": {"path": str(path.parent)}})
        begin = time.time()
        try:
            client.execute()
        except CellExecutionError as e:
            failed += 1
            print(f"{path.relative_to(ROOT)}: FAILED after {time.time() - begin:.1f} s\n{e}", file=sys.stderr)
            continue
        nbformat.write(nb, out / path.name)
        print(f"{path.relative_to(ROOT)}: executed in {time.time() - begin:.1f} s -> {out / path.name}")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
