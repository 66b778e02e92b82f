"""The explorer studies' probes (docs/beyond-the-thesis.md and the experiment log): ablations,
weight sweeps and privileged probes of the linear slot scorer, and the resolution sweep. Each
module is the code of a script in benchmarks/ (``benchmarks/explorer_*.py``,
``imitation_probe.py``, ``resolution_sweep.py``), except :mod:`.validation_study`, the command
line several of them share."""
