"""The broad phase: an obstacle far from the chain's box is skipped (its rows not written, that
distance kept as their lower bound), a part far from a polygon's or an inlet's box gets the
box's distance (a lower bound), and every row that may matter (below the far distance, the
damper's refining, the arm's or the probe's closest part) is exactly what it is without it."""

from __future__ import annotations

import math

import numpy as np
import pytest

import dvqp
from dvqp.geometry.broad_phase import box_bound, chain_box, obstacle_bound
from dvqp.geometry.measure import ShapeArrays, measure_chain, penalties
from dvqp.geometry.real_links import real_links
from dvqp.kinematics.state import KinematicState
from dvqp.workspace import ProximityBuffers, as_struct, link_ends
from tests.compiled_cases import Case, mixed_case, paper_robot

FAR = 0.06


def states(case: Case, count: int, spread: float) -> list[KinematicState]:
    return [case.state(q) for q in case.configurations(count, spread)]


def measured(case: Case, state: KinematicState, far: float) -> ProximityBuffers:
    """Every row of ``state`` to the case's obstacles, the broad phase beyond ``far``."""
    shapes = list(case.obstacles)
    packed = ShapeArrays.of(shapes, 2 * math.pi * case.radius)
    packed.refine[:] = 0.01
    packed.far[:] = far
    ends = link_ends(state.k, state.rail)
    near = ProximityBuffers.sized(len(shapes), state.guarded.shape[0], ends)
    chain = np.ascontiguousarray(state.guarded)
    measure_chain(as_struct(packed), chain, as_struct(near))
    real_links(
        as_struct(packed), chain, np.array(state.origins), case.radius, state.k, as_struct(near)
    )
    penalties(as_struct(packed), as_struct(near))
    assert not near.point_penalty[near.skipped].any()  # not written: no repulsion computed
    skipped = near.skipped  # their rows: the bound (the real links' less their bend)
    near.point_distance[skipped] = near.bound[skipped, None]
    near.real_distance[skipped] = near.bound[skipped, None] - near.bends
    return near


@pytest.mark.parametrize(("spread", "seam"), [(0.05, False), (0.4, False), (0.4, True)])
def test_rows_that_may_matter_are_exact_and_the_others_below_the_truth(
    spread: float, seam: bool
) -> None:
    case = mixed_case(paper_robot(), seam)
    proxies = skipped = 0
    for state in states(case, 12, spread):
        exact, broad = measured(case, state, math.inf), measured(case, state, FAR)
        for side in ("point_distance", "real_distance"):
            e, b = getattr(exact, side), getattr(broad, side)
            same = e < FAR
            np.testing.assert_array_equal(b[same], e[same])  # bit for bit
            assert (b <= e + 1e-15).all() and (b[~same] >= FAR - 1e-15).all()
            assert e.min() == b.min()  # the arm's closest part, exact
            proxies += int((b != e).sum())
        skipped += int(broad.skipped.sum())
        k = state.k  # the probe and its holder
        assert min(exact.point_distance[:, k].min(), exact.real_distance[:, k - 1].min()) == min(
            broad.point_distance[:, k].min(), broad.real_distance[:, k - 1].min()
        )
    if spread > 0.1:
        assert proxies > 0 and skipped > 0  # the broad phase did skip rows and obstacles


@pytest.mark.parametrize("seam", [False, True])
def test_the_chain_box_bound_is_below_every_row_of_the_obstacle(seam: bool) -> None:
    case = mixed_case(paper_robot(), seam)
    packed = ShapeArrays.of(list(case.obstacles), 2 * math.pi * case.radius)
    shapes, far = as_struct(packed), 0
    for state in states(case, 30, 0.6):
        exact = measured(case, state, math.inf)
        chain = np.ascontiguousarray(state.guarded)
        box = chain_box(chain, exact.ends, packed.period)
        for j in range(len(case.obstacles)):
            bound = obstacle_bound(shapes, j, *box)
            rows = np.concatenate([exact.point_distance[j], exact.link_distance[j]])
            assert bound <= max(rows.min(), 0.0) + 1e-15
            far += bound > FAR
    assert far > 0  # some obstacles were far from the whole chain


def test_the_box_bound_is_below_the_exact_distance_outside() -> None:
    case = mixed_case(paper_robot())
    for state in states(case, 6, 0.4):
        near = measured(case, state, math.inf)
        packed = as_struct(ShapeArrays.of(list(case.obstacles), 2 * math.pi * case.radius))
        g = state.guarded
        for j, shape in enumerate(case.obstacles):
            if type(shape).__name__ not in ("Polygon", "Inlet"):
                continue
            for i in range(g.shape[0]):
                bound = box_bound(packed, j, g[i, 0], g[i, 1], g[i, 0], g[i, 1])[0]
                assert bound <= max(near.point_distance[j, i], 0.0) + 1e-15
            for i, (a, b) in enumerate(near.ends):
                bound = box_bound(packed, j, g[a, 0], g[a, 1], g[b, 0], g[b, 1])[0]
                assert bound <= max(near.link_distance[j, i], 0.0) + 1e-15


def test_fifty_obstacles_report_the_true_clearance() -> None:
    scene = dvqp.load_scene("benchmarks/scenes/fifty-obstacles.toml")
    traj = dvqp.plan(scene, "daqp")
    for k in range(0, traj.n_steps + 1, 150):
        state = KinematicState.compute(scene.robot, traj.q[k], scene.pipe_radius)
        near = dvqp.geometry.proximity(state, scene.obstacles)  # every row exact
        assert abs(traj.min_clearance[k] - near.min_clearance()) <= 1e-5


def test_far_obstacles_rows_never_reach_the_solver() -> None:
    scene = dvqp.load_scene("benchmarks/scenes/fifty-obstacles.toml")
    resolver = dvqp.QPResolver(scene.spec(), "daqp")
    stepper = dvqp.Stepper(scene.robot, scene.pipe_radius, resolver, scene.q0, scene.dt)
    stepper.start(scene.q0)
    found = stepper.resolve(np.array([0.0, 0.01, 0.0, 0.0]), scene.dt)
    assert found.success
    applies = int(np.isfinite(stepper.arrays.qp.h).sum())
    strict = stepper.solver.backends[0]  # type: ignore[union-attr]
    seen = strict._copy.problem.h  # type: ignore[attr-defined]
    assert stepper.arrays.near.skipped.sum() > 30  # most obstacles are far from the arm
    assert applies <= seen.shape[0] <= max(8, 2 * applies) < stepper.arrays.qp.h.shape[0] // 4
    assert np.isfinite(seen).sum() == applies
