"""Training learned frontier selectors (training/README.md): one module per algorithm and a
dispatcher.

* :mod:`~frontier_marl.training.experiment`: TOML experiment configs
  (``frontier_marl/assets/configs/*.toml``); :mod:`~frontier_marl.training.settings` their
  ``[train]`` and ``[cem]`` sections.
* :mod:`~frontier_marl.training.train`: the dispatcher (run folder, resume) over the algorithms.
* :mod:`~frontier_marl.training.dqn`, :mod:`~frontier_marl.training.ppo`: the SB3 algorithms'
  classes and settings; :mod:`~frontier_marl.training.sb3_session` runs a session of either
  (learn, checkpoints, Ctrl-C, evaluation).
* :mod:`~frontier_marl.training.cem`: the cross-entropy method on the linear slot scorer.
* :mod:`~frontier_marl.training.imitation`: DAgger labels from the lookahead oracle and the fit
  of a slot Q-network to them (:mod:`frontier_marl.experiments.explorer_studies.imitation_probe`).
* :mod:`~frontier_marl.training.batched_vec_env`: the batched vector env as an SB3 ``VecEnv``
  (the default), and ``MixedVecEnv`` for several map families;
  :mod:`~frontier_marl.training.vec_env`: ParallelEnv -> SuperSuit -> SB3 vector env.
* :mod:`~frontier_marl.training.validation`, :mod:`~frontier_marl.training.family_validation`:
  the best-validated policy (mean reward, or T99 on map families).
* :mod:`~frontier_marl.training.checkpoints`, :mod:`~frontier_marl.training.run_files`,
  :mod:`~frontier_marl.training.callbacks`, :mod:`~frontier_marl.training.plots`: what a run
  writes.
* :mod:`~frontier_marl.training.workers`: several runs side by side in worker processes.

The networks are in :mod:`frontier_marl.policies.networks` (loading a model needs them, and
training is above the policies); these modules need the ``train`` extra.
"""
