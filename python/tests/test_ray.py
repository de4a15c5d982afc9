"""drafter.ray on a local two-node cluster (ray.cluster_utils.Cluster, one CPU each, every process
on 127.0.0.1 only): the outputs equal the local batch's bytes, and removing a node in the middle of
a run still completes it with every output and no partial file (Ray retries the lost tasks; writes
are atomic); relative paths are the driver's; nothing is written outside the output folder and the
cache."""

import ipaddress
import os
import pathlib
import shutil
import threading
import time

import pytest
from conftest import assert_confined, hostile_tree

import drafter

# A missing ray fails the run (scripts/test installs it), never skips it.
import ray
from ray.cluster_utils import Cluster

import drafter.ray as dray


@pytest.fixture(scope="module")
def cluster():
    # 127.0.0.1 for every node and the driver (conftest.py sets what makes Ray keep it).
    assert os.environ.get("RAY_ENABLE_WINDOWS_OR_OSX_CLUSTER") == "0"
    loopback = "127.0.0.1"
    c = Cluster(
        initialize_head=True,
        head_node_args={
            "num_cpus": 1,
            "object_store_memory": 80 * 1024 * 1024,
            "include_dashboard": False,
            "node_ip_address": loopback,
        },
    )
    worker = c.add_node(num_cpus=1, object_store_memory=80 * 1024 * 1024, node_ip_address=loopback)
    ray.init(address=c.address, logging_level="ERROR", log_to_driver=False, _node_ip_address=loopback)
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


def listening_sockets_of(pids) -> list:
    """(address, port, pid) of every TCP socket in LISTEN state that one of ``pids`` holds, from
    /proc (no tool needed)."""
    inodes = {}
    for pid in pids:
        try:
            for fd in os.listdir(f"/proc/{pid}/fd"):
                target = os.readlink(f"/proc/{pid}/fd/{fd}")
                if target.startswith("socket:["):
                    inodes[target[8:-1]] = pid
        except OSError:
            continue  # gone meanwhile
    found = []
    for table, size in (("/proc/net/tcp", 4), ("/proc/net/tcp6", 16)):
        with open(table) as f:
            next(f)
            for line in f:
                fields = line.split()
                local, state, inode = fields[1], fields[3], fields[9]
                if state != "0A" or inode not in inodes:  # 0A: LISTEN
                    continue
                hex_address, hex_port = local.split(":")
                raw = bytes.fromhex(hex_address)
                # /proc writes the address as 32-bit words in host (little-endian) order.
                raw = b"".join(raw[k : k + 4][::-1] for k in range(0, size, 4))
                address = ipaddress.ip_address(raw)
                if isinstance(address, ipaddress.IPv6Address) and address.ipv4_mapped:
                    address = address.ipv4_mapped
                found.append((address, int(hex_port, 16), inodes[inode]))
    return found


def descendants(pid: int) -> set:
    children = {}
    for entry in os.listdir("/proc"):
        if entry.isdigit():
            try:
                with open(f"/proc/{entry}/stat") as f:
                    parent = int(f.read().rsplit(")", 1)[1].split()[1])
            except (OSError, ValueError, IndexError):
                continue
            children.setdefault(parent, []).append(int(entry))
    found, todo = set(), [pid]
    while todo:
        for child in children.get(todo.pop(), []):
            if child not in found:
                found.add(child)
                todo.append(child)
    return found


def test_every_ray_process_listens_on_the_loopback_address_only(cluster):
    """The cluster's servers (GCS, raylets, workers, the driver's own) accept connections from this
    machine only: none listens on the network address or on all addresses."""
    @ray.remote
    def where():
        return ray.util.get_node_ip_address()

    assert set(ray.get([where.remote() for _ in range(4)])) == {"127.0.0.1"}
    pids = descendants(os.getpid()) | {os.getpid()}
    sockets = listening_sockets_of(pids)
    assert len(sockets) >= 4, f"the cluster's servers were not found: {sockets}"
    assert [s for s in sockets if not s[0].is_loopback] == [], sockets


def test_relative_paths_are_the_drivers_not_the_workers(cluster, models, tmp_path, monkeypatch):
    """Relative inputs, output folder, cache, config and report, from the driver's working folder:
    before, discovery used the driver's folder and the tasks the workers' (``/``), so every file
    failed and a cache folder was made at ``/cache``."""
    shutil.copytree(models / "obj" / "cgal", tmp_path / "models")
    (tmp_path / "c.toml").write_text("[gradient]\nq = 12\n")
    root_cache_before = os.path.exists("/cache")
    monkeypatch.chdir(tmp_path)
    report = dray.bake_catalog(["models"], "out", cache="cache", config="c.toml", report="report.json")
    assert report["failed"] == 0 and report["baked"] == len(report["files"]) > 3, report
    assert (tmp_path / "report.json").is_file() and drafter.cache_stats(tmp_path / "cache")["entries"] == report["baked"]
    assert os.path.exists("/cache") == root_cache_before
    local = drafter.bake_many(tmp_path / "models", tmp_path / "local", config={"gradient": {"q": 12}})
    assert local["baked"] == report["baked"]
    assert_same_tree(tmp_path / "local", tmp_path / "out")
    # One str input is one path, as in drafter.bake_many.
    again = dray.bake_catalog("models", "out", cache="cache", config="c.toml")
    assert again["cached"] == report["baked"]


def test_ray_writes_nothing_outside_its_output_folder_and_the_cache(cluster, tmp_path):
    root = pathlib.Path(os.path.realpath(tmp_path))
    cases = hostile_tree(root)

    def bake(inputs, manifests, out_dir, cache):
        return dray.bake_catalog(inputs, out_dir, manifests=manifests, cache=cache)

    outcomes = assert_confined(root, cases, bake)
    assert isinstance(outcomes["collide"], drafter.InputError), outcomes["collide"]
    assert (root / "victim" / "keep.txt").read_bytes() == b"not to be touched\n"
