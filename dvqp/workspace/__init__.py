"""The compiled step's memory: buffers allocated once per run, the rows each part owns, and the
packing of many arrays into one numba struct. It imports no domain module of dvqp."""

from dvqp.workspace.buffers import PairBuffers, ProximityBuffers, StateBuffers, link_ends
from dvqp.workspace.parts import PartNames
from dvqp.workspace.plan import CheckBuffers, DamperBuffers, Kernel, QPBuffers, Slot, StepPlan
from dvqp.workspace.struct import as_struct, struct_type

__all__ = [
    "CheckBuffers",
    "DamperBuffers",
    "Kernel",
    "PairBuffers",
    "PartNames",
    "ProximityBuffers",
    "QPBuffers",
    "Slot",
    "StateBuffers",
    "StepPlan",
    "as_struct",
    "link_ends",
    "struct_type",
]
