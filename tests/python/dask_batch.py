"""The batch recipe of docs/python.md: assets × families × poses on Dask, one
bind per task, each deformed to every pose of its asset, results as arrays or
weights files. docs/python.md quotes the recipe (the lines between the
"recipe" markers) as it is here; tests/python/test_dask_batch.py runs it on a
LocalCluster and checks it against a serial run, bit for bit.

Timing (the figures of docs/python.md, "Many assets"):

    python tests/python/dask_batch.py --jobs 100 --workers 2

binds `--jobs` tasks (25 turned copies of the comb × 4 families, each deformed
to 2 poses) serially in this process, then on a LocalCluster of `--workers`
processes of one thread, each with RAYON_NUM_THREADS = cores / workers, and
prints both times.
"""

from __future__ import annotations

import argparse
import os
import sys
import time
from pathlib import Path

import numpy as np

import pmvc

ROOT = Path(__file__).resolve().parents[2]

# recipe: begin
import dask.distributed  # noqa: E402  (pip install "dask[distributed]")


def bind_and_deform(points, cage, poses, method, parameters, out=None):
    """One task: one bind (it uses every core this process gives rayon), then
    every pose. Returns the deformed points, one float64 (n, 3) array per pose;
    with `out`, also writes the weights there (W.npy or W.npz, W.classes.npy,
    W.json) on the worker's file system."""
    weights = pmvc.bind(points, cage, method=method, backend="cpu", **parameters)
    if out is not None:
        pmvc.save_weights(out, weights)
    return [pmvc.deform(points, cage, pose, weights=weights) for pose in poses]


def run_batch(client, assets, families, out_dir=None):
    """`assets`: {name: (points, cage, poses)}, `cage` a pmvc.Cage or (V, F);
    `families`: {label: (method, parameters)}. One task per asset and family;
    returns {(name, label): [deformed points per pose]}."""
    futures = {}
    for name, (points, cage, poses) in assets.items():
        # Each asset goes to the cluster once, not once per family.
        shared = client.scatter([points, cage, poses], hash=False)
        for label, (method, parameters) in families.items():
            out = None
            if out_dir is not None:
                extension = "npz" if method == "green" else "npy"
                out = str(Path(out_dir) / f"{name}-{label}.{extension}")
            futures[name, label] = client.submit(
                bind_and_deform, *shared, method, parameters, out, pure=False
            )
    return dict(zip(futures, client.gather(list(futures.values()))))


def local_cluster(workers, cores=None, rayon_threads=None):
    """`workers` processes of one thread each, sharing the machine's cores: each
    bind's rayon pool gets cores / workers threads (RAYON_NUM_THREADS, read when
    a worker's first bind starts), so that the workers do not fight over them."""
    cores = cores or os.cpu_count() or 1
    threads = rayon_threads or max(1, cores // workers)
    return dask.distributed.LocalCluster(
        n_workers=workers,
        threads_per_worker=1,
        processes=True,
        env={"RAYON_NUM_THREADS": str(threads)},
    )
# recipe: end


def serial(assets, families):
    """The same work in this process, one bind after the other."""
    return {
        (name, label): bind_and_deform(points, cage, poses, method, parameters)
        for name, (points, cage, poses) in assets.items()
        for label, (method, parameters) in families.items()
    }


FAMILIES = {
    "mvc": ("mvc", {}),
    "pmvc-32": ("pmvc", {"resolution": 32}),
    "harmonic-32": ("harmonic", {"grid": 32}),
    "green": ("green", {}),
}


def comb_assets(count: int):
    """`count` copies of the bundled comb, each turned about z by its own angle
    (as many distinct assets of one size), with two poses each: the middle
    finger pulled up, and the whole cage stretched along x by 10%."""
    from study import middle_finger_pose

    points, _ = pmvc.load_mesh(ROOT / "assets" / "comb_mesh.obj")
    vertices, faces = pmvc.load_mesh(ROOT / "assets" / "comb_cage.obj")
    pulled = middle_finger_pose(pmvc.Cage(vertices, faces))
    assets = {}
    for k in range(count):
        angle = 2 * np.pi * k / max(count, 1)
        turn = np.array([[np.cos(angle), -np.sin(angle), 0], [np.sin(angle), np.cos(angle), 0], [0, 0, 1]])
        stretched = vertices * [1.1, 1.0, 1.0]
        poses = [pulled @ turn.T, stretched @ turn.T]
        assets[f"comb{k:02d}"] = (points @ turn.T, pmvc.Cage(vertices @ turn.T, faces), poses)
    return assets


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--jobs", type=int, default=100, help="binds: a multiple of 4 (families)")
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--rayon-threads", type=int, help="per worker (default: cores / workers)")
    arguments = parser.parse_args(argv)
    assets = comb_assets(arguments.jobs // len(FAMILIES))
    jobs = len(assets) * len(FAMILIES)
    cores = os.cpu_count()
    started = time.perf_counter()
    expected = serial(assets, FAMILIES)
    serial_seconds = time.perf_counter() - started
    rayon_threads = arguments.rayon_threads or max(1, cores // arguments.workers)
    with local_cluster(arguments.workers, rayon_threads=rayon_threads) as cluster, dask.distributed.Client(
        cluster
    ) as client:
        client.run(lambda: pmvc.families())  # workers started and pmvc imported
        started = time.perf_counter()
        results = run_batch(client, assets, FAMILIES)
        dask_seconds = time.perf_counter() - started
    same = all(
        all(a.tobytes() == b.tobytes() for a, b in zip(results[key], expected[key])) for key in expected
    )
    print(
        f"{jobs} binds of the comb ({len(assets)} assets × {len(FAMILIES)} families, 2 poses each) "
        f"on {cores} cores: serial {serial_seconds:.1f} s, Dask {arguments.workers} workers × 1 thread "
        f"(RAYON_NUM_THREADS={rayon_threads}) {dask_seconds:.1f} s, "
        f"speed-up {serial_seconds / dask_seconds:.2f}; results {'identical' if same else 'DIFFERENT'}"
    )
    return 0 if same else 1


if __name__ == "__main__":
    sys.path.insert(0, str(Path(__file__).resolve().parent))
    sys.exit(main())
