"""The ``[train]`` section of an experiment config: budget, seed, vector env, validation."""

from __future__ import annotations

import dataclasses
from collections.abc import Mapping
from dataclasses import dataclass, field

from frontier_marl.utils.checks import check_int

EVAL_MAP_MODES = ("as-trained", "static", "dynamic")
VEC_ENVS = ("batched", "supersuit")
POLICIES = ("auto", "slot-scorer")
ALGORITHMS = ("dqn", "ppo", "maskable-ppo", "cem", "cost-regression")


@dataclass(frozen=True)
class TrainSettings:
    """Budget and bookkeeping of one training run.

    Attributes:
        total_timesteps: environment steps (transitions) to train for.
        seed: seeds torch/numpy/random, the action space, and every vector copy (distinctly).
        n_envs: worlds stepped side by side (1 keeps ``train_freq`` in the thesis's units).
        vec_env: how they are stepped: ``batched`` (the default; all worlds in one call,
            :mod:`frontier_marl.envs.vector`) or ``supersuit`` (SuperSuit's concatenated
            copies of the ParallelEnv). Both give the same transitions.
        checkpoint_every: steps between checkpoints (model + replay buffer + metadata);
            0 disables periodic checkpoints (the final model and Ctrl-C still save).
        keep_checkpoints: newest checkpoints kept on disk (0 keeps all).
        log_interval: episodes between logger dumps (TensorBoard and metrics.jsonl).
        eval_episodes: episodes of the final deterministic evaluation (0 skips it).
        eval_seed: first seed of the evaluation episodes.
        eval_map_mode: map mode of the final evaluation: ``as-trained`` (the default),
            ``static`` (the thesis protocol, e.g. after training on dynamic maps) or ``dynamic``.
            Validation always uses the training env.
        torch_threads: ``torch.set_num_threads`` value (1 is fastest for this small MLP).
        device: torch device of the model.
        bootstrap_truncations: pass truncations to SB3 as truncations (``TimeLimit.truncated``,
            the TD target bootstraps there). False treats them as terminal, as SuperSuit does
            by itself (an experiment option; see docs/results.md).
        validate_every: steps between validations of the greedy policy on held-out episodes
            (0: none). The best-scoring policy is kept in ``RUN/best/`` and evaluated with
            the thesis protocol at the end, beside the final one (SB3's ``EvalCallback``
            practice).
        validation_episodes: episodes per validation.
        validation_seed: first reset seed of the validation episodes; the range must not
            overlap the evaluation's (``eval_seed`` .. ``eval_seed + eval_episodes - 1``).
        policy: ``auto`` (SB3's ``MlpPolicy`` or ``MultiInputPolicy``, by observation) or
            ``slot-scorer`` (the masked, permutation-equivariant slot scorer; needs
            ``features = "explorer"``): with DQN the Q-network of
            :mod:`frontier_marl.policies.networks.slot_dqn`, trained by ``MaskedDQN``; with PPO the
            actor-critic of :mod:`frontier_marl.policies.networks.slot_actor_critic`.
        families: benchmark map families to train on
            (:mod:`frontier_marl.evaluation.benchmark.families`), ``n_envs`` worlds of each,
            their worlds seeded inside each family's training seed range; ``[env]`` then
            sets the observation and reward (not the map). Empty: the ``[env]`` world.
        agents: team sizes to train on with ``families``: ``n_envs`` worlds of every family
            with every team size (one parameter-shared model acts for each robot). The first
            size is the one validated.
        skip_forced_steps: train on decisions only: steps where every robot of a world has a
            single valid slot (a commitment, one cluster left) are played by the batched env
            and their rewards summed into the decision's transition (a semi-MDP; ``gamma``
            then discounts per decision). ``total_timesteps`` counts decisions.
        algorithm: ``dqn`` (SB3 DQN with ``[dqn]``), ``ppo`` (SB3 PPO with ``[ppo]``),
            ``maskable-ppo`` (sb3-contrib's MaskablePPO with ``[ppo]``: the env's action masks
            applied to the policy; needs the batched vector env) or ``cem``: the
            cross-entropy method on a linear slot scorer with ``[cem]``
            (:mod:`frontier_marl.training.cem`; one robot, ``families`` and the explorer
            features needed; ``total_timesteps``, checkpoints and ``[dqn]`` unused), or
            ``cost-regression``: the map-aware scorer fitted to true-map costs-to-go with
            ``[regression]`` (:mod:`frontier_marl.training.cost_regression`; one robot and
            ``families``).
    """

    total_timesteps: int = 1_000_000
    seed: int = 0
    n_envs: int = 1
    vec_env: str = "batched"
    checkpoint_every: int = 100_000
    keep_checkpoints: int = 2
    log_interval: int = 10
    eval_episodes: int = 30
    eval_seed: int = 0
    eval_map_mode: str = "as-trained"
    torch_threads: int = 1
    device: str = "cpu"
    bootstrap_truncations: bool = True
    validate_every: int = 0
    validation_episodes: int = 30
    validation_seed: int = 1000
    policy: str = "auto"
    families: tuple[str, ...] = ()
    agents: tuple[int, ...] = (1,)
    skip_forced_steps: bool = False
    algorithm: str = "dqn"

    def __post_init__(self) -> None:
        self._check_integers()
        self._check_algorithm()
        self._check_worlds()
        self._check_flags()
        self._check_validation_seeds()
        if self.eval_map_mode not in EVAL_MAP_MODES:
            raise ValueError(
                f"train.eval_map_mode must be one of {', '.join(EVAL_MAP_MODES)}, "
                f"got {self.eval_map_mode!r}"
            )
        if not isinstance(self.device, str) or not self.device:
            raise ValueError(f"train.device must be a torch device name, got {self.device!r}")

    def _check_integers(self) -> None:
        for name, low in (
            ("total_timesteps", 1),
            ("seed", 0),
            ("n_envs", 1),
            ("checkpoint_every", 0),
            ("keep_checkpoints", 0),
            ("log_interval", 1),
            ("eval_episodes", 0),
            ("eval_seed", 0),
            ("torch_threads", 1),
            ("validate_every", 0),
            ("validation_episodes", 1),
            ("validation_seed", 0),
        ):
            value = getattr(self, name)
            if isinstance(value, bool) or not isinstance(value, int) or value < low:
                raise ValueError(f"train.{name} must be an integer >= {low}, got {value!r}")

    def _check_algorithm(self) -> None:
        """The algorithm, what it needs, and the policy."""
        if self.algorithm not in ALGORITHMS:
            raise ValueError(
                f"train.algorithm must be one of {list(ALGORITHMS)}, got {self.algorithm!r}"
            )
        if self.algorithm in ("cem", "cost-regression") and (
            not self.families or self.agents != (1,)
        ):
            raise ValueError(
                f"train.algorithm = {self.algorithm!r} needs train.families and one robot"
            )
        if self.algorithm == "maskable-ppo" and self.vec_env != "batched":
            raise ValueError("train.algorithm = 'maskable-ppo' needs train.vec_env = 'batched'")
        if self.policy not in POLICIES:
            raise ValueError(f"train.policy must be one of {list(POLICIES)}, got {self.policy!r}")

    def _check_worlds(self) -> None:
        """The families, the team sizes and the vector env."""
        if self.families:
            from frontier_marl.evaluation.benchmark.families import check_families

            check_families(self.families, "train.families")
            if self.vec_env != "batched":
                raise ValueError("train.families needs train.vec_env = 'batched'")
        if not self.agents or any(
            isinstance(k, bool) or not isinstance(k, int) or k < 1 for k in self.agents
        ):
            raise ValueError(f"train.agents must be team sizes >= 1, got {list(self.agents)!r}")
        if self.agents != (1,) and not self.families:
            raise ValueError("train.agents needs train.families (the team sizes of their worlds)")
        if self.vec_env not in VEC_ENVS:
            raise ValueError(f"train.vec_env must be one of {list(VEC_ENVS)}, got {self.vec_env!r}")

    def _check_flags(self) -> None:
        for name in ("bootstrap_truncations", "skip_forced_steps"):
            if not isinstance(getattr(self, name), bool):
                raise ValueError(f"train.{name} must be true or false, got {getattr(self, name)!r}")
        if self.skip_forced_steps and self.vec_env != "batched":
            raise ValueError("train.skip_forced_steps needs train.vec_env = 'batched'")

    def _check_validation_seeds(self) -> None:
        """Validation episodes must not overlap the evaluation's."""
        if not (self.validate_every and self.eval_episodes):
            return
        first = self.validation_seed
        validation = range(first, first + self.validation_episodes)
        evaluation = range(self.eval_seed, self.eval_seed + self.eval_episodes)
        if validation.start < evaluation.stop and evaluation.start < validation.stop:
            raise ValueError(
                f"train.validation_seed: validation episodes (seeds {validation.start}.."
                f"{validation.stop - 1}) overlap the evaluation episodes (seeds "
                f"{evaluation.start}..{evaluation.stop - 1}); choosing the best policy "
                "on the evaluation episodes would bias the evaluation"
            )


