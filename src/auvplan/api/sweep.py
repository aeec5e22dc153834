"""A parameter sweep of a mission into one folder: what ``auvplan sweep`` does.

:func:`sweep_to_folder` validates every run first (:func:`auvplan.sweep.build_runs`: the
``--vary`` values and seeds over a mission file or the seeded scenario family), runs them on
dask (:func:`auvplan.sweep.run_sweep`: each into ``DIR/runs/<run-id>/``, runs finished by an
earlier sweep skipped, failed runs kept as rows), and writes ``sweep.csv``/``sweep.json``
(:func:`auvplan.sweep.write_sweep_files`) and, when the runs allow an energy/navigation
trade-off (:func:`auvplan.sweep.pareto_view`), ``pareto.png`` and the Pareto table.

The seeds multiply the runs only where they change something: with ``"scenarios"`` each seed
is a mission, and with a navigation evaluation each seed is a row's Monte-Carlo seed (the
runs of one mission then share its plan, :mod:`auvplan.sweep.runner`). A mission file's plan
does not depend on the seed, so without an evaluation its missions are planned once each, one
row each without a seed; a log line says so.
"""

from __future__ import annotations

import logging
import time
from collections import Counter
from collections.abc import Callable, Iterator, Sequence
from contextlib import AbstractContextManager, contextmanager, nullcontext
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any, Final

from auvplan.io.output import staged_output_file
from auvplan.navigation.montecarlo import available_cpus
from auvplan.sweep import (
    MissionBase,
    NavigationOptions,
    NavigationRequest,
    ParetoView,
    RunOptions,
    RunRecord,
    SweepProgress,
    SweepRun,
    add_run_columns,
    build_runs,
    json_rows,
    mission_file_base,
    navigation_columns,
    pareto_view,
    parse_seeds,
    require_dask,
    run_sweep,
    scenario_bases,
    sweep_frame,
    trade_off,
    write_pareto_table,
    write_sweep_files,
)
from auvplan.sweep.table import relative_to

if TYPE_CHECKING:
    import pandas as pd

    from auvplan.scenarios import Scenario

#: ``mission`` naming the public scenario family instead of a file.
SCENARIOS: Final = "scenarios"
#: Resolution of ``pareto.png`` [dots per inch].
PARETO_DPI: Final = 150

logger = logging.getLogger(__name__)

#: Opens the progress display of ``n`` runs and gives its callback (None: no progress).
SweepDisplay = Callable[[int], AbstractContextManager[Callable[[SweepProgress], None] | None]]


@dataclass(frozen=True)
class SweepOutcome:
    """What :func:`sweep_to_folder` ran and wrote."""

    records: tuple[RunRecord, ...]
    """One record per run, in the order of the grid."""
    counts: dict[str, Any]
    """Runs in all, ``ran``, ``skipped`` (finished before), ``failed``, ``planned`` (runs that
    ran the planner now; the others were finished before or share the plan of a run of the
    same mission), and runs per status."""
    view: ParetoView | None
    """The energy/navigation trade-off of the runs, if they have one."""
    trade_off: dict[str, dict[str, Any] | None] | None
    """The best points of :attr:`view` (:func:`auvplan.sweep.trade_off`)."""
    written: tuple[Path, ...]
    """``sweep.csv``, ``sweep.json`` and, with a trade-off, ``pareto.png`` and its table."""
    wall_s: float
    """Wall time of the runs [s]."""

    @property
    def all_failed(self) -> bool:
        """Whether there were runs and every one of them failed."""
        return bool(self.counts["runs"]) and self.counts["failed"] == self.counts["runs"]


