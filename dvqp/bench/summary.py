"""The bench's figures per backend: success, steps, shifted geometric means, agreement.

Times are compared by their shifted geometric mean, as in qpbenchmark: a ratio of two is the
typical ratio of the times, and the shift keeps the shortest times from ruling it. Every
backend's is over the same scenes (those every backend ran) and relative to the fastest
backend's. See ``docs/bench.md``.
"""

from __future__ import annotations

import itertools
from collections.abc import Sequence
from typing import Any

import numpy as np

from dvqp.bench.runner import Row, is_lost
from dvqp.errors import ParameterError
from dvqp.resolution.registry import PINV
from solvers.accuracy import METRICS, AccuracyTally
from solvers.accuracy import shifted_geometric_mean as sgm

SHIFT_US = 10.0
"""Shift of the shifted geometric means of times, µs."""
OUTCOME_KEYS = ("success", "steps", "failures", "relaxed", "substepped", "error")
"""Figures of a run that must not depend on where it ran (with ``final_tool``)."""


def shifted_geometric_mean(values: Sequence[float], shift: float = SHIFT_US) -> float:
    """``exp(mean(log(v + shift))) − shift`` of non-negative ``values`` (same unit as shift,
    :func:`solvers.accuracy.shifted_geometric_mean`); ParameterError for no value, a negative
    or non-finite value, or a shift < 1."""
    try:
        return sgm(values, shift)
    except ValueError as exc:
        raise ParameterError("values", "need finite values >= 0 and a shift >= 1") from exc


def _max(values: Sequence[float | None]) -> float | None:
    return max((v for v in values if v is not None), default=None)


def summarize_backends(
    rows: Sequence[Row], backends: Sequence[str], shift: float = SHIFT_US
) -> dict[str, dict[str, Any]]:
    """One dict of figures per backend, in ``backends`` order (undefined figures None).

    ``runs``, ``succeeded``, ``success_rate`` (0..1), ``failed_steps``, ``relaxed_steps``,
    ``substepped_steps``, ``refused_calls`` (backend calls with no accepted answer) and of those
    ``capped_calls`` (stopped at an iteration or time cap), ``raised`` (runs that ended in an
    error, no figures), ``lost`` (of those, runs whose worker died or timed out:
    :func:`~dvqp.bench.runner.is_lost`);
    ``step_time_sgm_us`` and ``solve_time_sgm_us`` (shifted geometric mean over the timed
    scenes of each run's mean full step time and mean solver time, µs) and their ``_ratio``
    to the best backend; ``timed_scenes``; ``worst_limit_excess`` (m or rad);
    ``worst_task_error``; ``max_distance_to_qp_median_m`` (final tool position, m);
    ``qp_solves``, ``unanswered_solves`` and the shifted geometric means ``primal_residual``,
    ``dual_residual``, ``duality_gap`` over every step's QP answer of its runs (None: baseline).
    """
    timed = _timed_scenes(rows, backends)
    step = _sgm_column(rows, backends, timed, "mean_step_us", shift)
    solve = _sgm_column(rows, backends, timed, "mean_solve_us", shift)
    distance = _distance_to_qp_median(rows)
    out = {}
    for b in backends:
        runs = [r for r in rows if r["backend"] == b]
        ok = sum(1 for r in runs if r["success"])
        out[b] = {
            "runs": len(runs),
            "succeeded": ok,
            "success_rate": ok / len(runs) if runs else None,
            "failed_steps": sum(r["failures"] or 0 for r in runs),
            "relaxed_steps": sum(r["relaxed"] or 0 for r in runs),
            "refused_calls": sum(r.get("refused_calls") or 0 for r in runs),
            "capped_calls": sum(r.get("capped_calls") or 0 for r in runs),
            "substepped_steps": sum(r["substepped"] or 0 for r in runs),
            "raised": sum(1 for r in runs if r["steps"] is None),
            "lost": sum(1 for r in runs if is_lost(r)),
            "step_time_sgm_us": step[b][0],
            "step_time_sgm_ratio": step[b][1],
            "solve_time_sgm_us": solve[b][0],
            "solve_time_sgm_ratio": solve[b][1],
            "timed_scenes": len(timed),
            "worst_limit_excess": _max([r["max_limit_excess"] for r in runs]),
            "worst_task_error": _max([r["max_task_error"] for r in runs]),
            "max_distance_to_qp_median_m": distance.get(b),
            **_accuracy(runs),
        }
    return out


