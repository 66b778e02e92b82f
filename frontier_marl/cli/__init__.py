"""The ``frontier-marl`` command (:mod:`frontier_marl.cli.main`) and its subcommands."""
