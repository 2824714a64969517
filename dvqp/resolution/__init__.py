"""Redundancy resolution: the step's spec, the QP built from it, and the resolvers."""

from dvqp.resolution.pinv import PseudoinverseResolver
from dvqp.resolution.qp import StepQP, StepTerms, build_qp, limit_rows, step_terms
from dvqp.resolution.qp_resolver import QPResolver
from dvqp.resolution.registry import available_resolvers, make_resolver
from dvqp.resolution.spec import StepSpec
from dvqp.resolution.step import Resolver, Step

__all__ = [
    "PseudoinverseResolver",
    "QPResolver",
    "Resolver",
    "Step",
    "StepQP",
    "StepSpec",
    "StepTerms",
    "available_resolvers",
    "build_qp",
    "limit_rows",
    "make_resolver",
    "step_terms",
]
