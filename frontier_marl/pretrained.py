"""Trained models shipped with the package, usable by name wherever a model path is accepted::

    frontier-marl evaluate thesis-config01

Each model lives in ``frontier_marl/assets/models/<name>/`` as ``model.zip`` (SB3 DQN, or
sb3-contrib MaskablePPO for ``explorer-ppo``) with its
``model.json`` metadata (env config, observation layout, training run). How each was trained is
in docs/results.md (``thesis-config01``) and docs/beyond-the-thesis.md (``explorer``,
``explorer-dqn``, ``explorer-ppo``, ``team-explorer``).
"""

from __future__ import annotations

from importlib import resources
from pathlib import Path

#: name -> one-line description
PRETRAINED: dict[str, str] = {
    "explorer": "the learned frontier selector (docs/beyond-the-thesis.md): a linear, "
    "permutation-equivariant slot scorer on size-independent slot features with the tour, "
    "unknown_near and fill features, trained by the cross-entropy method on T99 on five "
    "benchmark map families by `frontier-marl train explorer` (seed 0); the best-validated "
    "weights (generation 0 of 12)",
    "explorer-dqn": "the first learned frontier selector (docs/beyond-the-thesis.md): DQN on a "
    "masked, permutation-equivariant slot scorer on size-independent slot features, trained on "
    "the four benchmark map families by `frontier-marl train explorer-dqn` (seed 0); the "
    "best-validated policy (step 200,000); at parity with nearest-path",
    "explorer-ppo": "a policy-gradient frontier selector (docs/beyond-the-thesis.md): "
    "MaskablePPO on the masked, permutation-equivariant slot scorer (MLP actor, pooled "
    "critic) with the explorer's features and a pure travel cost, trained on five benchmark "
    "map families by `frontier-marl train explorer-ppo` (seed 0); the best-validated policy "
    "(step 250,000 of 600,000)",
    "team-explorer": "the learned team selector (docs/beyond-the-thesis.md): the explorer's "
    "slot scorer with three teammate features per slot, one parameter-shared model for teams "
    "of 2 to 8, trained on random-30 and rooms-64 by `frontier-marl train team-explorer` "
    "(seed 0); the best-validated policy (step 1,600,032)",
    "thesis-config01": "configuration 1 (absolute centroids + agent position, unsorted, "
    "Reward 2, normalized): the best-validated policy of seed 2 (step 340,000) of a default "
    "frontier-marl reproduce run, the seed whose protocol score is the median of the three",
}


def pretrained_names() -> list[str]:
    return list(PRETRAINED)


def pretrained_model_dir(name: str) -> Path:
    """The folder of shipped model ``name``; ``ValueError`` if unknown or missing."""
    if name not in PRETRAINED:
        raise ValueError(f"pretrained model must be one of {pretrained_names()}, got {name!r}")
    folder = resources.files("frontier_marl").joinpath("assets", "models", name)
    if not isinstance(folder, Path) or not (folder / "model.zip").is_file():
        raise ValueError(f"pretrained model {name!r} is missing from the installed package")
    return folder
