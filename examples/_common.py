"""Shared by the examples: short settings and the output directory.

Every example runs in full by default and with short settings when CHAINSIM_EXAMPLE_QUICK=1 or --quick is given
(CTest runs them so); outputs go to CHAINSIM_EXAMPLE_OUT or results/examples/<example>/.
"""
import os
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
SOURCE = os.path.dirname(HERE)
SCENES = os.path.join(SOURCE, "cases", "scenes")


def quick():
    return "--quick" in sys.argv[1:] or os.environ.get("CHAINSIM_EXAMPLE_QUICK", "") not in ("", "0")


def out_dir(name):
    path = os.environ.get("CHAINSIM_EXAMPLE_OUT") or os.path.join("results", "examples", name)
    os.makedirs(path, exist_ok=True)
    return path


def binary():
    """The chainsim executable: CHAINSIM_BINARY, else build/chainsim of this source tree, else chainsim on PATH."""
    candidate = os.environ.get("CHAINSIM_BINARY") or os.path.join(SOURCE, "build", "chainsim")
    return candidate if os.path.exists(candidate) else "chainsim"