TRAIN_KEYS = {f.name for f in dataclasses.fields(TrainSettings)}


@dataclass(frozen=True)
class CEMSettings:
    """The ``[cem]`` section of an experiment config.

    Attributes:
        generations: CEM iterations.
        population: weight vectors tried per generation (the current mean among them).
        elite: the best of them that the next mean and spread are fitted to.
        episodes: training episodes per family per generation (fresh every generation).
        sigma: initial spread of every free weight.
        min_sigma: floor of the spread (keeps the search from collapsing early).
        init: initial mean weight by feature name (the others start at 0); must name ``path``,
            whose weight fixes the scale and is not searched.
    """

    generations: int = 20
    population: int = 12
    elite: int = 4
    episodes: int = 12
    sigma: float = 0.3
    min_sigma: float = 0.03
    init: Mapping[str, float] = field(default_factory=lambda: {"path": -1.0})

    def __post_init__(self) -> None:
        for name in ("generations", "population", "elite", "episodes"):
            value = getattr(self, name)
            if isinstance(value, bool) or not isinstance(value, int) or value < 1:
                raise ValueError(f"cem.{name} must be an integer >= 1, got {value!r}")
        if self.elite > self.population:
            raise ValueError(
                f"cem.elite ({self.elite}) must not exceed cem.population ({self.population})"
            )
        for name in ("sigma", "min_sigma"):
            value = getattr(self, name)
            if isinstance(value, bool) or not isinstance(value, int | float) or value <= 0:
                raise ValueError(f"cem.{name} must be a number > 0, got {value!r}")
        if not isinstance(self.init, Mapping) or not isinstance(self.init.get("path"), int | float):
            raise ValueError(
                f"cem.init must map feature names to weights with 'path', got {self.init!r}"
            )
        if self.init["path"] >= 0:
            raise ValueError(
                f"cem.init.path must be < 0 (shorter paths score higher), got {self.init['path']}"
            )


