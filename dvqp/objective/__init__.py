"""The objective ``w(Q)``: terms that add up to its value and gradient."""

from dvqp.objective.objective import Objective, Term

__all__ = ["Objective", "Term"]
