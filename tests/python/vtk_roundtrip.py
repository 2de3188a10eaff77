#!/usr/bin/python3
"""Reads VTK XML PolyData files with VTK's own reader (python3-vtk9) and checks them against the values
the writer was given, exactly.

Usage: vtk_roundtrip.py EXPECTED.json FILE.vtp [FILE.vtp ...]
EXPECTED.json: {"points": [[x, y, z], ...], "segments": [[a, b], ...],
                "point_data": {name: [[c0, c1, ...] per point]}, "cell_data": {name: [[...] per cell]}}
Exit code 0: every file matches; 1: a difference (printed); 77: vtk is not importable (the test is skipped).
"""
import json
import sys

try:
    import vtk
    from vtk.util.numpy_support import vtk_to_numpy
except ImportError:
    print("vtk is not importable: install python3-vtk9")
    sys.exit(77)
import numpy as np


def check(path, expected):
    reader = vtk.vtkXMLPolyDataReader()
    reader.SetFileName(path)
    reader.Update()
    if reader.GetErrorCode():
        return [f"{path}: the reader reports error {reader.GetErrorCode()}"]
    poly = reader.GetOutput()
    problems = []

    def same(what, got, want):
        got, want = np.asarray(got), np.asarray(want)
        if got.shape != want.shape:
            problems.append(f"{path}: {what}: shape {got.shape}, expected {want.shape}")
        elif not np.array_equal(got, want):
            k = np.argwhere(got != want)[0]
            problems.append(f"{path}: {what}: {got[tuple(k)]!r} at {tuple(k)}, expected {want[tuple(k)]!r}")
        elif got.dtype.kind == "f" and not np.array_equal(np.signbit(got), np.signbit(want)):
            problems.append(f"{path}: {what}: the sign of a zero differs")

    same("points", vtk_to_numpy(poly.GetPoints().GetData()), expected["points"])
    lines = poly.GetLines()
    same("line offsets", vtk_to_numpy(lines.GetOffsetsArray()), 2 * np.arange(len(expected["segments"]) + 1))
    same("line connectivity", vtk_to_numpy(lines.GetConnectivityArray()).reshape(-1, 2), expected["segments"])
    for kind, data in (("point_data", poly.GetPointData()), ("cell_data", poly.GetCellData())):
        names = [data.GetArrayName(i) for i in range(data.GetNumberOfArrays())]
        if sorted(names) != sorted(expected[kind]):
            problems.append(f"{path}: {kind} arrays {names}, expected {list(expected[kind])}")
            continue
        for name, values in expected[kind].items():
            got = vtk_to_numpy(data.GetArray(name))
            same(f"{kind} '{name}'", got.reshape(len(values), -1), values)
    return problems


def main():
    if len(sys.argv) < 3:
        sys.stderr.write(__doc__)
        sys.exit(2)
    with open(sys.argv[1]) as fh:
        expected = json.load(fh)
    problems = [p for path in sys.argv[2:] for p in check(path, expected)]
    for p in problems:
        print(p)
    if not problems:
        print(f"ok: {len(sys.argv) - 2} files read back exactly")
    sys.exit(1 if problems else 0)


if __name__ == "__main__":
    main()
