"""The heuristic baselines: every heuristic with the thesis's protocol on one env setting.

:func:`run_baselines` gives one JSON-able row per heuristic (an
:class:`~frontier_marl.evaluation.EvaluationResult` dict, with the thesis's figure beside it
where the thesis gives one for that setting); :func:`format_table` prints them and
:func:`dumps_rows` writes them as JSON. ``frontier-marl baselines`` and ``reproduce`` use them.
"""

from __future__ import annotations

import json
from collections.abc import Sequence
from pathlib import Path
from typing import Any

from frontier_marl.config import EnvConfig, make_config
from frontier_marl.config.thesis import heuristic_baseline
from frontier_marl.evaluation import evaluate
from frontier_marl.policies import make_policy
from frontier_marl.policies.registry import env_settings
from frontier_marl.utils.json_files import json_safe
from frontier_marl.utils.progress import progress_bar

DEFAULT_POLICIES = "greedy-distance,greedy-gain,cost-utility,random"

#: The thesis's baseline protocol (its Table 6.5: one robot on a ``thesis-*`` preset's
#: geometry): the options each heuristic runs with there. Greedy distance (nearest centroid)
#: re-decides every step, except once it stands again on a cell without having seen anything
#: new since it stood there: it would then cycle between two clusters until the no-progress
#: rule ends the episode, so it keeps its target until it sees something (``commit``
#: ``on-cycle``; docs/calibration.md, "Table 6.5"). Elsewhere, and through ``make_policy``
#: alone, the heuristics keep their own defaults.
THESIS_PROTOCOL: dict[str, dict[str, Any]] = {"greedy-distance": {"commit": "on-cycle"}}


def _thesis_comparable(cfg: EnvConfig, preset: str) -> bool:
    """Whether the thesis's figures apply: its geometry (size, range) with one robot only."""
    base = make_config(preset)
    return (
        cfg.n_agents == 1
        and cfg.map_path is None
        and cfg.map_generator == base.map_generator
        and (cfg.height, cfg.width, cfg.perception_range)
        == (base.height, base.width, base.perception_range)
    )


def run_baselines(
    env_kwargs: dict[str, Any],
    policies: Sequence[str],
    episodes: int,
    seed: int,
    progress: bool = True,
) -> list[dict[str, Any]]:
    """Evaluate each heuristic; one JSON-able row per policy (see ``EvaluationResult``).

    Where the run is the thesis's setting (one robot, a ``thesis-*`` preset's geometry, its
    map generator), the thesis's figure is put beside each row and the heuristics take the
    options of :data:`THESIS_PROTOCOL`.
    """
    cfg = make_config(**env_kwargs)
    preset = str(env_kwargs.get("preset", "thesis-20x20"))
    comparable = _thesis_comparable(cfg, preset)
    protocol = comparable and preset.startswith("thesis-")
    rows = []
    with progress_bar(episodes * len(policies), disable=not progress, unit="ep") as bar:
        for name in policies:
            bar.set_description(name)
            options = THESIS_PROTOCOL.get(name, {}) if protocol else {}
            result = evaluate(
                {**env_kwargs, **env_settings(name)},
                make_policy(name, seed, **options),
                episodes=episodes,
                seed=seed,
                on_episode=lambda _i, _rec: bar.update(1),
            )
            row = result.to_dict()
            figure = heuristic_baseline(preset, cfg.map_mode, name) if comparable else None
            row["preset"] = preset
            row["thesis_mean"] = None if figure is None else figure[0]
            row["thesis_std"] = None if figure is None else figure[1]
            rows.append(row)
    return rows


def _fmt_cells(entry: dict[str, Any], episodes: int) -> str:
    if not entry["reached"]:
        return f"— (0/{episodes})"
    return f"{entry['mean']:.1f} ({entry['reached']}/{episodes})"


def _fmt_mean_std(mean: float | None, std: float | None, digits: int = 1) -> str:
    if mean is None:
        return "—"
    return f"{mean:.{digits}f} ± {std:.{digits}f}"


