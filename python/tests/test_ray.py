"""drafter.ray on a local two-node cluster (ray.cluster_utils.Cluster, one CPU each): the outputs
equal the local batch's bytes, and removing a node in the middle of a run still completes it with
every output and no partial file (Ray retries the lost tasks; writes are atomic)."""

import pathlib
import threading
import time

import pytest

import drafter

# A missing ray fails the run (scripts/test installs it), never skips it.
import ray
from ray.cluster_utils import Cluster

import drafter.ray as dray


@pytest.fixture(scope="module")
def cluster():
    c = Cluster(
        initialize_head=True,
        head_node_args={"num_cpus": 1, "object_store_memory": 80 * 1024 * 1024, "include_dashboard": False},
    )
    worker = c.add_node(num_cpus=1, object_store_memory=80 * 1024 * 1024)
    ray.init(address=c.address, logging_level="ERROR", log_to_driver=False)
    c.wait_for_nodes()
    yield c, worker
    ray.shutdown()
    c.shutdown()


def inputs(models):
    # Small and mid-size models of every format: the run stays short on two 1-CPU nodes.
    return [
        models / "obj" / "cgal",
        models / "obj" / "occt",
        models / "gltf" / "RodAssembly",
        models / "obj" / "common-3d-test-models" / "fandisk.obj",
    ]


def assert_same_tree(a: pathlib.Path, b: pathlib.Path):
    files_a = sorted(p.relative_to(a) for p in a.rglob("*") if p.is_file())
    files_b = sorted(p.relative_to(b) for p in b.rglob("*") if p.is_file())
    assert files_a == files_b
    for f in files_a:
        assert (a / f).read_bytes() == (b / f).read_bytes(), f
    assert not [f for f in files_a if f.name.startswith(".")], "a temporary file was left"


def test_two_nodes_bake_the_local_batchs_bytes(cluster, models, tmp_path):
    local = drafter.bake_many(inputs(models), tmp_path / "local")
    assert local["failed"] == 0
    report = dray.bake_catalog(inputs(models), tmp_path / "ray", report=tmp_path / "report.json")
    assert report["failed"] == 0 and report["baked"] == len(local["files"])
    assert_same_tree(tmp_path / "local", tmp_path / "ray")
    nodes = {n["NodeID"] for n in ray.nodes() if n["Alive"]}
    assert len(nodes) == 2
    assert {r["node"] for r in report["files"]} == nodes, "both nodes baked files"
    # Through a cache shared by the tasks: a second run is all hits, the same bytes.
    cache = tmp_path / "cache"
    dray.bake_catalog(inputs(models), tmp_path / "ray-cached", cache=cache)
    again = dray.bake_catalog(inputs(models), tmp_path / "ray-cached", cache=cache)
    assert again["cached"] == len(local["files"])
    assert_same_tree(tmp_path / "local", tmp_path / "ray-cached")


def test_a_node_lost_mid_run_still_completes_every_file(cluster, models, tmp_path):
    c, worker = cluster
    local = drafter.bake_many(inputs(models), tmp_path / "local")
    result = {}
    run = threading.Thread(target=lambda: result.update(dray.bake_catalog(inputs(models), tmp_path / "ray")))
    run.start()
    # Remove the worker node once the run is under way (some outputs written, more to come).
    deadline = time.time() + 120
    while time.time() < deadline and len(list((tmp_path / "ray").rglob("*.glb"))) < 2:
        time.sleep(0.05)
    written_before = len(list((tmp_path / "ray").rglob("*.glb")))
    c.remove_node(worker, allow_graceful=False)
    assert written_before < len(local["files"]), "the node was removed before the run ended"
    run.join(timeout=600)
    assert not run.is_alive()
    assert result["failed"] == 0, [r for r in result["files"] if r["status"] == "failed"]
    assert_same_tree(tmp_path / "local", tmp_path / "ray")
