"""Where the action mask sits in an observation: PettingZoo's classic layout, or the flat one.

The engine encodes an observation with the mask beside the other entries (``{"clusters",
"agent_position", "action_mask"}``, or the explorer's ``{"slots", "action_mask"}``): the
*flat* layout, which Stable-Baselines3 takes (its ``MultiInputPolicy`` refuses nested
``Dict`` spaces), and on which the SB3 training routes and the saved models rest.

The *classic* layout (the adapters' default) is the one of PettingZoo's classic
environments, where Tianshou, RLlib's PettingZoo examples, AgileRL and TorchRL look for a
mask: ``{"observation": ..., "action_mask": ...}``. ``observation`` is a single array: the
one other entry as it is (the clusters vector, the explorer's ``(n_slots, F)`` slots), or
the other entries concatenated in the ``Dict`` space's order (sorted keys, as
``gymnasium.spaces.flatten`` orders them: ``agent_position``, ``clusters``, ``teammates``).
No space is nested, so SB3 takes this layout too.

An observation without a mask has no mask to move: both layouts are then the same.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

import numpy as np
from gymnasium import spaces

OBS_LAYOUTS = ("classic", "flat")


def check_obs_layout(layout: str) -> str:
    if layout not in OBS_LAYOUTS:
        raise ValueError(f"obs_layout must be one of {list(OBS_LAYOUTS)}, got {layout!r}")
    return layout


class ObservationLayout:
    """Turns observations of ``flat_space`` (the engine's) into ``layout`` and back.

    ``space`` is the observation space in ``layout``; :meth:`wrap` takes one observation or
    a batch of them (arrays with leading axes), :meth:`unwrap` turns a classic one back.
    """

    def __init__(self, flat_space: spaces.Space[Any], layout: str = "classic") -> None:
        self.layout = check_obs_layout(layout)
        self.flat_space = flat_space
        self.masked = isinstance(flat_space, spaces.Dict) and "action_mask" in flat_space.spaces
        self.classic = self.masked and layout == "classic"
        self.space: spaces.Space[Any] = flat_space
        if not self.masked:
            return
        assert isinstance(flat_space, spaces.Dict)
        self.others = [key for key in flat_space.spaces if key != "action_mask"]
        parts = [flat_space[key] for key in self.others]
        if not all(isinstance(part, spaces.Box) for part in parts):
            raise ValueError("the classic layout needs Box entries beside the action mask")
        if len(parts) > 1 and any(len(part.shape) != 1 for part in parts):
            raise ValueError("the classic layout concatenates one-dimensional entries only")
        self.sizes = [int(np.prod(part.shape)) for part in parts]
        if self.classic:
            self.space = spaces.Dict(
                {"observation": _joined(parts), "action_mask": flat_space["action_mask"]}
            )

    def wrap(self, obs: Any) -> Any:
        """``obs`` (flat layout, one or a batch) in this layout."""
        if not self.classic:
            return obs
        if len(self.others) == 1:
            observation = obs[self.others[0]]
        else:
            observation = np.concatenate([obs[key] for key in self.others], axis=-1)
        return {"observation": observation, "action_mask": obs["action_mask"]}

    def unwrap(self, obs: Any) -> Any:
        """``obs`` in the flat layout: a classic one split back into its entries (views of
        it, the same values); any other observation as it is."""
        if not (self.masked and isinstance(obs, Mapping) and "observation" in obs):
            return obs
        observation = obs["observation"]
        if len(self.others) == 1:
            entries = {self.others[0]: observation}
        else:
            bounds = np.cumsum(self.sizes)[:-1]
            pieces = np.split(np.asarray(observation), bounds, axis=-1)
            entries = dict(zip(self.others, pieces, strict=True))
        return {**entries, "action_mask": obs["action_mask"]}


def _joined(parts: list[spaces.Box]) -> spaces.Box:
    """One Box: a single part as it is, several concatenated."""
    if len(parts) == 1:
        return parts[0]
    dtype = np.result_type(*(part.dtype for part in parts))
    low = np.concatenate([part.low.reshape(-1) for part in parts]).astype(dtype)
    high = np.concatenate([part.high.reshape(-1) for part in parts]).astype(dtype)
    return spaces.Box(low, high, dtype=dtype)  # type: ignore[arg-type]