def sweep_to_folder(
    mission: str,
    output: Path,
    *,
    vary: Sequence[str] = (),
    seeds: str | None = None,
    stage: str = "full",
    client: Any = None,
    scheduler: str | None = None,
    workers: int | None = None,
    figures: bool = False,
    navigation: NavigationRequest | None = None,
    data_dir: Path | None = None,
    progress: SweepDisplay | None = None,
) -> SweepOutcome:
    """Plan ``mission`` over the grid of ``vary`` x ``seeds`` into ``output`` (module notes).

    Parameters
    ----------
    mission : str
        A mission file, or ``"scenarios"`` for the seeded scenario family (one mission per
        seed, written to ``output/scenarios/``).
    output : Path
        The sweep's folder.
    vary : sequence of str
        ``KEY=V1,V2,...`` items (:func:`auvplan.sweep.parse_vary`); the grid is their product.
    seeds : str, optional
        Seeds such as ``"0..49"`` or ``"0,3,7"`` (:func:`auvplan.sweep.parse_seeds`): the
        scenarios' seeds, or the Monte-Carlo seeds of ``navigation`` (module notes).
    stage : str
        Last stage of each run: ``"preplan"``, ``"deconflict"`` or ``"full"``.
    client : distributed.Client, optional
        A client of a cluster the caller made (left open); or
    scheduler : str, optional
        the address of a running dask scheduler; or
    workers : int, optional
        the worker processes of a local cluster (default: the number of cores).
    figures : bool
        Also write each run's figures.
    navigation : NavigationRequest, optional
        Fly each plan through the TAN simulator (``navigation.json`` in each run folder).
    data_dir : Path, optional
        With ``"scenarios"``: the folder of the real bathymetry grids.
    progress : callable, optional
        Called with the number of runs; the context manager it returns gives the progress
        callback (or None).

    Returns
    -------
    SweepOutcome

    Raises
    ------
    InputError, DataFormatError
        For a run that is not a valid mission, bad seeds or values, a navigation value out of
        range, more than one of ``client``, ``scheduler`` and ``workers``, or dask missing;
        nothing is run.

    Examples
    --------
    >>> from distributed import Client, LocalCluster  # doctest: +SKIP
    >>> with LocalCluster(n_workers=2) as cluster, Client(cluster) as client:  # doctest: +SKIP
    ...     outcome = sweep_to_folder("mission.toml", Path("sweep"), client=client,
    ...                               vary=["weights.terrain=0,1"])
    """
    local = client is None and scheduler is None
    options = None if navigation is None else _navigation_options(navigation, local, workers)
    require_dask()
    seed_list: tuple[int | None, ...] = (None,) if seeds is None else parse_seeds(seeds)
    base_of, scenario_files = _bases(mission, output, seed_list, data_dir)
    seeds_plan = mission == SCENARIOS or seeds is None
    grid_seeds = seed_list if seeds_plan or options is not None else (None,)
    axes, runs = build_runs(vary, grid_seeds, base_of, stage=stage)
    if not seeds_plan:
        _log_shared_plans(seeds or "", runs, evaluated=options is not None)

    def write_scenarios() -> None:  # only once every run is valid and the cluster answers
        for base, scenario in scenario_files:
            scenario.write(base.base_dir)

    write_figures = None
    if figures:
        from auvplan.viz.report import save_mission_figures

        write_figures = save_mission_figures
    run_options = RunOptions(
        stage=stage,
        write_figures=write_figures,
        quiet_logs=local,
        navigation=options,
    )
    started = time.perf_counter()
    with nullcontext() if progress is None else progress(len(runs)) as callback:
        records = run_sweep(
            runs, output, options=run_options, client=client, scheduler=scheduler,
            n_workers=workers, progress=callback, on_ready=write_scenarios,
        )  # fmt: skip
    wall_s = time.perf_counter() - started
    keys = [axis.key for axis in axes]
    spec = {
        "mission": mission if mission == SCENARIOS else relative_to(mission, output),
        "vary": {axis.key: list(axis.values) for axis in axes},
        "seeds": None if seeds is None else list(seed_list),
        "stage": stage,
        "scheduler": scheduler if client is None else client.scheduler.address,
        "workers": workers,
        "figures": figures,
        "navigation": None if options is None else options.settings_document,
    }
    frame = add_run_columns(sweep_frame(records, keys), navigation_columns)
    view = pareto_view(frame, keys, seeds_are_missions=mission == SCENARIOS)
    counts = _counts(records)
    best = None if view is None else trade_off(view)
    written = _write_tables(frame, output.resolve(), spec, counts, wall_s, view, best)
    return SweepOutcome(tuple(records), counts, view, best, tuple(written), wall_s)


