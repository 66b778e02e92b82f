"""The same speed measurements on two revisions of the package, alternated in one run.

    python benchmarks/bench_revisions.py BEFORE_TREE [AFTER_TREE] --rounds 3 --json out.json

``BEFORE_TREE`` and ``AFTER_TREE`` (default: this checkout) are source trees of the package, e.g.
``git worktree add /tmp/before <commit>``. Each round runs every measurement once per tree, in
a fresh process whose ``PYTHONPATH`` puts that tree first, alternating the order from round to
round so that the drift of a shared machine hits both alike. Measurements, all on
thesis-20x20 with one robot and random valid actions:

* ``step_us``: microseconds per ``step`` (resets not timed) of ``FrontierExploreEnv`` with its
  default infos, and ``step_us_training``: the same with the infos training uses
  (``info="minimal"`` where the tree has it); ``parallel_step_us``: the same for
  ``frontier_marl.parallel_env`` (default infos); each also as the stepping thread's CPU time
  (``step_cpu_us``...), which the other processes of a shared machine move less;
* ``env_share``: the share of thesis-DQN training time spent in the env (training infos),
  against a null env with the same spaces, interleaved in chunks within one process
  (:func:`frontier_marl.experiments.speed.bench_env.train_interleaved`).

The report gives each figure's median and minimum over the rounds per tree and the ratio of
the medians (``--dqn-steps 0`` leaves the training share out, for quick step timings).
``--vector-envs N`` also times ``vector_env(N)`` per decision (CPU time) in the trees that have
it, and reports it against the before tree's single parallel env.
"""

from __future__ import annotations

import argparse
import importlib.util
import json
import os
import statistics
import subprocess
import sys
import time
from pathlib import Path
from types import ModuleType
from typing import Any

HERE = Path(__file__).resolve().parent
#: The figures, each a wall-clock time and the CPU time of the stepping thread (``_cpu_``):
#: on a shared machine the CPU time moves less with the other processes' load.
KEYS = (
    "step_us",
    "step_cpu_us",
    "step_us_training",
    "step_cpu_us_training",
    "parallel_step_us",
    "parallel_step_cpu_us",
    "env_share",
)
#: The measurement code of the training share, in this checkout.
BENCH_ENV = HERE.parent / "frontier_marl" / "experiments" / "speed" / "bench_env.py"


def make_env(training: bool) -> Any:
    import frontier_marl

    if training:
        try:
            return frontier_marl.FrontierExploreEnv(preset="thesis-20x20", info="minimal")
        except ValueError:  # a tree without info levels: its only infos are the full ones
            pass
    return frontier_marl.FrontierExploreEnv(preset="thesis-20x20")


def step_us(training: bool, steps: int) -> tuple[float, float]:
    """Wall and CPU (this thread's) microseconds per step of the Gymnasium env."""
    import numpy as np

    env = make_env(training)
    rng = np.random.default_rng(0)
    _, info = env.reset(seed=0)
    for _ in range(200):  # warm-up: compiled kernels, caches
        _, _, terminated, truncated, info = env.step(
            int(rng.choice(np.flatnonzero(info["action_mask"])))
        )
        if terminated or truncated:
            _, info = env.reset()
    elapsed = cpu = 0.0
    seed = 1
    for _ in range(steps):
        action = int(rng.choice(np.flatnonzero(info["action_mask"])))
        start, start_cpu = time.perf_counter(), time.thread_time()
        _, _, terminated, truncated, info = env.step(action)
        cpu += time.thread_time() - start_cpu
        elapsed += time.perf_counter() - start
        if terminated or truncated:
            _, info = env.reset(seed=seed)
            seed += 1
    return 1e6 * elapsed / steps, 1e6 * cpu / steps


def parallel_step_us(steps: int) -> tuple[float, float]:
    """Wall and CPU microseconds per step of ``frontier_marl.parallel_env`` (default infos)."""
    import numpy as np

    import frontier_marl

    env = frontier_marl.parallel_env(preset="thesis-20x20")
    rng = np.random.default_rng(0)
    _, infos = env.reset(seed=0)
    elapsed = cpu = 0.0
    seed = 1
    for step in range(steps + 200):  # the first 200 warm up
        if not env.agents:
            _, infos = env.reset(seed=seed)
            seed += 1
        actions = {a: int(rng.choice(np.flatnonzero(infos[a]["action_mask"]))) for a in env.agents}
        start, start_cpu = time.perf_counter(), time.thread_time()
        _, _, _, _, infos = env.step(actions)
        if step >= 200:
            cpu += time.thread_time() - start_cpu
            elapsed += time.perf_counter() - start
    return 1e6 * elapsed / steps, 1e6 * cpu / steps


def vector_cpu_us(num_envs: int, steps: int) -> float | None:
    """CPU microseconds per decision of ``frontier_marl.vector_env(num_envs)`` (mask infos,
    random valid slots, thesis-20x20), or None in a tree without it."""
    import numpy as np

    import frontier_marl

    if not hasattr(frontier_marl, "vector_env"):
        return None
    env = frontier_marl.vector_env(num_envs, preset="thesis-20x20", info="mask")
    rng = np.random.default_rng(0)
    _, infos = env.reset(seed=0)
    cpu = 0.0
    for step in range(steps + 20):  # the first 20 warm up
        masks = infos["action_mask"]
        actions = (rng.random(masks.shape) * masks).argmax(axis=1)
        start = time.thread_time()
        _, _, _, _, infos = env.step(actions)
        if step >= 20:
            cpu += time.thread_time() - start
    return 1e6 * cpu / (steps * num_envs)


