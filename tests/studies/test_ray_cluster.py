"""Ray across machines, shown on one: a head node and a second node started with `ray start`
(two raylets on this host, each of one CPU), a study run on them with `--backend ray
--ray-address`, and the same study with `--jobs 2`: the same summary, every trial the same
but for where it ran, and the trials spread over both nodes.

The nodes run `ray start --block` in process groups of their own, without this test's
PYTHONPATH, and the studies run outside the checkout: the workers get pbp_drake from the
study, as on a real cluster. The nodes are killed by their groups and ids, never with
`ray stop`, which stops every Ray on the machine, other users' too: by the fixture's
finalizer, or by a watchdog process when this test's process is killed."""

import importlib.util
import json
import os
import pathlib
import secrets
import shutil
import signal
import socket
import subprocess
import sys
import tempfile
import textwrap
import time

import pytest

from pbp_drake.studies.trial_files import trial_paths

RAY_CLI = shutil.which("ray", path=str(pathlib.Path(sys.executable).parent)) or shutil.which(
    "ray")
pytestmark = [
    pytest.mark.slow,
    pytest.mark.skipif(importlib.util.find_spec("ray") is None,
                       reason="ray is not installed: pip install 'pbp_drake[ray]'"),
    pytest.mark.skipif(RAY_CLI is None, reason="the `ray` command is not on the PATH"),
]

REPO = pathlib.Path(__file__).resolve().parents[2]
METHODS = ["pbp_alternated", "teleop"]
SEEDS = (10000,)  # the first evaluation seed of diagrams/hsr_reach.yaml
# Ray on two busy cores takes 10 to 30 s to start a node; a study of 2 trials half a minute.
NODE_TIMEOUT = 120
STUDY_TIMEOUT = 420
# The smallest object store Ray accepts is 75 MiB; the trials send only their CSV text.
OBJECT_STORE_BYTES = 100 * 1024 * 1024
# Ray's token authentication, with a token of this test's own (not ~/.ray/auth_token): the
# nodes listen on this host's address, and every node and driver must give the token.
AUTH = {"RAY_AUTH_MODE": "token", "RAY_AUTH_TOKEN": secrets.token_hex(32)}
# The refused driver's retries (see test_a_study_without_the_clusters_token_says_why).
NO_TOKEN_RETRIES = {"RAY_gcs_server_port_wait_time_s": "2"}
# Waits for process argv[1] to end (a pidfd is readable then, zombie or not), then kills
# process group argv[2] and removes folder argv[3].
WATCHDOG = textwrap.dedent("""
    import os, select, shutil, signal, sys, time
    select.select([os.pidfd_open(int(sys.argv[1]))], [], [])
    os.killpg(int(sys.argv[2]), signal.SIGKILL)
    time.sleep(2)
    shutil.rmtree(sys.argv[3], ignore_errors=True)
""")
# ray.nodes() from a driver of its own: the ids of the alive nodes, once there are two.
ALIVE_NODES = textwrap.dedent("""
    import json, sys, time
    import ray
    ray.init(address=sys.argv[1], log_to_driver=False, configure_logging=False)
    deadline = time.monotonic() + float(sys.argv[2])
    while True:
        alive = sorted(node["NodeID"] for node in ray.nodes() if node["Alive"])
        if len(alive) >= 2 or time.monotonic() > deadline:
            break
        time.sleep(1)
    print(json.dumps(alive))
""")


def free_ports(count):
    """`count` distinct ports free on this host now (held open together while chosen)."""
    sockets = []
    try:
        for _ in range(count):
            sockets.append(socket.socket())
            sockets[-1].bind(("", 0))
        return [s.getsockname()[1] for s in sockets]
    finally:
        for s in sockets:
            s.close()


def node_env():
    """The nodes' environment: without this test's PYTHONPATH, so that the workers get
    pbp_drake from the study (its runtime_env), as the nodes of a real cluster would."""
    env = {key: value for key, value in os.environ.items() if key != "PYTHONPATH"}
    return {**env, **AUTH, "RAY_USAGE_STATS_ENABLED": "0"}


def start_node(root, name, head_args):
    """`ray start --block` for one node, in a process group of its own, its output in
    ROOT/NAME.log. Every port a node opens is chosen here: two nodes share this host."""
    node_manager, object_manager, agent, agent_grpc, runtime_env_agent, metrics = free_ports(6)
    command = [RAY_CLI, "start", "--block", *head_args, "--num-cpus=1",
               f"--temp-dir={root / name}", f"--object-store-memory={OBJECT_STORE_BYTES}",
               f"--node-manager-port={node_manager}", f"--object-manager-port={object_manager}",
               f"--dashboard-agent-listen-port={agent}",
               f"--dashboard-agent-grpc-port={agent_grpc}",
               f"--runtime-env-agent-port={runtime_env_agent}",
               f"--metrics-export-port={metrics}", "--disable-usage-stats"]
    log = open(root / f"{name}.log", "w")
    process = subprocess.Popen(command, stdout=log, stderr=subprocess.STDOUT,
                               stdin=subprocess.DEVNULL, env=node_env(), cwd=root,
                               start_new_session=True)
    log.close()
    return process


