"""The exploration-efficiency benchmark: map families and their seed splits, the runs, the
statistics."""
