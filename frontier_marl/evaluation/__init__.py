"""The evaluation layer: the thesis's protocol, exploration metrics, plots and the benchmark.

* :mod:`~frontier_marl.evaluation.protocol`: :func:`evaluate`; its records in
  :mod:`~frontier_marl.evaluation.records`;
* :mod:`~frontier_marl.evaluation.metrics`: coverage curves, cells to a coverage level, overlap;
* :mod:`~frontier_marl.evaluation.model_evaluation`: the thesis protocol on a saved model;
  :mod:`~frontier_marl.evaluation.model_refs`: saved models by path, loaded once per process;
* :mod:`~frontier_marl.evaluation.plots`: result figures;
* :mod:`~frontier_marl.evaluation.benchmark`: the exploration benchmark (map families,
  T99/T90, the paired difference to the best heuristic; docs/benchmark.md).

The policies it evaluates are in :mod:`frontier_marl.policies`.
"""

from frontier_marl.evaluation.protocol import evaluate, run_episode
from frontier_marl.evaluation.records import (
    DEFAULT_LEVELS,
    EpisodeRecord,
    EvaluationResult,
    level_key,
)

__all__ = [
    "DEFAULT_LEVELS",
    "EpisodeRecord",
    "EvaluationResult",
    "evaluate",
    "level_key",
    "run_episode",
]