CEM_KEYS = {f.name for f in dataclasses.fields(CEMSettings)}


#: The rollout finishers of the cost-to-go labels (``regression.finisher``).
FINISHERS = ("nearest-path", "frontier-rule")
#: The step size over a fit of the map scorer: fixed, or a half cosine down to zero.
SCHEDULES = ("constant", "cosine")
#: The labelling settings a family may set for itself (``regression.per_family``).
PER_FAMILY_KEYS = ("label_episodes", "label_every", "completions")


@dataclass(frozen=True)
class RegressionSettings:
    """The ``[regression]`` section: DAgger rounds of true-map labels and fits of the map
    scorer (:mod:`frontier_marl.training.cost_regression`). The names differ from every other
    section's, so a bare ``key=value`` override finds its section.

    Attributes:
        rounds: label-and-fit rounds; round 0 follows frontier-rule, later ones the scorer
            (each decision the rule's with probability ``rule_share``).
        label_episodes: training episodes per family per round (fresh seeds every round).
        label_workers: processes that label episodes side by side.
        fit_epochs: passes over all labels so far, per round (the scorer starts afresh).
        fit_batch: decisions per gradient step.
        fit_rate: Adam's step size.
        scorer_width: the scorer's channels (its embedding is twice this).
        scorer_members: scorers of that width fitted side by side from their own initial
            weights, as one batched network, and averaged (1: a single scorer).
        rule_share: the rule's share of the decisions in rounds after the first.
        rule_weights: the weights of frontier-rule's margin tried after each fit
            (:class:`~frontier_marl.policies.map_explorer.MapExplorer`); the best on the
            validation episodes is kept with the scorer.
        finisher: the policy that finishes each labelled candidate's rollout on the true map
            (:data:`FINISHERS`): ``nearest-path`` (compiled, the cheapest) or
            ``frontier-rule`` (the cost-to-go a correction to the rule should predict).
        completions: 0 labels each candidate with one rollout on the true map; K >= 1 with the
            mean over K maps drawn from the family's generator that complete the robot's
            belief (:func:`~frontier_marl.policies.lookahead.completion_costs`; no true map,
            nearest-path finishing, K times the rollouts).
        label_every: label one real decision in this many (the first, then every
            ``label_every``-th; the others are played, not labelled): fewer, less correlated
            labels where an episode's decisions are many and their rollouts long.
        balance_families: how the families weigh in the fit: ``true`` draws each gradient
            step's decisions so that every family weighs the same, however many decisions it
            labelled; ``false`` sees every decision once per epoch; a number ``b`` in [0, 1]
            lies between (a family's total weight grows as its decisions to the power
            ``1 - b``: 0.5 gives the square root; 1 is ``true``, 0 ``false``).
        fit_schedule: the step size over a fit: ``constant`` (``fit_rate`` throughout) or
            ``cosine`` (from ``fit_rate`` down to zero along a half cosine, so the fit ends
            at rest rather than wherever its last noisy step left it).
        per_family: a family's own ``label_episodes``, ``label_every`` and ``completions``
            (:data:`PER_FAMILY_KEYS`), for example
            ``{"floorplan-96" = {label_episodes = 24, label_every = 8}}``: few, thinned labels
            where a family's episodes are long; other families take the section's values, and
            an entry for a family not in ``train.families`` is not used.
    """

    rounds: int = 3
    label_episodes: int = 40
    label_workers: int = 2
    fit_epochs: int = 10
    fit_batch: int = 64
    fit_rate: float = 1e-3
    scorer_width: int = 32
    scorer_members: int = 1
    rule_share: float = 0.5
    rule_weights: tuple[float, ...] = (0.0,)
    finisher: str = "nearest-path"
    completions: int = 0
    label_every: int = 1
    balance_families: bool | float = False
    fit_schedule: str = "constant"
    per_family: dict[str, dict[str, int]] = field(default_factory=dict)

    def label_episodes_of(self, family: str) -> int:
        """The training episodes labelled per round for ``family``."""
        return self.per_family.get(family, {}).get("label_episodes", self.label_episodes)

    def label_every_of(self, family: str) -> int:
        """One decision in this many is labelled in ``family``'s episodes."""
        return self.per_family.get(family, {}).get("label_every", self.label_every)

    def completions_of(self, family: str) -> int:
        """The completions each of ``family``'s labels averages over (0: the true map)."""
        return self.per_family.get(family, {}).get("completions", self.completions)

    @property
    def balance(self) -> float:
        """``balance_families`` as a number in [0, 1] (``true`` is 1, ``false`` 0)."""
        return float(self.balance_families)

    def __post_init__(self) -> None:
        self._check_per_family()
        balance = self.balance_families
        if not isinstance(balance, bool) and not (
            isinstance(balance, int | float) and 0 <= balance <= 1
        ):
            raise ValueError(
                "regression.balance_families must be true, false or a number in [0, 1], "
                f"got {balance!r}"
            )
        if self.fit_schedule not in SCHEDULES:
            raise ValueError(
                f"regression.fit_schedule must be one of {', '.join(SCHEDULES)}, "
                f"got {self.fit_schedule!r}"
            )
        if self.finisher not in FINISHERS:
            raise ValueError(
                f"regression.finisher must be one of {', '.join(FINISHERS)}, got {self.finisher!r}"
            )
        check_int("regression.completions", self.completions, 0)
        counts = [self.completions, *(v.get("completions", 0) for v in self.per_family.values())]
        if self.finisher != "nearest-path" and any(counts):
            raise ValueError(
                "regression.completions needs regression.finisher = 'nearest-path' "
                f"(the completions are finished by nearest-path), got {self.finisher!r}"
            )
        weights = self.rule_weights
        if (
            not isinstance(weights, tuple | list)
            or not weights
            or not all(
                isinstance(w, int | float) and not isinstance(w, bool) and w >= 0 for w in weights
            )
        ):
            raise ValueError(
                f"regression.rule_weights must be a list of numbers >= 0, got {weights!r}"
            )
        counts = ("rounds", "label_episodes", "label_every", "label_workers", "fit_epochs")
        for name in (*counts, "fit_batch", "scorer_width", "scorer_members"):
            check_int(f"regression.{name}", getattr(self, name), 1)
        rate = self.fit_rate
        if isinstance(rate, bool) or not isinstance(rate, int | float) or not rate > 0:
            raise ValueError(f"regression.fit_rate must be a number > 0, got {rate!r}")
        share = self.rule_share
        if isinstance(share, bool) or not isinstance(share, int | float) or not 0 <= share <= 1:
            raise ValueError(f"regression.rule_share must be a number in [0, 1], got {share!r}")

    def _check_per_family(self) -> None:
        if not isinstance(self.per_family, dict):
            raise ValueError(
                "regression.per_family must be a table of family name -> {label_episodes, "
                f"label_every, completions}}, got {self.per_family!r}"
            )
        from frontier_marl.evaluation.benchmark.families import check_families

        check_families(list(self.per_family), "regression.per_family")
        for name, values in self.per_family.items():
            where = f"regression.per_family.{name}"
            if not isinstance(values, dict):
                raise ValueError(f"{where} must be a table, got {values!r}")
            unknown = sorted(set(values) - set(PER_FAMILY_KEYS))
            if unknown:
                raise ValueError(
                    f"{where} has unknown keys {unknown}; allowed: {', '.join(PER_FAMILY_KEYS)}"
                )
            for key, value in values.items():
                check_int(f"{where}.{key}", value, 0 if key == "completions" else 1)


REGRESSION_KEYS = {f.name for f in dataclasses.fields(RegressionSettings)}
