"""Hooke: mass-spring simulation you can trust, from Python.

    >>> import hooke
    >>> sim = hooke.load("hanging-cloth", integrator="rk4")
    >>> sim.advance(0.5)
    >>> sim.positions.shape
    (625, 3)

`load` takes a built-in scene (`scenes()`), a `.toml` scene or a `.w` jello world, with the
`hooke` command's overrides. A `Simulation` steps with the command's own code, so its
trajectory is the command's, bit for bit. `sweep` runs a scene over a grid of parameters,
in local processes or as Ray tasks. `report(dir)` runs the checks of `hooke report` and
writes their page.
"""

from __future__ import annotations

import concurrent.futures
import itertools
import multiprocessing
import os
from typing import Any, Callable, Iterable, Mapping, Optional, Sequence

from . import metrics
from ._hooke import DivergenceError, HookeError, Simulation, load, report
from ._hooke import scenes as _scenes

__all__ = [
    "DivergenceError",
    "HookeError",
    "Simulation",
    "load",
    "metrics",
    "report",
    "scenes",
    "sweep",
    "LOAD_OPTIONS",
]

#: Grid keys that are `load` options; any other key is a scene-file key for `set`.
LOAD_OPTIONS = ("dt", "integrator", "steps", "duration", "every", "table", "threads")


def scenes() -> dict[str, str]:
    """The built-in scenes: name to one-line description."""
    return dict(_scenes())


def _points(grid: Mapping[str, Sequence[Any]]) -> list[dict[str, Any]]:
    keys = list(grid)
    for key in keys:
        values = grid[key]
        if isinstance(values, (str, bytes)) or not isinstance(values, Iterable):
            raise TypeError(f"grid[{key!r}]: expected a list of values, found {values!r}")
    return [dict(zip(keys, values)) for values in itertools.product(*(grid[k] for k in keys))]


def run_point(source: str, point: Mapping[str, Any], metric: Callable[[Simulation], Any],
              fixed: Optional[Mapping[str, Any]] = None) -> Any:
    """Loads `source` at one grid point, runs the scene to its end and returns
    `metric(simulation)`. What `sweep` runs for each point, in whatever process."""
    options = dict(fixed or {})
    scene_keys = {}
    for key, value in point.items():
        if key in LOAD_OPTIONS:
            options[key] = value
        else:
            scene_keys[key] = value
    sim = load(source, set=scene_keys, **options)
    sim.run()
    return metric(sim)


def sweep(source: str, grid: Mapping[str, Sequence[Any]], metric: Callable[[Simulation], Any],
          *, executor: Any = None, max_workers: Optional[int] = None,
          **fixed: Any) -> list[dict[str, Any]]:
    """Runs `source` at every point of `grid` and returns one row per point: the point's
    values and `"metric"`, `metric(simulation)` after the scene's whole run, in the grid's
    order (the last key varies fastest).

    `grid` maps keys to lists of values: `load` options (`dt`, `integrator`, `table`, …) or
    scene-file keys (`"body.springs.structural.ks"`, see `load`'s `set`). `fixed` are `load`
    options for every point.

    `executor` is where the points run: `None` a local process pool (`max_workers`
    processes, default one per core; `metric` must then be a function the workers can
    import, such as those of `hooke.metrics`, as processes receive it by pickling), `"ray"` one Ray task per point on the cluster
    `ray.init()` connects to (started here if it is not yet: a local one, or the cluster in
    `RAY_ADDRESS`), `"serial"` this process, or any `concurrent.futures.Executor`.
    The results do not depend on where the points ran: each point is the same computation.
    """
    if isinstance(executor, str) and executor not in ("serial", "ray"):
        raise HookeError(
            f"executor: expected None, 'serial', 'ray' or a concurrent.futures.Executor, "
            f"found {executor!r}")
    if executor is not None and not isinstance(executor, str) and not hasattr(executor, "submit"):
        raise HookeError(
            f"executor: expected None, 'serial', 'ray' or a concurrent.futures.Executor, "
            f"found {type(executor).__name__}")
    points = _points(grid)
    if executor == "serial":
        values = [run_point(source, p, metric, fixed) for p in points]
    elif executor == "ray":
        import ray

        if not ray.is_initialized():
            ray.init()
        task = ray.remote(run_point)
        values = ray.get([task.remote(source, p, metric, fixed) for p in points])
    elif executor is None:
        # Spawned, not forked: a forked child would inherit the solver's thread pool in a
        # state it cannot use.
        workers = max_workers or os.cpu_count() or 1
        context = multiprocessing.get_context("spawn")
        with concurrent.futures.ProcessPoolExecutor(workers, mp_context=context) as pool:
            values = list(pool.map(run_point, [source] * len(points), points,
                                   [metric] * len(points), [fixed] * len(points)))
    else:
        futures = [executor.submit(run_point, source, p, metric, fixed) for p in points]
        values = [f.result() for f in futures]
    return [{**p, "metric": v} for p, v in zip(points, values)]
