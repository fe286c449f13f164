"""Many simulated walks on all cores: :func:`sweep` runs scenarios in a process pool.

Each walk is the walk of ``zmpwalk simulate`` (:func:`zmpwalk.walk.run_walk`): the pattern at 1 kHz, the
joint angles, the MuJoCo walk (with the stabilizer where asked), standing
:data:`~zmpwalk.sim.verdict.SETTLE` before and :data:`~zmpwalk.sim.verdict.HOLD` after, and the verdict of
:func:`zmpwalk.sim.verdict.walk_verdict`. Workers load the robot
themselves (by name or model path), so nothing heavier than a few strings crosses a process
boundary.

Past one machine, the same jobs run on a Dask cluster (``scheduler``: a scheduler's address, or
``"local"`` for a local cluster of ``workers`` processes; ``pip install "zmpwalk[distributed]"``). Dask
schedules and moves the jobs; every worker needs zmpwalk and the robot's files at the same paths.
"""

from __future__ import annotations

import math
import os
import time
from collections.abc import Callable, Sequence
from concurrent.futures import ProcessPoolExecutor, as_completed
from dataclasses import dataclass
from typing import Any, TypeVar

from zmpwalk.errors import InvalidParameterError, ZmpwalkError
from zmpwalk.robots import loaded_robot

T = TypeVar("T")

DASK_CONNECT_TIMEOUT = 10.0  # [s] to reach a Dask scheduler


@dataclass(frozen=True)
class SweepResult:
    """One walk of a sweep.

    Attributes:
        scenario: The scenario's name.
        robot: The robot's name.
        passed: Every criterion of the verdict passed.
        failed: Names of the criteria that failed.
        fell: The robot fell.
        distance: Distance walked [m].
        cop_error_rms: RMS of the measured CoP against the reference ZMP [m].
        simulated: Simulated time [s].
        seconds: Wall-clock time of the walk in its worker [s].
        error: Why the walk could not be planned (then nothing was simulated), else empty.
    """

    scenario: str
    robot: str
    passed: bool
    failed: tuple[str, ...]
    fell: bool
    distance: float  # [m]
    cop_error_rms: float  # [m]
    simulated: float  # [s]
    seconds: float  # [s]
    error: str = ""


def walk_scenario(robot: str, scenario: str, balance: bool = True, generator: str | None = None,
                  schedule: str | None = None, pelvis: str = "cubic") -> SweepResult:
    """Simulate one built-in scenario on a robot (name, robot file or model path) and judge it.

    Args:
        robot: What ``--robot`` takes.
        scenario: A built-in scenario name.
        balance: Close the loop with the stabilizer (the default, for every robot); False: open loop.
        generator: The pattern generator's name (:data:`zmpwalk.patterns.GENERATORS`); None: the robot's own.
        schedule: A schedule file (e.g. from ``zmpwalk tune``) instead of Tables 2-3.
        pelvis: ``"cubic"`` or ``"quintic"`` (the polynomial generator's pelvis curves).
    """
    from zmpwalk.ready_fit import fit_ready_posture_of
    from zmpwalk.scenarios import load_scenario_with_labels
    from zmpwalk.walk import WalkSpec, planned_walk, run_walk

    start = time.perf_counter()
    model = loaded_robot(robot)
    commands, labels = load_scenario_with_labels(scenario)
    tables = None
    if schedule is not None:
        from pathlib import Path

        from zmpwalk.schedule import Schedule

        tables = Schedule.from_file(Path(schedule))
    try:
        fitted = fit_ready_posture_of(robot, WalkSpec(model, commands, labels, generator=generator, schedule=tables,
                                                      pelvis=pelvis, balance=balance))
        planned = fitted.planned or planned_walk(fitted.spec)  # a box model's or a posture a file sets: not planned
    except ZmpwalkError as error:  # this walk is not possible with this generator: a result, not a crash
        return SweepResult(scenario=scenario, robot=model.name, passed=False, failed=("planned",), fell=False,
                           distance=math.nan, cop_error_rms=math.nan, simulated=0.0,
                           seconds=time.perf_counter() - start, error=str(error))
    with fitted.walking(say=False):  # an error of the walk says which posture it walked from
        walk = run_walk(fitted.spec, planned=planned)
    result, verdict = walk.result, walk.verdict
    rms, _ = result.cop_error_stats()
    return SweepResult(
        scenario=scenario, robot=model.name, passed=verdict.passed,
        failed=tuple(c.name for c in verdict.criteria if not c.passed), fell=result.fell,
        distance=result.distance, cop_error_rms=rms, simulated=float(result.time[-1]),
        seconds=time.perf_counter() - start,
    )


