"""`dvqp compare`'s table fits a terminal; `tracked` says whether a safe run also followed."""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np

from dvqp.cli.report import TABLE, WIDE_TABLE, footer_lines, format_table
from dvqp.motion.path import ToolPath
from dvqp.run.comparison import FIELDS
from dvqp.run.sample_checks import tracking


def _row(backend: str, **given: object) -> dict[str, object]:
    row: dict[str, object] = dict.fromkeys(FIELDS)
    row.update(scene="weld-circumference", backend=backend, success=True, tracked=True)
    row.update(max_task_error=8.3e-4, min_clearance=0.01, median_step_us=27.0)
    row.update(median_solver_us=11.5, primal_residual=1e-16, refused_calls=0)
    row.update(given)
    return row


def test_the_default_table_fits_a_hundred_columns_even_with_long_names() -> None:
    rows = [_row("qpsolvers:clarabel", median_step_us=123456.0), _row("pinv", success=False)]
    text = format_table(rows)
    assert max(len(line) for line in text.splitlines()) <= 100
    headers = text.splitlines()[0].split()
    assert headers[:4] == ["scene", "backend", "ok", "tracked"]
    assert len(TABLE) < len(WIDE_TABLE)


def test_the_wide_table_has_every_column() -> None:
    text = format_table([_row("daqp")], wide=True)
    assert text.splitlines()[0].split()[:4] == ["scene", "backend", "ok", "tracked"]
    assert len(text.splitlines()[2].split()) >= len(WIDE_TABLE) - 1  # "closest": one cell


def test_the_footer_says_why_a_safe_run_is_not_tracked() -> None:
    rows = [
        _row("highs", tracked=False, max_tracking_error=0.05, max_heading_error=0.002),
        _row("daqp"),
    ]
    rows[0]["refused_calls"] = 16
    lines = footer_lines(rows)
    text = " ".join(line.strip() for line in lines)
    assert "highs: ok (every limit kept) but not tracked" in text
    assert "up to 50 mm" in text and "16 backend calls refused" in text
    assert all(len(line) <= 100 for line in lines)
    assert not any("daqp" in line for line in lines)


def test_a_failed_runs_reason_is_wrapped_within_a_hundred_columns() -> None:
    lines = footer_lines([_row("pinv", success=False, error="x " * 150)])
    assert len(lines) > 1 and all(len(line) <= 100 for line in lines)


def test_tracked_against_the_paths_tolerance_or_a_paths_defaults_for_jog() -> None:
    error = np.zeros((5, 4))
    error[2] = [0.0, -0.004, 0.0, 0.01]
    traj = SimpleNamespace(tracking_error=error)
    jog = SimpleNamespace(path=None)
    assert tracking(jog, traj) == (True, 0.004, 0.01)  # type: ignore[arg-type]
    tight = SimpleNamespace(path=ToolPath(np.zeros((2, 4)), 0.1, tolerance=0.003))
    assert tracking(tight, traj) == (False, 0.004, 0.01)  # type: ignore[arg-type]
    error[3, 3] = -0.06  # heading past the default 0.05 rad
    assert tracking(jog, traj)[0] is False  # type: ignore[arg-type, index]
    assert tracking(jog, SimpleNamespace(tracking_error=np.zeros((0, 4)))) is None  # type: ignore[arg-type]