def _navigation_options(
    request: NavigationRequest, local: bool, workers: int | None
) -> NavigationOptions:
    """The evaluation of every run: ``local`` workers share the cores, others get 1 each."""
    threads = 1
    if local:
        cpus = available_cpus()
        threads = max(1, cpus // (workers or cpus))
    return request.options(None, seed=0, threads=threads)


def _bases(
    mission: str, output: Path, seeds: tuple[int | None, ...], data_dir: Path | None
) -> tuple[Callable[[int | None], MissionBase], list[tuple[MissionBase, Scenario]]]:
    """The base mission of each seed and the scenario files to write before the runs."""
    if mission != SCENARIOS:
        base = mission_file_base(Path(mission))
        return (lambda _seed: base), []
    bases = scenario_bases([s for s in seeds if s is not None], output, data_dir=data_dir)
    return (lambda seed: bases[seed][0]), list(bases.values())


def _log_shared_plans(seeds: str, runs: Sequence[SweepRun], *, evaluated: bool) -> None:
    """Say that a mission file's seeds do not change its plans, and what they do instead."""
    n_plans = len({run.digest for run in runs})
    if evaluated:
        logger.info(
            "--seeds %s do not change a mission file's plan: %d plans, each evaluated with "
            "every seed (%d rows)", seeds, n_plans, len(runs),
        )  # fmt: skip
    else:
        logger.info(
            "--seeds %s do not change a mission file's plan: each of its %d missions is "
            "planned once, one row without a seed (seeds count with --evaluate, the "
            "Monte-Carlo seed, or with 'scenarios')", seeds, n_plans,
        )  # fmt: skip


def _counts(records: Sequence[RunRecord]) -> dict[str, Any]:
    statuses = Counter(record.status for record in records).most_common()
    return {
        "runs": len(records),
        "ran": sum(not record.skipped for record in records),
        "skipped": sum(record.skipped for record in records),
        "failed": sum(record.failed for record in records),
        "planned": sum(not record.skipped and record.plan_of is None for record in records),
        "status": dict(statuses),
    }


def _write_tables(
    frame: pd.DataFrame,
    output: Path,
    spec: dict[str, Any],
    counts: dict[str, Any],
    wall_s: float,
    view: ParetoView | None,
    best: dict[str, dict[str, Any] | None] | None,
) -> list[Path]:
    """Write ``sweep.csv``/``sweep.json``, and ``pareto.png`` and its table with a view."""
    written = write_sweep_files(
        frame, output, spec=spec, counts=counts, wall_time_s=wall_s,
        pareto=None if view is None else json_rows(view.points), trade_off=best,
    )  # fmt: skip
    if view is not None:
        from auvplan.viz.sweep import plot_pareto

        with staged_output_file(output / "pareto.png") as staging:
            plot_pareto(view).savefig(staging, dpi=PARETO_DPI)
        written.append(output / "pareto.png")
        written += write_pareto_table(
            view.points, output, label_key=view.label_key, objective=view.objective
        )
    return written


@contextmanager
def progress_bar(total: int) -> Iterator[Callable[[SweepProgress], None]]:
    """A rich progress bar of ``total`` runs on stderr: counts, elapsed time and ETA.

    Failed runs are printed above the bar (:attr:`auvplan.sweep.RunRecord.description`).
    """
    from rich.console import Console
    from rich.progress import (
        BarColumn,
        MofNCompleteColumn,
        Progress,
        TextColumn,
        TimeElapsedColumn,
        TimeRemainingColumn,
    )

    console = Console(stderr=True)
    with Progress(
        TextColumn("sweep"), BarColumn(), MofNCompleteColumn(), TextColumn("{task.fields[counts]}"),
        TimeElapsedColumn(), TextColumn("ETA"), TimeRemainingColumn(), console=console,
    ) as bar:  # fmt: skip
        task = bar.add_task("sweep", total=total, counts="starting the cluster")

        def update(event: SweepProgress) -> None:
            if event.record is None:  # the start: runs finished before count as done
                bar.update(task, total=total - event.skipped)
            elif event.record.failed:
                bar.console.print(f"failed {event.record.description}")
            ok = event.finished - event.failed
            bar.update(
                task,
                completed=event.finished,
                counts=f"{ok} finished, {event.failed} failed, {event.running} running"
                + (f", {event.skipped} skipped" if event.skipped else ""),
            )

        yield update
