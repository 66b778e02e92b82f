"""Why does a trained policy stop making progress? A diagnostic for docs/results.md.

    python training/diagnose_cycles.py thesis-config01
    python training/diagnose_cycles.py runs/config01/seed0 --episodes 30

Plays the thesis protocol (deterministic, episode i reset with seed i) and, for every episode
that ends by the no-progress limit, looks at its last ``no_progress_limit`` decisions: how many
distinct targets the policy chose, and how often the chosen cluster was a padding slot or
vanished from the slots after the move (which would point at the slot selection rather than at
the policy).
"""

from __future__ import annotations

import argparse
import json
from collections import Counter
from pathlib import Path

from frontier_marl.envs.gym_env import FrontierExploreEnv
from frontier_marl.envs.infos import reason_name, slot_table
from frontier_marl.policies.models import PRETRAINED, load_model, pretrained_model_dir


def diagnose(model_dir: Path, episodes: int) -> dict[str, float]:
    loaded = load_model(model_dir / "model.zip")
    env_config = json.loads((model_dir / "model.json").read_text())["env_config"]
    env = FrontierExploreEnv(obs_layout="flat", **env_config)  # the model's own layout
    window = env.config.reward.no_progress_limit
    counts: Counter[str] = Counter()
    for seed in range(episodes):
        obs, info = env.reset(seed=seed)
        history = []
        done = False
        while not done:
            action, _ = loaded.model.predict(obs, deterministic=True)
            slot = int(action)
            rows = slot_table(info).rows()
            chosen = next((c["target"] for c in rows if c["slot"] == slot), None)
            obs, _, terminated, truncated, info = env.step(slot)
            still_live = chosen in {c["target"] for c in slot_table(info).rows()}
            history.append((chosen, still_live))
            done = terminated or truncated
        reason = reason_name(info["end_reason"])
        counts[f"end: {reason}"] += 1
        if "no_progress" in reason:
            stuck = history[-window:]
            counts["stuck episodes"] += 1
            counts["stuck decisions"] += len(stuck)
            counts["stuck: padding slot"] += sum(target is None for target, _ in stuck)
            counts["stuck: chosen cluster gone after the move"] += sum(
                target is not None and not live for target, live in stuck
            )
            counts["stuck: distinct targets"] += len({target for target, _ in stuck})
    stuck = max(counts["stuck episodes"], 1)
    return {
        **dict(counts),
        "distinct targets per stuck episode": counts["stuck: distinct targets"] / stuck,
    }


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("model", help="a shipped model name or a run folder with model.zip")
    parser.add_argument("--episodes", type=int, default=30)
    args = parser.parse_args(argv)
    folder = pretrained_model_dir(args.model) if args.model in PRETRAINED else Path(args.model)
    for key, value in diagnose(folder, args.episodes).items():
        print(f"{key:<45}{value:g}")
    return 0
