"""qpbenchmark's test set of a ``dvqp export-qps`` folder: the problems beside this file.

``dvqp export-qps`` copies this file, unchanged, into every export it writes. qpbenchmark's own
runner then benchmarks the export (its tolerances and solver settings are qpbenchmark's, the
defaults of ``qpbenchmark.TestSet``)::

    qpbenchmark DIR/dvqp_qps.py --results-path RESULTS/dvqp_qps.csv run --author NAME

It writes the results (``RESULTS/dvqp_qps.csv``) and its report (``RESULTS/dvqp_qps.md``). The
problems are the folder's, in the order of the run's backend calls (``index.json``), each named
after its file (``<scene>-<step>-<call>``). Needs only qpbenchmark (not dvqp).
"""

from __future__ import annotations

import json
from collections.abc import Iterator
from pathlib import Path

import qpbenchmark

FOLDER = Path(__file__).resolve().parent
"""The export's folder: this file's."""


def _index() -> dict:
    """The export's ``index.json``."""
    return json.loads((FOLDER / "index.json").read_text(encoding="utf-8"))


class DvqpQps(qpbenchmark.TestSet):
    """Every QP of one dvqp run (the class qpbenchmark finds by this file's name)."""

    @property
    def description(self) -> str:
        """What the problems are, for the report."""
        index = _index()
        return (
            f"The {len(index['problems'])} QPs of dvqp {index['dvqp']}'s run of the scene "
            f"{index['scene']!r} on {index['backend']} ({index['steps']} steps of "
            f"{index['dt']} s): one per backend call, the inequality rows that apply. "
            "dvqp found no answer to "
            f"{sum(not entry['found'] for entry in index['problems'])} of them (infeasible)."
        )

    @property
    def title(self) -> str:
        """The report's title."""
        return f"dvqp export: {_index()['scene']}"

    @property
    def sparse_only(self) -> bool:
        """Dense problems (n about 13 to 20): every solver takes them."""
        return False

    def __iter__(self) -> Iterator[qpbenchmark.Problem]:
        """The problems, in the order of the run's calls."""
        for entry in _index()["problems"]:
            yield qpbenchmark.Problem.load(str(FOLDER / entry["file"]))