def _table_row(row: dict[str, Any], levels: list[str], team: bool) -> list[str]:
    """One policy's cells of :func:`format_table`."""
    n = row["episodes"]
    thesis = (
        "—"
        if row.get("thesis_mean") is None
        else f"{row['thesis_mean']:.2f} ± {row['thesis_std']:.2f}"
    )
    cells = [_fmt_cells(row["cells_to_coverage"][key], n) for key in levels]
    if team:
        spans = row.get("makespan_to_coverage", {})
        cells += [
            _fmt_mean_std(row.get("mean_makespan"), row.get("std_makespan")),
            *(_fmt_cells(spans[key], n) if key in spans else "—" for key in levels),
            _fmt_mean_std(row.get("mean_overlap"), row.get("std_overlap"), 3),
        ]
    shares = " ".join(f"{s:.2f}" for s in row["action_shares"])
    return [
        row["policy"],
        f"{row['mean_reward']:.2f} ± {row['std_reward']:.2f}",
        thesis,
        f"{row['terminations']}/{n}",
        f"{row['mean_steps']:.1f}",
        f"{row['mean_travelled']:.1f}",
        *cells,
        shares,
    ]


def format_table(rows: Sequence[dict[str, Any]]) -> str:
    """The results as a plain-text table; with a team (``n_agents > 1``) also the makespan
    (longest single robot path) at the end and to each coverage level, and the overlap."""
    header = ["policy", "reward", "thesis", "term.", "steps", "travelled"]
    levels = list(rows[0]["cells_to_coverage"]) if rows else []
    team = any(row.get("n_agents", 1) > 1 for row in rows)
    header += [f"cells→{float(key):.0%}" for key in levels]
    if team:
        header += ["makespan", *(f"makespan→{float(key):.0%}" for key in levels), "overlap"]
    header.append("action shares")
    lines = [header, *(_table_row(row, levels, team) for row in rows)]
    widths = [max(len(line[i]) for line in lines) for i in range(len(header))]
    out = []
    for k, line in enumerate(lines):
        out.append("  ".join(cell.ljust(w) for cell, w in zip(line, widths, strict=True)).rstrip())
        if k == 0:
            out.append("  ".join("-" * w for w in widths))
    return "\n".join(out)


def describe(env_kwargs: dict[str, Any], episodes: int, seed: int) -> str:
    cfg = make_config(**env_kwargs)
    if cfg.map_path is not None:
        layout = f"file {Path(cfg.map_path).name}"
    elif cfg.map_mode == "static":
        layout = f"{cfg.map_generator}, map_seed={cfg.map_seed}"
    else:
        layout = f"{cfg.map_generator}, fresh layout per seed"
    return (
        f"{env_kwargs.get('preset')} ({cfg.height}x{cfg.width}, r={cfg.perception_range}), "
        f"{cfg.map_mode} map ({layout}), {cfg.n_agents} robot(s), {episodes} episodes, "
        f"seeds {seed}..{seed + episodes - 1}"
    )


#: Per-episode keys of the per-step coverage curves (left out of results kept in the tree).
CURVE_KEYS = ("curve", "makespan_curve")


def without_curves(row: dict[str, Any]) -> dict[str, Any]:
    """An evaluation row with its per-episode records but without their per-step curves."""
    episodes = [
        {k: v for k, v in episode.items() if k not in CURVE_KEYS}
        for episode in row.get("per_episode", [])
    ]
    return {**row, "per_episode": episodes}


def dumps_rows(rows: Sequence[dict[str, Any]]) -> str:
    """JSON text of the rows: summary fields indented, one compact line per episode."""
    parts = []
    for row in json_safe(list(rows)):
        episodes = row.pop("per_episode", None)
        text = json.dumps(row, indent=1)
        if episodes is not None:
            lines = ",\n  ".join(json.dumps(e, separators=(",", ":")) for e in episodes)
            text = text[: -len("\n}")] + f',\n "per_episode": [\n  {lines}\n ]\n}}'
        parts.append(text)
    return "[\n" + ",\n".join(parts) + "\n]\n"
