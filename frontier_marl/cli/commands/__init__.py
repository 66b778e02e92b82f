"""Subcommands of the ``frontier-marl`` CLI (see :mod:`frontier_marl.cli.main`)."""