def _accuracy(runs: Sequence[Row]) -> dict[str, Any]:
    """The runs' accuracy tallies merged: every QP answer of every run counted once."""
    tally = AccuracyTally()
    for r in runs:
        if r.get("qp_solves"):
            tally.merge(
                AccuracyTally.from_dict(
                    {
                        "solves": r["qp_solves"],
                        "unanswered": r["unanswered_solves"],
                        **{m: r[m] for m in METRICS},
                    }
                )
            )
    means = tally.means()
    return {
        "qp_solves": tally.solves if means else None,
        "unanswered_solves": tally.unanswered if means else None,
        **{m: means[m] if means else None for m in METRICS},
    }


def _timed_scenes(rows: Sequence[Row], backends: Sequence[str]) -> list[str]:
    """Scenes on which every backend has a mean step and solver time."""
    timed: dict[str, set[str]] = {}
    for r in rows:
        if r["mean_step_us"] is not None and r["mean_solve_us"] is not None:
            timed.setdefault(r["scene"], set()).add(r["backend"])
    return sorted(s for s, have in timed.items() if have >= set(backends))


def _sgm_column(
    rows: Sequence[Row], backends: Sequence[str], scenes: Sequence[str], key: str, shift: float
) -> dict[str, tuple[float | None, float | None]]:
    """``(sgm, sgm / best sgm)`` of ``key`` per backend over ``scenes`` (None if none)."""
    if not scenes:
        return {b: (None, None) for b in backends}
    wanted = set(scenes)
    means = {
        b: shifted_geometric_mean(
            [r[key] for r in rows if r["backend"] == b and r["scene"] in wanted], shift
        )
        for b in backends
    }
    best = min(means.values())
    return {b: (m, m / best if best > 0 else None) for b, m in means.items()}


def _final_positions(rows: Sequence[Row]) -> dict[str, dict[str, np.ndarray]]:
    """Final tool ``[l, z, h]`` (m) of the QP runs that succeeded, by scene and backend."""
    out: dict[str, dict[str, np.ndarray]] = {}
    for r in rows:
        if r["backend"] != PINV and r["success"] and r["final_tool"] is not None:
            out.setdefault(r["scene"], {})[r["backend"]] = np.asarray(r["final_tool"][:3])
    return out


def qp_disagreement(rows: Sequence[Row]) -> dict[str, Any]:
    """The largest spread of the final tool position among QP backends that succeeded:
    ``max_spread_m`` (largest distance between two QP backends' final ``[l, z, h]`` on one
    scene, m; None if no scene had two successful QP runs), that ``scene`` and ``backends``
    pair, and ``scenes_compared``."""
    worst: dict[str, Any] = {"max_spread_m": None, "scene": None, "backends": None}
    compared = 0
    for scene, finals in _final_positions(rows).items():
        if len(finals) < 2:
            continue
        compared += 1
        for (a, pa), (b, pb) in itertools.combinations(sorted(finals.items()), 2):
            d = float(np.linalg.norm(pa - pb))
            if worst["max_spread_m"] is None or d > worst["max_spread_m"]:
                worst = {"max_spread_m": d, "scene": scene, "backends": [a, b]}
    return {**worst, "scenes_compared": compared}


def _distance_to_qp_median(rows: Sequence[Row]) -> dict[str, float]:
    """Per backend, the largest distance (m) of a successful run's final tool position from
    the median of the successful QP runs' on the same scene (scenes with two or more)."""
    finals = _final_positions(rows)
    out: dict[str, float] = {}
    for r in rows:
        qp = finals.get(r["scene"], {})
        if len(qp) < 2 or not r["success"] or r["final_tool"] is None:
            continue
        median = np.median(np.array(list(qp.values())), axis=0)
        d = float(np.linalg.norm(np.asarray(r["final_tool"][:3]) - median))
        out[r["backend"]] = max(d, out.get(r["backend"], 0.0))
    return out


def outcome_differences(a: Sequence[Row], b: Sequence[Row], tol: float = 1e-9) -> list[str]:
    """How two runs of the same suite differ in outcome, per scene and backend: in
    :data:`OUTCOME_KEYS` or in ``final_tool`` by more than ``tol`` (m, rad); empty if they agree."""
    index_a = {(r["scene"], r["backend"]): r for r in a}
    index_b = {(r["scene"], r["backend"]): r for r in b}
    found = [f"{s} / {k}: only in one" for s, k in sorted(set(index_a) ^ set(index_b))]
    for key in sorted(set(index_a) & set(index_b)):
        ra, rb = index_a[key], index_b[key]
        where = f"{key[0]} / {key[1]}"
        found += [f"{where}: {k} {ra[k]!r} != {rb[k]!r}" for k in OUTCOME_KEYS if ra[k] != rb[k]]
        ta, tb = ra["final_tool"], rb["final_tool"]
        if (ta is None) != (tb is None) or (
            ta is not None and np.max(np.abs(np.subtract(ta, tb))) > tol
        ):
            found.append(f"{where}: final_tool {ta} != {tb}")
    return found
