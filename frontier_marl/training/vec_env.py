"""The training env: ParallelEnv -> SuperSuit vector env -> SB3 ``VecMonitor``.

Pipeline (docs/thesis-mapping.md; the traps it avoids are below)::

    FrontierParallelEnv
      -> TimeLimitInfo                 (marks truncations for SB3's replay buffer)
      -> supersuit.pettingzoo_env_to_vec_env_v1     (one vector slot per robot)
      -> supersuit.concat_vec_envs_v1(..., base_class="stable_baselines3")   (n_envs copies)
      -> stable_baselines3 VecMonitor                (episode reward/length for the logger)

SuperSuit's SB3 wrapper folds ``terminated or truncated`` into ``dones`` and drops the
difference, so SB3 would treat a truncation (step limit, no progress, Reward 1's padding
action) as terminal and stop bootstrapping there. :class:`TimeLimitInfo` puts SB3's
``info["TimeLimit.truncated"] = True`` on truncated-but-not-terminated steps; the replay
buffer (``handle_timeout_termination=True``) then stores the step as a timeout and the TD
target keeps bootstrapping from the terminal observation.

Seeding: SuperSuit's ``ConcatVecEnv`` has no ``seed`` (so ``DQN(seed=...)`` and
``VecEnv.seed`` crash) and its copies are clones of one env. :func:`seed_vec_env` resets every
copy with its own seed spawned from one ``numpy.random.SeedSequence``; later unseeded resets
(SB3 resets the env when learning starts) continue each copy's own generator.
"""

from __future__ import annotations

import warnings
from typing import Any

import numpy as np
import supersuit as ss
from pettingzoo.utils.wrappers import BaseParallelWrapper
from stable_baselines3.common.vec_env import VecMonitor

from frontier_marl.envs.parallel import FrontierParallelEnv
from frontier_marl.sim.rewards import reason_name

TRUNCATED_KEY = "TimeLimit.truncated"
END_REASON_KEY = "episode_end_reason"


class TimeLimitInfo(BaseParallelWrapper):
    """Marks the last step of an episode in each agent's info, in keys that survive SuperSuit.

    * ``info["TimeLimit.truncated"] = True`` when the episode was truncated, not terminated;
    * ``info["episode_end_reason"]``: the name of the env's ``end_reason`` code (``threshold``,
      ``step_limit``, ...). SuperSuit's ``MarkovVectorEnv`` merges the next episode's reset
      info over the last step's info, so the env's own ``end_reason``/``step`` keys read
      ``0`` there.

    With ``mark_truncations=False`` the first key is left out, so SB3 treats truncations as
    terminal: SuperSuit's own behaviour, kept as an option for experiments (the thesis's
    SuperSuit pipeline most likely ran that way).

    The only work on an ordinary step is two ``any()`` over the agents' flags.
    """

    def __init__(self, env: Any, mark_truncations: bool = True) -> None:
        super().__init__(env)
        self.mark_truncations = mark_truncations

    def step(self, actions: dict[str, Any]) -> tuple[Any, Any, Any, Any, Any]:
        observations, rewards, terminations, truncations, infos = self.env.step(actions)
        if any(truncations.values()) or any(terminations.values()):
            for agent, info in infos.items():
                info[END_REASON_KEY] = reason_name(info.get("end_reason", 0))
                if self.mark_truncations and truncations[agent] and not terminations[agent]:
                    info[TRUNCATED_KEY] = True
        return observations, rewards, terminations, truncations, infos


def make_parallel_env(env_kwargs: dict[str, Any], mark_truncations: bool = True) -> TimeLimitInfo:
    """The wrapped ParallelEnv for ``env_kwargs`` (flat keywords of ``make_config``), with the
    minimal infos (training reads only the end reason, the mask and the scalars) and the flat
    observation layout (SB3 takes no nested ``Dict``; saved models record this layout)."""
    env = FrontierParallelEnv(info="minimal", obs_layout="flat", **env_kwargs)
    return TimeLimitInfo(env, mark_truncations)


def make_vec_env(
    env_kwargs: dict[str, Any],
    n_envs: int = 1,
    seed: int | None = None,
    bootstrap_truncations: bool = True,
) -> Any:
    """An SB3 ``VecMonitor`` over ``n_envs`` SuperSuit copies of the env (see module doc).

    With ``seed`` the copies are reset once with distinct seeds (:func:`seed_vec_env`). With
    ``bootstrap_truncations=False`` SB3 treats truncations as terminal (see
    :class:`TimeLimitInfo`).
    """
    if isinstance(n_envs, bool) or not isinstance(n_envs, int) or n_envs < 1:
        raise ValueError(f"n_envs must be an integer >= 1, got {n_envs!r}")
    markov = ss.pettingzoo_env_to_vec_env_v1(make_parallel_env(env_kwargs, bootstrap_truncations))
    vec = ss.concat_vec_envs_v1(markov, n_envs, num_cpus=0, base_class="stable_baselines3")
    with warnings.catch_warnings():
        # SuperSuit's ConcatVecEnv has no get_attr, so SB3 cannot read render_mode (harmless)
        warnings.filterwarnings("ignore", message="The `render_mode` attribute is not defined")
        monitored = VecMonitor(vec)
    if seed is not None:
        seed_vec_env(monitored, seed)
    return monitored


def copy_seeds(seed: int, n: int) -> list[int]:
    """``n`` independent 32-bit seeds derived from ``seed`` (one per vector copy)."""
    return [int(s.generate_state(1)[0]) for s in np.random.SeedSequence(seed).spawn(n)]


def concat_vec_env(vec: Any) -> Any:
    """The SuperSuit ``ConcatVecEnv`` inside an SB3 wrapper chain."""
    inner = vec
    while not hasattr(inner, "vec_envs"):
        if not hasattr(inner, "venv"):
            raise ValueError(f"no SuperSuit ConcatVecEnv inside {type(vec).__name__}")
        inner = inner.venv
    return inner


def parallel_envs(vec: Any) -> list[Any]:
    """The wrapped ParallelEnv of every copy, in vector order."""
    return [markov.par_env for markov in concat_vec_env(vec).vec_envs]


def seed_vec_env(vec: Any, seed: int) -> list[int]:
    """Reset every copy once with its own seed; returns the seeds used.

    The observations of this reset are discarded: SB3 resets the vector env again when
    learning starts, and that unseeded reset draws from each copy's seeded generator.
    """
    copies = concat_vec_env(vec).vec_envs
    seeds = copy_seeds(seed, len(copies))
    for markov, copy_seed in zip(copies, seeds, strict=True):
        markov.reset(seed=copy_seed)
    return seeds
