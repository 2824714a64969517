"""The compiled hot path: a run's step over preallocated buffers and numba kernels."""

from dvqp.compiled.plan import (
    Kernel,
    ProximityBuffers,
    SelfPairBuffers,
    Slot,
    StateBuffers,
    StepPlan,
)

__all__ = ["Kernel", "ProximityBuffers", "SelfPairBuffers", "Slot", "StateBuffers", "StepPlan"]