def watch(process, root):
    """A process of its own that kills `process`'s group and removes `root` when this
    test's process ends, however it ends (even SIGKILL, when no finalizer runs); the
    finalizer kills it first."""
    return subprocess.Popen([sys.executable, "-c", WATCHDOG, str(os.getpid()),
                             str(process.pid), str(root)], stdin=subprocess.DEVNULL,
                            start_new_session=True)


def wait_for(condition, timeout, what, root, process):
    deadline = time.monotonic() + timeout
    while not condition():
        if time.monotonic() > deadline or process.poll() is not None:
            logs = "\n".join(f"--- {path.name}\n{path.read_text()[-3000:]}"
                             for path in sorted(root.glob("*.log")))
            raise AssertionError(f"{what} within {timeout} s\n{logs}")
        time.sleep(0.5)


def stop_nodes(processes, watchdogs, root):
    """Kills the nodes as `ray stop --force` would, but only these: their process groups,
    their descendants (Ray's workers run in groups of their own) and any process whose
    command line names this test's temp folder, each by its id. (They do not end on
    SIGTERM within seconds, and nothing of theirs needs to outlive the test.)"""
    started = time.monotonic()
    descendants = _descendants({process.pid for process in processes})
    for process in processes:
        _signal_group(process.pid, signal.SIGKILL)
    for pid in descendants | _processes_naming(root):
        try:
            os.kill(pid, signal.SIGKILL)
        except (ProcessLookupError, PermissionError):
            pass
    for process in processes:
        process.wait(timeout=30)
    deadline = time.monotonic() + 30
    while any(_group_alive(p.pid) for p in processes) and time.monotonic() < deadline:
        time.sleep(0.2)
    for watchdog in watchdogs:
        watchdog.kill()
        watchdog.wait(timeout=10)
    print(f"Ray nodes stopped in {time.monotonic() - started:.1f} s")


def _proc_entries():
    """(pid, parent pid, command line) of every process (Linux's /proc)."""
    for folder in pathlib.Path("/proc").glob("[0-9]*"):
        try:
            parent = int((folder / "stat").read_text().rsplit(")", 1)[1].split()[1])
            yield int(folder.name), parent, (folder / "cmdline").read_bytes()
        except (OSError, ValueError, IndexError):
            pass


def _descendants(pids):
    """`pids`' descendants now."""
    children = {}
    for pid, parent, _ in _proc_entries():
        children.setdefault(parent, []).append(pid)
    found, queue = set(), list(pids)
    while queue:
        for child in children.get(queue.pop(), ()):
            if child not in found:
                found.add(child)
                queue.append(child)
    return found


def _processes_naming(root):
    """The ids of the processes whose command line names `root`."""
    return {pid for pid, _, cmdline in _proc_entries() if str(root).encode() in cmdline}


def _signal_group(pgid, signum):
    try:
        os.killpg(pgid, signum)
    except (ProcessLookupError, PermissionError):
        pass


def _group_alive(pgid):
    """Whether a process of group `pgid` still runs (zombies do not count: whoever
    adopted them may never reap them)."""
    for stat in pathlib.Path("/proc").glob("[0-9]*/stat"):
        try:
            fields = stat.read_text().rsplit(")", 1)[1].split()
        except (OSError, IndexError):
            continue
        if fields[0] != "Z" and fields[2] == str(pgid):
            return True
    return False


@pytest.fixture(scope="module")
def cluster(request):
    """A head node and a second node joining it, on this host: (address, node ids)."""
    # Short: a node's Unix sockets live under it, and their paths must stay under 108 bytes.
    root = pathlib.Path(tempfile.mkdtemp(prefix="pbpray", dir="/tmp"))
    processes, watchdogs = [], []
    request.addfinalizer(lambda: (stop_nodes(processes, watchdogs, root),
                                  shutil.rmtree(root, ignore_errors=True)))
    port, dashboard = free_ports(2)  # Ray starts a dashboard process even without the UI
    started = time.monotonic()
    processes.append(start_node(root, "head", [
        "--head", f"--port={port}", "--include-dashboard=false",
        f"--dashboard-port={dashboard}"]))
    watchdogs.append(watch(processes[-1], root))
    address_file = root / "head" / "ray_current_cluster"
    wait_for(address_file.exists, NODE_TIMEOUT, "the head node did not start", root,
             processes[0])
    address = address_file.read_text().strip()
    assert address.endswith(f":{port}")
    processes.append(start_node(root, "worker", [f"--address={address}"]))
    watchdogs.append(watch(processes[-1], root))
    alive = subprocess.run(
        [sys.executable, "-c", ALIVE_NODES, address, str(NODE_TIMEOUT)], env=node_env(),
        capture_output=True, text=True, timeout=NODE_TIMEOUT + 60, stdin=subprocess.DEVNULL)
    assert alive.returncode == 0, alive.stderr[-3000:]
    nodes = json.loads(alive.stdout.strip().splitlines()[-1])
    assert len(nodes) == 2, f"alive nodes: {nodes}\n" + (root / "worker.log").read_text()
    print(f"two Ray nodes up in {time.monotonic() - started:.1f} s at {address}")
    return address, nodes


