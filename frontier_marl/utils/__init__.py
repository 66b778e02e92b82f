"""Small helpers every layer uses: value checks, the JSON writer, the progress bar,
the parsing of ``--set KEY=VALUE`` options, and :func:`~frontier_marl.utils.parallel.map_tasks`
(independent tasks in worker processes or on a Ray cluster)."""
