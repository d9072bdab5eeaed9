"""`python -m pbp_drake_bench.soak`: a soak test of the HSR reaching task. One process, one
Meshcat and one diagram run the task of `diagrams/hsr_reach.yaml` (virtual participant,
seed 0) back to back, each run to success on a fresh Simulator, as fast as possible, for an
hour of simulated time in all (`--minutes`), every run's per-tick rows streamed to a CSV
file of its own (`run_task_streamed`). The resident memory (VmRSS) is sampled every
simulated minute; the soak fails (exit 1) when its peak after the first minute is 10 % or
more above the first minute's, or when a run fails.

Why one diagram: pydrake 1.51 never frees a Python LeafSystem that declared a callback (its
bound methods and the C++ system form a cycle Python's garbage collector cannot see: Drake
issues 23930 and 24162), so every diagram built in a process stays in memory, about 2.5 MB
for this task. Why runs to success: held at its target past success (a success distance
it never reaches), the task's plant diverges (SAP fails to converge) within a minute.
"""

import argparse
import dataclasses
import pathlib
import sys
import time

from pydrake.geometry import Meshcat, MeshcatParams

from pbp_drake.builder import build_diagram
from pbp_drake.builder.streamed_run import run_task_streamed
from pbp_drake.scenarios import counted, load_scenario_file, resolve

# The repository's diagrams/ folder (this file is pbp_drake_bench/soak.py).
SCENARIO_FILE = pathlib.Path(__file__).resolve().parents[1] / "diagrams" / "hsr_reach.yaml"
DEFAULT_LOG_DIR = pathlib.Path("outputs", "soak")
GROWTH_LIMIT_PERCENT = 10.0


@dataclasses.dataclass
class Soak:
    """What a soak measured.

    Attributes:
        samples: `(simulated seconds, wall seconds, RSS in bytes)` at the end of the first
            chunk at or after each simulated minute (the first one is the baseline).
        results: each run's TaskResult (its time series are in its CSV).
        log_paths: each run's CSV file of per-tick rows.
    """

    samples: list
    results: list
    log_paths: list

    @property
    def growth_percent(self):
        """How much the RSS grew after the first minute: its peak over the samples against
        the first, in percent."""
        baseline = self.samples[0][2]
        return 100.0 * (max(rss for _, _, rss in self.samples) - baseline) / baseline


def resident_bytes():
    """This process's resident set size (VmRSS of /proc/self/status), in bytes."""
    with open("/proc/self/status") as status:
        for line in status:
            if line.startswith("VmRSS:"):
                return int(line.split()[1]) * 1024
    raise RuntimeError("/proc/self/status has no VmRSS line")


def run_soak(minutes, log_dir, meshcat=None, report=None):
    """Runs the soak (see the module's docstring) for `minutes` of simulated time, the runs'
    CSV files `run_0001.csv`, ... in `log_dir`; `report(sample)` is called with each
    `(simulated seconds, wall seconds, RSS bytes)` sample as it is taken. Meshcat is made
    here when not given (on a free port of localhost). The last run stops at the soak's end,
    its time limit (the scenario's duration) cut to what is left."""
    if meshcat is None:
        meshcat = Meshcat(MeshcatParams(host="localhost", port=None))
    log_dir = pathlib.Path(log_dir)
    log_dir.mkdir(parents=True, exist_ok=True)
    resolved = resolve(load_scenario_file(SCENARIO_FILE).scenario)
    scenario = resolved.scenario
    diagram = build_diagram(resolved, meshcat)
    soak = Soak(samples=[], results=[], log_paths=[])
    total = minutes * 60.0
    done = 0.0  # simulated seconds of the runs finished
    started = time.monotonic()

    def after_chunk(simulated):
        now = done + simulated
        if now + 1e-9 >= 60.0 * (len(soak.samples) + 1):
            soak.samples.append((now, time.monotonic() - started, resident_bytes()))
            if report is not None:
                report(soak.samples[-1])

    while total - done > scenario.control_period / 2:
        left = total - done
        run = resolved if left >= scenario.duration else dataclasses.replace(
            resolved, scenario=dataclasses.replace(scenario, duration=left))
        log_path = log_dir / f"run_{len(soak.results) + 1:04d}.csv"
        reached = []
        result = run_task_streamed(run, log_path, meshcat, realtime_rate=0.0, diagram=diagram,
                                   after_chunk=lambda t: (reached.append(t), after_chunk(t)))
        soak.results.append(result)
        soak.log_paths.append(log_path)
        done += reached[-1]
    return soak


def _megabytes(rss):
    return f"{rss / 2**20:.1f} MB"


def main(argv=None):
    parser = argparse.ArgumentParser(prog="python -m pbp_drake_bench.soak",
                                     description=__doc__.split("\n\n")[0])
    parser.add_argument("--minutes", type=int, default=60,
                        help="simulated minutes, at least 2 (default 60)")
    parser.add_argument("--log-dir", type=pathlib.Path, default=DEFAULT_LOG_DIR,
                        metavar="DIR", help="the folder of the runs' per-tick CSV files "
                        f"(default {DEFAULT_LOG_DIR})")
    args = parser.parse_args(argv)
    if args.minutes < 2:
        parser.error("--minutes must be at least 2 (the first minute is the baseline)")
    meshcat = Meshcat(MeshcatParams(host="localhost", port=None))
    print(f"Soak: the HSR reaching task back to back for {args.minutes} simulated minutes, "
          f"Meshcat at {meshcat.web_url()}, per-tick rows in {args.log_dir}/run_*.csv",
          flush=True)

    def report(sample):
        simulated, wall, rss = sample
        print(f"  {simulated / 60:5.1f} min simulated, {wall:6.0f} s wall: RSS "
              f"{_megabytes(rss)}", flush=True)

    soak = run_soak(args.minutes, args.log_dir, meshcat, report)
    (_, _, first), (simulated, wall, last) = soak.samples[0], soak.samples[-1]
    peak = max(rss for _, _, rss in soak.samples)
    rows = sum(sum(1 for _ in open(path)) - 1 for path in soak.log_paths)
    failed = sum(not result.success for result in soak.results[:-1])
    print(f"{counted(len(soak.results), 'run')} ({failed} failed before the last), "
          f"{counted(rows, 'row')} (one per "
          f"tick), {simulated:.0f} s simulated in {wall:.0f} s wall", flush=True)
    print(f"RSS at 1 min {_megabytes(first)}, at the end {_megabytes(last)}, peak "
          f"{_megabytes(peak)}: growth {soak.growth_percent:.2f} % (limit "
          f"{GROWTH_LIMIT_PERCENT:g} %)", flush=True)
    if failed:
        print(f"pbp-drake soak: {failed} runs failed", file=sys.stderr)
        return 1
    if soak.growth_percent >= GROWTH_LIMIT_PERCENT:
        print(f"pbp-drake soak: memory grew {soak.growth_percent:.1f} % after the first "
              "minute", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
