"""The compiled hot path: a run's step over preallocated buffers and numba kernels."""

from dvqp.compiled.interrupts import guard_compilation
from dvqp.compiled.plan import (
    Kernel,
    ProximityBuffers,
    SelfPairBuffers,
    Slot,
    StateBuffers,
    StepPlan,
)

guard_compilation()

__all__ = ["Kernel", "ProximityBuffers", "SelfPairBuffers", "Slot", "StateBuffers", "StepPlan"]
