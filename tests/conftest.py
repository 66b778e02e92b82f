"""Shared pytest settings: Hypothesis profiles for the property tests.

``HYPOTHESIS_PROFILE=ci`` makes the property tests derandomized (same examples on every run);
the default ``dev`` profile draws fresh examples each run. Neither has a per-example deadline,
because timings on a shared 2-core machine are noisy.
"""

from __future__ import annotations

import os

from hypothesis import HealthCheck, settings

settings.register_profile(
    "dev",
    deadline=None,
    suppress_health_check=[HealthCheck.too_slow],
    print_blob=True,
)
settings.register_profile(
    "ci",
    deadline=None,
    suppress_health_check=[HealthCheck.too_slow],
    derandomize=True,
    print_blob=True,
)
settings.load_profile(os.environ.get("HYPOTHESIS_PROFILE", "dev"))