def in_pool(function: Callable[..., T], arguments: dict[int, tuple[Any, ...]], workers: int,
            record: Callable[[int, T], None], scheduler: str | None = None) -> None:
    """``function(*arguments[i])`` for every ``i``, ``workers`` at a time in worker processes (in this process
    when one worker or one call), each result handed to ``record(i, result)`` as it comes.

    Args:
        scheduler: Run the calls on a Dask cluster instead: a scheduler's address (``tcp://host:8786``), or
            ``"local"`` for a local cluster of ``workers`` processes.

    Raises:
        InvalidParameterError: ``scheduler`` given without Dask installed.
    """
    if scheduler is not None:
        _on_dask(function, arguments, workers, record, scheduler)
        return
    if workers == 1 or len(arguments) <= 1:
        for index, args in arguments.items():
            record(index, function(*args))
        return
    with ProcessPoolExecutor(max_workers=min(workers, len(arguments))) as pool:
        futures = {pool.submit(function, *args): index for index, args in arguments.items()}
        for future in as_completed(futures):
            record(futures[future], future.result())


def _on_dask(function: Callable[..., T], arguments: dict[int, tuple[Any, ...]], workers: int,
             record: Callable[[int, T], None], scheduler: str) -> None:
    try:
        from dask.distributed import Client, LocalCluster
        from dask.distributed import as_completed as dask_completed
    except ImportError:
        raise InvalidParameterError("scheduler", scheduler, 'a Dask scheduler with Dask installed: '
                                    'pip install "zmpwalk[distributed]"') from None
    cluster = (LocalCluster(n_workers=workers, threads_per_worker=1, processes=True)  # type: ignore[no-untyped-call]
               if scheduler == "local" else None)
    try:
        try:
            client = Client(cluster if cluster is not None else scheduler,  # type: ignore[no-untyped-call]
                            timeout=DASK_CONNECT_TIMEOUT)
        except (OSError, ValueError, TypeError) as error:
            raise InvalidParameterError("scheduler", scheduler, f"a Dask scheduler reachable within "
                                        f"{DASK_CONNECT_TIMEOUT:g} s, or 'local' ({error})") from None
        with client:
            futures = {client.submit(function, *args, pure=False): index for index, args in arguments.items()}
            for future in dask_completed(list(futures)):  # type: ignore[no-untyped-call]
                record(futures[future], future.result())
    finally:
        if cluster is not None:
            cluster.close()


def sweep(robot: str, scenarios: Sequence[str], balance: bool = True, workers: int | None = None,
          progress: Callable[[int, int], None] | None = None, generator: str | None = None,
          schedule: str | None = None, pelvis: str = "cubic", scheduler: str | None = None) -> list[SweepResult]:
    """Simulate every scenario on ``robot``, ``workers`` walks at a time (default: one per core), or on a
    Dask cluster (``scheduler``, see the module docstring).

    Returns:
        The results in the order of ``scenarios``.

    Raises:
        InvalidParameterError: ``workers`` < 1.
        ZmpwalkError: A scenario or the robot is unknown or infeasible (raised before any walk when
            the robot does not load).
    """
    if workers is None:
        workers = os.cpu_count() or 1
    if isinstance(workers, bool) or not isinstance(workers, int) or workers < 1:
        raise InvalidParameterError("workers", workers, "an integer >= 1")
    loaded_robot(robot)  # a bad robot is one error here, not one per worker
    results: dict[int, SweepResult] = {}

    def record(index: int, result: SweepResult) -> None:
        results[index] = result
        if progress:
            progress(len(results), len(scenarios))

    in_pool(walk_scenario, {index: (robot, name, balance, generator, schedule, pelvis)
                            for index, name in enumerate(scenarios)}, workers, record, scheduler)
    return [results[index] for index in range(len(scenarios))]
