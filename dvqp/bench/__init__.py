"""``dvqp bench``: a seeded suite of random scenes run with every backend, here or on Dask.

:mod:`~dvqp.bench.generate` draws the scenes, :mod:`~dvqp.bench.runner` runs one with every
backend, :mod:`~dvqp.bench.execution` (here) or :mod:`~dvqp.bench.dask_run` runs the suite,
:mod:`~dvqp.bench.summary` sums it up, :mod:`~dvqp.bench.output` writes it and
:func:`run_suite` ties it together. See ``docs/bench.md``.
"""

from dvqp.bench.dask_run import DaskUnavailableError, import_distributed
from dvqp.bench.generate import BenchScene, generate_scene, generate_scenes, save_scenes
from dvqp.bench.output import PartialFile, Suite, bench_json, format_summary, rows_to_csv
from dvqp.bench.runner import Job, run_job
from dvqp.bench.suite import BenchInterrupted, make_suite, run_suite
from dvqp.bench.summary import (
    SHIFT_US,
    outcome_differences,
    qp_disagreement,
    shifted_geometric_mean,
    summarize_backends,
)

__all__ = [
    "SHIFT_US",
    "BenchInterrupted",
    "BenchScene",
    "DaskUnavailableError",
    "Job",
    "PartialFile",
    "Suite",
    "bench_json",
    "format_summary",
    "generate_scene",
    "generate_scenes",
    "import_distributed",
    "make_suite",
    "outcome_differences",
    "qp_disagreement",
    "rows_to_csv",
    "run_job",
    "run_suite",
    "save_scenes",
    "shifted_geometric_mean",
    "summarize_backends",
]