def study(output, *extra, env=None):
    """`pbp-drake study diagrams/hsr_reach.yaml` of 2 methods x 1 trial, as a user runs it
    (CI=true, no stdin; Ray's token only when `env` gives it); returns the finished
    process."""
    command = [sys.executable, "-m", "pbp_drake", "study",
               str(REPO / "diagrams" / "hsr_reach.yaml"), "--methods", ",".join(METHODS),
               "--trials", "1", "--output", str(output), *extra]
    base = {key: value for key, value in os.environ.items() if key not in AUTH}
    env = {**base, **(env or {}), "PYTHONPATH": str(REPO), "CI": "true"}
    started = time.monotonic()
    # Not from the checkout: Ray puts a driver's working folder on its workers' path, which
    # on one machine would hand them this pbp_drake whether the study sends it or not.
    output.parent.mkdir(parents=True, exist_ok=True)
    done = subprocess.run(command, cwd=output.parent, env=env, capture_output=True,
                          text=True, stdin=subprocess.DEVNULL, timeout=STUDY_TIMEOUT)
    print(f"{' '.join(extra)}: {time.monotonic() - started:.1f} s")
    return done


@pytest.fixture(scope="module")
def studies(cluster, tmp_path_factory):
    address, _ = cluster
    root = tmp_path_factory.mktemp("cluster_studies")
    on_ray = study(root / "ray", "--backend", "ray", "--ray-address", address, "--jobs", "2",
                   env=AUTH)
    assert on_ray.returncode == 0, on_ray.stdout[-3000:] + on_ray.stderr[-3000:]
    assert f"on Ray ({address})" in on_ray.stdout
    local = study(root / "local", "--jobs", "2")
    assert local.returncode == 0, local.stdout[-3000:] + local.stderr[-3000:]
    return root / "ray", root / "local"


def test_a_study_on_two_ray_nodes_gives_the_summary_of_local_processes(studies):
    on_ray, local = studies
    # summary.json holds only values read from the trial files, none that say how or when
    # they ran (no wall times, hosts or Ray nodes): so nothing is left out, it is the
    # same bytes; and so are the table and the flat list of trials.
    for name in ("summary.json", "results.md", "trials.json"):
        assert (on_ray / name).read_bytes() == (local / name).read_bytes(), name
    summary = json.loads((on_ray / "summary.json").read_text())
    assert list(summary["methods"]) == METHODS
    assert summary["seeds"] == [SEEDS[0], SEEDS[-1]]  # the first and the last
    for entry in summary["methods"].values():
        assert entry["trials"] == 1 and entry["errors"] == 0 and entry["missing"] == 0
    # Each trial, field by field, but for wall_time (how long it took on a busy machine)
    # and host and ray_node (where it ran: only a Ray trial records them); its time
    # series the same bytes.
    for method in METHODS:
        for seed in SEEDS:
            ray_json, ray_csv = trial_paths(on_ray, method, seed)
            local_json, local_csv = trial_paths(local, method, seed)
            assert ray_csv.read_bytes() == local_csv.read_bytes(), (method, seed)
            ours, theirs = json.loads(ray_json.read_text()), json.loads(local_json.read_text())
            for field in ("wall_time", "host", "ray_node"):
                ours.pop(field, None)
                theirs.pop(field, None)
            assert ours == theirs, (method, seed)


def test_the_trials_ran_on_both_nodes(cluster, studies):
    _, nodes = cluster
    on_ray, local = studies
    ran_on = []
    for method in METHODS:
        for seed in SEEDS:
            record = json.loads(trial_paths(on_ray, method, seed)[0].read_text())
            # (Where another pbp_drake is installed, this also shows that the workers ran
            # the one the study sent them: a copy older than this field does not write it.)
            assert "ray_node" in record, f"{method}, seed {seed}: no ray_node"
            assert record["host"] == socket.gethostname()
            ran_on.append(record["ray_node"])
            assert "ray_node" not in json.loads(trial_paths(local, method, seed)[0].read_text())
    # The two trials at once (--jobs 2) on nodes of one CPU each: one ran on each node.
    assert sorted(set(ran_on)) == nodes, ran_on


def test_a_study_without_the_clusters_token_says_why(cluster, tmp_path):
    address, _ = cluster
    # As on a machine where nobody exported RAY_AUTH_MODE and RAY_AUTH_TOKEN. Ray's driver
    # tries the refused connection once a second, 20 times by default, before it gives up;
    # RAY_gcs_server_port_wait_time_s cuts that to 2 tries (the same error, 18 s sooner).
    done = study(tmp_path / "out", "--backend", "ray", "--ray-address", address,
                 env=NO_TOKEN_RETRIES)
    assert done.returncode == 2
    message = next(line for line in done.stderr.splitlines() if line.startswith("pbp-drake:"))
    assert message.startswith(f"pbp-drake: could not connect to Ray at {address}: ")
    assert "AuthenticationError" in message and "RAY_AUTH_TOKEN" in message
    assert not list((tmp_path / "out").glob("trials/*/*.json"))
