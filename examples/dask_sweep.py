"""A sweep on a Dask cluster: the falling chain (string solver with front tracking) at several f and meshes,
one task per point on the workers of a LocalCluster (two worker processes here). On a real cluster, replace the
LocalCluster by Client("tcp://scheduler:8786") or a dask_jobqueue cluster (docs/python.md). One point is
deliberately bad (f = 1.5): it comes back as a row with its error, and the sweep goes on.

    PYTHONPATH=build/python:python /usr/bin/python3 examples/dask_sweep.py [--quick]
"""
import os

from dask.distributed import Client, LocalCluster

import chainsim
from _common import SCENES, out_dir, quick

if __name__ == "__main__":   # the worker processes import this file: start the cluster only here
    out = out_dir("dask_sweep")
    scene = chainsim.Scene.from_file(os.path.join(SCENES, "falling_chain.toml"))
    grid = {"f": [0.0, 0.5, 1.0, 1.5], "string.nodes": [11, 21] if quick() else [51, 101]}
    # (short settings: worker threads in this process, quicker to start; the real thing: worker processes)
    with LocalCluster(n_workers=2, threads_per_worker=1, processes=not quick(), dashboard_address=":0") as cluster, \
            Client(cluster) as client:
        df = chainsim.sweep(scene, grid, client=client, t_end=0.1 if quick() else None)
    df.to_csv(os.path.join(out, "sweep.csv"), index=False)
    print(df[["f", "string.nodes", "status", "t_stop", "relative_energy_drift", "wall_time_s"]].to_string(na_rep="-"))
    print("errors:", *df[df.status == "error"].error, sep="\n  ")
    assert len(df) == 8 and (df.status == "error").sum() == 2
