"""``dvqp bench``: a seeded suite of random scenes run with every backend, here or on Dask.

- :mod:`dvqp.bench.generate` draws the scenes (:func:`generate_scenes`), one seeded stream
  each, with :mod:`~dvqp.bench.obstacles` and :mod:`~dvqp.bench.motion`, written as TOML by
  :mod:`~dvqp.bench.toml_text`;
- :mod:`dvqp.bench.runner` runs one scene with every backend (:func:`run_job`);
- :mod:`dvqp.bench.execution` runs the jobs here or in a process pool,
  :mod:`dvqp.bench.dask_run` on a Dask cluster (optional: ``pip install 'dvqp[dask]'``);
- :mod:`dvqp.bench.summary` sums the runs up per backend (shifted geometric means);
- :mod:`dvqp.bench.output` prints and writes them; :mod:`dvqp.bench.suite` ties it together
  (:func:`run_suite`).

See ``docs/bench.md``.
"""

from dvqp.bench.dask_run import DaskUnavailableError, import_distributed
from dvqp.bench.generate import BenchScene, generate_scene, generate_scenes, save_scenes
from dvqp.bench.output import Suite, bench_json, format_summary, rows_to_csv
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
