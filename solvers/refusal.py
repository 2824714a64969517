"""Why a backend's answer was not accepted, named for counting (never used to accept one)."""

from __future__ import annotations

REFUSALS = ("infeasible", "iteration limit", "time limit", "inaccurate", "no answer")
"""The kinds of :attr:`Solution.refusal <solvers.Solution.refusal>`."""

_MARKS = (("infeasible", "infeas"), ("iteration limit", "iter"), ("time limit", "time"))


def refusal(status: str, answered: bool) -> str:
    """The kind of a refused answer: from the solver's ``status`` word (``"infeasible"``,
    ``"iteration limit"``, ``"time limit"``), else ``"inaccurate"`` if the solver ``answered``
    an ``x`` (that failed the check), else ``"no answer"``."""
    word = status.lower()
    for kind, mark in _MARKS:
        if mark in word:
            return kind
    return "inaccurate" if answered else "no answer"
