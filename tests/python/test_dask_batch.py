"""The Dask recipe of docs/python.md on a LocalCluster of two worker processes
gives what a serial run gives, bit for bit, as arrays and as weights files; the
doc quotes the recipe as tests/python/dask_batch.py has it."""

from __future__ import annotations

import os

import numpy as np
import pytest

import pmvc
from conftest import ROOT

if os.environ.get("PMVC_REQUIRE_DASK"):
    # tests/run installs dask[distributed]: there a missing one is a failure.
    import distributed
else:
    distributed = pytest.importorskip(
        "distributed",
        reason="dask[distributed] is not installed: pip install 'dask[distributed]' to run the batch recipe's test",
    )

import dask_batch  # noqa: E402  (imports dask.distributed)

FAMILIES = {
    "mvc": ("mvc", {}),
    "pmvc-8": ("pmvc", {"resolution": 8}),
    "harmonic-16": ("harmonic", {"grid": 16}),
    "green": ("green", {}),
}


@pytest.fixture(scope="module")
def client():
    with dask_batch.local_cluster(workers=2, cores=2) as cluster, distributed.Client(cluster) as client:
        yield client


def test_the_batch_on_two_workers_equals_a_serial_run(client, tmp_path):
    assets = dask_batch.comb_assets(3)
    # One asset as libigl's (V, F) pair, as a batch read with igl would give it.
    name = "comb01"
    points, cage, poses = assets[name]
    assets[name] = (points, (cage.vertices, cage.triangles), poses)
    results = dask_batch.run_batch(client, assets, FAMILIES, out_dir=tmp_path)
    expected = dask_batch.serial(assets, FAMILIES)
    assert results.keys() == expected.keys() and len(results) == 12
    for key, moved in results.items():
        assert len(moved) == 2
        for a, b in zip(moved, expected[key]):
            assert a.dtype == np.float64 and a.tobytes() == b.tobytes(), key
    # The weights files the workers wrote are the serial binds', and deform again.
    for (name, label), (method, parameters) in [
        ((asset, label), FAMILIES[label]) for asset in assets for label in FAMILIES
    ]:
        points, cage, poses = assets[name]
        extension = "npz" if method == "green" else "npy"
        loaded = pmvc.load_weights(tmp_path / f"{name}-{label}.{extension}")
        bound = pmvc.bind(points, cage, method=method, backend="cpu", **parameters)
        assert loaded.matrix.tobytes() == bound.matrix.tobytes(), (name, label)
        again = pmvc.deform(points, cage, poses[0], weights=loaded)
        assert again.tobytes() == expected[name, label][0].tobytes()


def test_workers_get_their_share_of_the_cores(client):
    threads = client.run(lambda: __import__("os").environ.get("RAYON_NUM_THREADS"))
    assert sorted(threads.values()) == ["1", "1"]


def test_weights_travel_between_tasks(client):
    """A bind's Weights, returned by one task, are an argument of the next
    (Dask pickles them between workers)."""
    points, cage, poses = dask_batch.comb_assets(1)["comb00"]
    weights = client.submit(pmvc.bind, points, cage, method="pmvc", resolution=8, backend="cpu", pure=False)
    moved = client.submit(pmvc.deform, points, cage, poses[0], weights=weights, pure=False)
    local = pmvc.bind(points, cage, method="pmvc", resolution=8, backend="cpu")
    assert weights.result().matrix.tobytes() == local.matrix.tobytes()
    assert moved.result().tobytes() == pmvc.deform(points, cage, poses[0], weights=local).tobytes()


def test_docs_quote_the_recipe_as_it_is():
    source = (ROOT / "tests" / "python" / "dask_batch.py").read_text()
    recipe = source.split("# recipe: begin\n")[1].split("# recipe: end\n")[0]
    doc = (ROOT / "docs" / "python.md").read_text()
    assert recipe.strip() in doc, "docs/python.md does not quote the recipe of tests/python/dask_batch.py"
