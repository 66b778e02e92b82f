"""The Ray Tune glue of :mod:`frontier_marl.experiments.campaign`: the optional import, one grid
search over trial indices, a progress callback, and the signal handlers Tune leaves behind.

Ray is an optional extra (``pip install "frontier-marl[ray]"``): Ray Tune only, no RLlib.
"""

from __future__ import annotations

import json
import signal
import sys
import threading
import time
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any

from frontier_marl.utils.progress import progress_bar

RAY_HINT = 'Ray Tune is not installed: pip install "frontier-marl[ray]"'


class RayNotInstalledError(ImportError):
    """``ray[tune]`` is missing."""


def require_ray() -> Any:
    """``ray.tune``, or :class:`RayNotInstalledError` with the install hint."""
    try:
        import ray
        from ray import tune
    except ImportError as exc:
        raise RayNotInstalledError(RAY_HINT) from exc
    if not (hasattr(tune, "report") and hasattr(tune, "RunConfig")):  # added in Ray 2.41
        raise RayNotInstalledError(
            f"Ray {getattr(ray, '__version__', '?')} is too old (ray.tune.report and "
            'ray.tune.RunConfig need Ray >= 2.41): pip install -U "frontier-marl[ray]"'
        )
    return tune


def flat_scalars(row: dict[str, Any]) -> dict[str, Any]:
    """Tune's loggers want flat scalars: lists become JSON text, ``None`` NaN."""
    out: dict[str, Any] = {}
    for key, value in row.items():
        if isinstance(value, list | tuple):
            out[key] = json.dumps(list(value))
        elif value is None:
            out[key] = float("nan")
        else:
            out[key] = value
    return out


def fit_trials(
    tune: Any,
    trainable: Callable[..., None],
    names: Sequence[str],
    out: Path,
    cpus_per_trial: float,
    max_concurrent: int | None,
    progress: bool,
    **parameters: Any,
) -> Any:
    """Run ``trainable(config, **parameters)`` once per trial (``config["trial"]`` is its
    index into ``names``) on Ray Tune, and return Tune's result grid."""
    resources = tune.with_resources(
        tune.with_parameters(trainable, **parameters), {"cpu": cpus_per_trial}
    )
    tuner = tune.Tuner(
        resources,
        param_space={"trial": tune.grid_search(list(range(len(names))))},
        tune_config=tune.TuneConfig(
            max_concurrent_trials=max_concurrent,
            trial_name_creator=lambda t: names[t.config["trial"]],
            trial_dirname_creator=lambda t: names[t.config["trial"]],
        ),
        run_config=tune.RunConfig(
            name=f"campaign_{time.strftime('%Y%m%d-%H%M%S')}",
            storage_path=str(out / "ray_results"),
            verbose=0,
            callbacks=[_progress_callback(tune, names, progress)],
        ),
    )
    return restoring_signal_handlers(tuner.fit)


def restoring_signal_handlers(run: Any) -> Any:
    """``run()``, then the SIGINT/SIGUSR1 handlers it found: Ray Tune's ``fit`` installs its
    own and leaves them in place when the run ends normally, after which Ctrl-C no longer
    raises ``KeyboardInterrupt`` anywhere in this process."""
    names = [n for n in ("SIGINT", "SIGUSR1") if hasattr(signal, n)]
    saved = {n: signal.getsignal(getattr(signal, n)) for n in names}
    try:
        return run()
    finally:
        if threading.current_thread() is threading.main_thread():
            for name, handler in saved.items():
                if handler is not None:
                    signal.signal(getattr(signal, name), handler)


def _trial_text(r: dict[str, Any]) -> str:
    """A finished trial's line: its evaluation, or that it reported none."""
    if "mean_reward" not in r:
        return "finished without a result"
    flag = ", DEGENERATE" if r.get("degenerate") else ""
    return (
        f"{r['mean_reward']:.2f} ± {r['std_reward']:.2f}, "
        f"{int(r['terminations'])}/{int(r['episodes'])} terminations{flag} "
        f"({r.get('trial_wall_time_s', 0):.0f} s)"
    )


def _progress_callback(tune: Any, names: Sequence[str], progress: bool) -> Any:
    """A Tune callback (run in the driver): a progress bar over finished trials and one line per
    finished trial. Tune pickles its callbacks, so the bar is made in ``setup``."""

    class _Progress(tune.Callback):
        def __init__(self) -> None:
            self.names = list(names)
            self.progress = progress
            self.bar: Any = None

        def __getstate__(self) -> dict[str, Any]:
            return {**self.__dict__, "bar": None}

        def setup(self, **info: Any) -> None:
            self.bar = progress_bar(
                len(self.names), unit="trial", disable=not self.progress, desc="campaign"
            )

        def _done(self, trial: Any, text: str) -> None:
            if self.bar is None:
                self.setup()
            line = f"{self.names[trial.config['trial']]}: {text}"
            if self.progress:
                self.bar.write(line, file=sys.stderr)
            else:
                print(line, flush=True)
            self.bar.update(1)

        def on_trial_complete(self, iteration: int, trials: list, trial: Any, **info: Any) -> None:
            self._done(trial, _trial_text(trial.last_result or {}))

        def on_trial_error(self, iteration: int, trials: list, trial: Any, **info: Any) -> None:
            self._done(trial, "FAILED")

        def on_experiment_end(self, trials: list, **info: Any) -> None:
            if self.bar is not None:
                self.bar.close()
                self.bar = None

    return _Progress()
