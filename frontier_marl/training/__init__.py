"""DQN training with Stable-Baselines3 (training/README.md).

* :mod:`~frontier_marl.training.experiment`: TOML experiment configs (``assets/configs/*.toml``);
  :mod:`~frontier_marl.training.settings` their ``[train]`` section.
* :mod:`~frontier_marl.training.batched_vec_env`: the batched vector env as an SB3 ``VecEnv``
  (the default), and ``MixedVecEnv`` for several map families.
* :mod:`~frontier_marl.training.vec_env`: ParallelEnv -> SuperSuit -> SB3 vector env.
* :mod:`~frontier_marl.policies.networks.slot_dqn`: the masked, permutation-equivariant slot
  Q-network and ``MaskedDQN`` (the ``explorer``).
* :mod:`~frontier_marl.training.family_validation`: T99 validation on map families (a
  team: the makespan against utility-discount).
* :mod:`~frontier_marl.training.imitation`: DAgger labels from the lookahead oracle and the
  fit of a slot Q-network to them (``benchmarks/imitation_probe.py``).
* :mod:`~frontier_marl.training.train`: the training loop, checkpoints, resume, Ctrl-C.
* :mod:`~frontier_marl.evaluation.model_evaluation`: thesis evaluation of a saved model.
* :mod:`~frontier_marl.policies.metadata`: what is saved beside a model, and the mismatch check.

Submodules import torch / SB3 lazily where they can; import them directly.
"""
