"""Redundancy resolution: the step's spec, the resolvers and the registry of their names."""

from dvqp.resolution.pinv import PseudoinverseResolver
from dvqp.resolution.qp import QPResolver
from dvqp.resolution.registry import available_resolvers, make_resolver
from dvqp.resolution.spec import StepSpec
from dvqp.resolution.step import Resolver, Step

__all__ = [
    "PseudoinverseResolver",
    "QPResolver",
    "Resolver",
    "Step",
    "StepSpec",
    "available_resolvers",
    "make_resolver",
]
