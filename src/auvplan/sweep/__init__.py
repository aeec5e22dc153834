"""Parameter sweeps of missions, run in parallel on dask.distributed (``auvplan sweep``).

:func:`build_runs` expands ``--vary KEY=v1,v2,...`` options and seeds into validated runs
(:mod:`~auvplan.sweep.spec`), :func:`run_sweep` runs them on a cluster, each into its own
output folder, skipping runs finished before (:mod:`~auvplan.sweep.runner`),
:func:`sweep_frame` tabulates the records and :func:`add_run_columns` adds per-run columns
such as the TAN figures of a navigation evaluation (:mod:`~auvplan.sweep.table`),
:func:`evaluate_folder` flies a plan folder's tracks through the TAN simulator
(:mod:`~auvplan.sweep.navigation`, ``auvplan evaluate`` and ``sweep --evaluate``), and
:func:`pareto_view` finds the energy/navigation trade-off (:mod:`~auvplan.sweep.pareto`).
"""

from __future__ import annotations

from auvplan.sweep.missions import mission_file_base, scenario_bases
from auvplan.sweep.navigation import (
    FolderNavigation,
    NavigationOptions,
    NavigationRequest,
    evaluate_folder,
    evaluate_run_folder,
    is_evaluated,
)
from auvplan.sweep.pareto import ParetoView, non_dominated, pareto_view, trade_off
from auvplan.sweep.runner import RunOptions, SweepProgress, require_dask, run_folder, run_sweep
from auvplan.sweep.spec import (
    MissionBase,
    SweepRun,
    VaryAxis,
    build_runs,
    parse_seeds,
    parse_vary,
    run_identifier,
)
from auvplan.sweep.table import (
    TAN_COLUMN,
    RunRecord,
    add_run_columns,
    json_rows,
    navigation_columns,
    sweep_frame,
    write_pareto_table,
    write_sweep_files,
)

__all__ = [
    "TAN_COLUMN",
    "FolderNavigation",
    "MissionBase",
    "NavigationOptions",
    "NavigationRequest",
    "ParetoView",
    "RunOptions",
    "RunRecord",
    "SweepProgress",
    "SweepRun",
    "VaryAxis",
    "add_run_columns",
    "build_runs",
    "evaluate_folder",
    "evaluate_run_folder",
    "is_evaluated",
    "json_rows",
    "mission_file_base",
    "navigation_columns",
    "non_dominated",
    "pareto_view",
    "parse_seeds",
    "parse_vary",
    "require_dask",
    "run_folder",
    "run_identifier",
    "run_sweep",
    "scenario_bases",
    "sweep_frame",
    "trade_off",
    "write_pareto_table",
    "write_sweep_files",
]