def checkout_module(path: Path) -> ModuleType:
    """The module in ``path``, loaded from its file: the worker's ``frontier_marl`` is the tree
    under test (``PYTHONPATH``), which may predate the module, and every tree is measured by
    this checkout's code."""
    spec = importlib.util.spec_from_file_location(path.stem, path)
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def env_share(steps: int, chunks: int) -> float:
    bench = checkout_module(BENCH_ENV)
    env = make_env(training=True)
    seconds = bench.train_interleaved({"null": bench.NullEnv(env), "env": env}, steps, chunks)
    null, real = sum(seconds["null"]), sum(seconds["env"])
    return (real - null) / real


def worker(args: argparse.Namespace) -> None:
    import frontier_marl

    report: dict[str, Any] = {"package": frontier_marl.__file__}
    for name, (wall, cpu) in (
        ("step_us", step_us(False, args.steps)),
        ("step_us_training", step_us(True, args.steps)),
        ("parallel_step_us", parallel_step_us(args.steps)),
    ):
        report[name], report[name.replace("_us", "_cpu_us")] = wall, cpu
    if args.vector_envs > 0:
        report["vector_cpu_us"] = vector_cpu_us(args.vector_envs, max(args.steps // 64, 10))
    if args.dqn_steps > 0:
        report["env_share"] = env_share(args.dqn_steps, args.dqn_chunks)
    print(json.dumps(report))


def measure(tree: Path, args: argparse.Namespace) -> dict[str, Any]:
    env = {**os.environ, "PYTHONPATH": str(tree)}
    command = [sys.executable, __file__, "--worker", "--steps", str(args.steps)]
    command += ["--dqn-steps", str(args.dqn_steps), "--dqn-chunks", str(args.dqn_chunks)]
    command += ["--vector-envs", str(args.vector_envs)]
    done = subprocess.run(command, env=env, capture_output=True, text=True, check=True)
    report = json.loads(done.stdout.strip().splitlines()[-1])
    if not Path(report["package"]).is_relative_to(tree):
        raise RuntimeError(f"{tree}: the worker imported {report['package']}")
    return report


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("before", type=Path, nargs="?")
    parser.add_argument("after", type=Path, nargs="?", default=HERE.parent)
    parser.add_argument("--rounds", type=int, default=3)
    parser.add_argument("--steps", type=int, default=20_000, help="timed env steps")
    parser.add_argument("--dqn-steps", type=int, default=30_000)
    parser.add_argument("--dqn-chunks", type=int, default=10)
    parser.add_argument(
        "--vector-envs", type=int, default=0, help="also time vector_env(N) (0: not)"
    )
    parser.add_argument("--json", type=Path, default=None)
    parser.add_argument("--worker", action="store_true", help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.worker:
        worker(args)
        return
    if args.before is None:
        parser.error("give the source tree of the revision to compare with")
    trees = {"before": args.before.resolve(), "after": args.after.resolve()}
    runs: dict[str, list[dict[str, Any]]] = {name: [] for name in trees}
    for round_index in range(args.rounds):
        order = list(trees) if round_index % 2 == 0 else list(reversed(trees))
        for name in order:
            runs[name].append(measure(trees[name], args))
            print(f"round {round_index + 1}, {name}: {runs[name][-1]}", file=sys.stderr)
    keys = [k for k in KEYS if k in runs["after"][0] and k in runs["before"][0]]
    stats = {
        name: {
            k: {"median": statistics.median(r[k] for r in rows), "min": min(r[k] for r in rows)}
            for k in keys
        }
        for name, rows in runs.items()
    }
    report = {
        "trees": {name: str(tree) for name, tree in trees.items()},
        "rounds": args.rounds,
        "steps": args.steps,
        "dqn_steps": args.dqn_steps,
        "runs": runs,
        "stats": stats,
        "median_ratio_after_before": {
            k: stats["after"][k]["median"] / stats["before"][k]["median"] for k in keys
        },
    }
    for k in keys:
        before, after = stats["before"][k], stats["after"][k]
        print(
            f"{k:<22} median before {before['median']:8.3f} after {after['median']:8.3f} "
            f"(ratio {after['median'] / before['median']:.3f}); min before {before['min']:8.3f} "
            f"after {after['min']:8.3f}"
        )
    vector = [r["vector_cpu_us"] for r in runs["after"] if r.get("vector_cpu_us") is not None]
    if vector:  # the batched env against the older tree's single env, per decision
        single = statistics.median(r["parallel_step_cpu_us"] for r in runs["before"])
        per_decision = statistics.median(vector)
        report["vector_speedup_over_before_single"] = single / per_decision
        print(
            f"vector_env({args.vector_envs}) CPU us per decision, median {per_decision:.3f}: "
            f"{single / per_decision:.1f}x the before tree's single parallel env"
        )
    if args.json is not None:
        args.json.write_text(json.dumps(report, indent=1) + "\n")


if __name__ == "__main__":
    main()
