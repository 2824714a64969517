"""The scene-field readers: sane ranges with the bound in the message, and the one guard that
turns whatever escapes the checks (overflow, NumPy floating-point errors, recursion) into a
one-line SceneError."""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
import pytest

from dvqp.errors import ParameterError, SceneError, SingularConfigurationError
from dvqp.scenes.fields import ANY, Bound, Fields

SRC = "x.toml"


@pytest.mark.parametrize(
    ("bound", "value", "reason"),
    [
        (Bound(0.001, 100.0, "m"), 1e300, "must be <= 100 m, got 1e+300"),
        (Bound(0.001, 100.0, "m"), 1e-5, "must be >= 0.001 m, got 1e-05"),
        (Bound(0.0, 10.0, "s", strict=True), 0.0, "must be > 0, got 0.0"),
        (Bound(0.0, 10.0, "s", strict=True), -2.0, "must be > 0, got -2.0"),
        (Bound(-10.0, 10.0, "m/s"), -11.0, "must be >= -10 m/s, got -11.0"),
        (Bound(0.0, 10.0, "m/s", strict=True), 10**400, "must be <= 10 m/s, got 1.000e+400"),
        (ANY, 2e6, "must be <= 1e+06, got 2000000.0"),
        (Bound(0.0, 10.0, "m"), 10.0, None),
        (Bound(0.0, 10.0, "m"), 0.0, None),
    ],
)
def test_a_bound_names_itself_and_the_value(bound: Bound, value: float, reason: str | None) -> None:
    assert bound.reason(value) == reason


def read(field_value: object, **kw: object) -> float:
    return Fields(SRC).number({"v": field_value}, "v", "t", **kw)  # type: ignore[arg-type]


def test_numbers_are_checked_against_their_bound_or_the_default_one() -> None:
    assert read(5, within=Bound(0.0, 10.0, "m")) == 5.0
    with pytest.raises(SceneError, match=r"^x\.toml: t\.v: must be <= 10 m, got 11\.0$"):
        read(11.0, within=Bound(0.0, 10.0, "m"))
    with pytest.raises(SceneError, match=r"^x\.toml: t\.v: must be <= 1e\+06, got 1e\+300$"):
        read(1e300)
    with pytest.raises(SceneError, match=r"t\.v: must be >= -1e\+06, got -1\.000e\+400$"):
        read(-(10**400))


def test_vectors_take_one_bound_per_element_and_infinite_limits_pass() -> None:
    f = Fields(SRC)
    bounds = (Bound(-1.0, 1.0, "m"), Bound(-5.0, 5.0, "rad"))
    np.testing.assert_array_equal(f.vector_value("t.v", [1, -5], 2, within=bounds), [1.0, -5.0])
    with pytest.raises(SceneError, match=r"t\.v\[1\]: must be <= 5 rad, got 6\.0$"):
        f.vector_value("t.v", [1, 6.0], 2, within=bounds)
    limits = f.vector_value("t.v", [-np.inf, 3.0], 2, infinite=True, within=Bound(-4, 4, "rad"))
    assert limits[0] == -np.inf
    with pytest.raises(SceneError, match=r"t\.v\[1\]: must be <= 4 rad, got 1e\+300$"):
        f.vector_value("t.v", [-np.inf, 1e300], 2, infinite=True, within=Bound(-4, 4, "rad"))


def overflow() -> None:
    np.float64(1e308) * np.float64(10.0)  # a RuntimeWarning outside the guard


def deep(n: int) -> int:
    return deep(n + 1)


@pytest.mark.parametrize(
    ("raise_", "reason"),
    [
        (overflow, "cannot be used (FloatingPointError: overflow encountered in scalar multiply)"),
        (
            lambda: round(float("inf")),
            "cannot be used (OverflowError: cannot convert float infinity to integer)",
        ),
        (lambda: deep(0), "cannot be used (RecursionError: maximum recursion depth exceeded)"),
        (
            lambda: int("x"),
            "cannot be used (ValueError: invalid literal for int() with base 10: 'x')",
        ),
    ],
    ids=["numpy overflow", "OverflowError", "RecursionError", "ValueError"],
)
def test_the_guard_turns_numeric_failures_into_one_scene_error(
    raise_: Callable[[], object], reason: str
) -> None:
    with pytest.raises(SceneError) as info, Fields(SRC).guard("motion.jog[0]"):
        raise_()
    assert str(info.value) == f"{SRC}: motion.jog[0]: {reason}"


def test_the_guard_maps_constructor_and_dvqp_errors_and_passes_scene_errors() -> None:
    f = Fields(SRC)
    cases = [
        (ParameterError("radius", "must be > 0"), "pipe", "x.toml: pipe.radius: must be > 0"),
        (
            SingularConfigurationError("axis"),
            "robot.q0",
            "x.toml: robot.q0: singular configuration: axis",
        ),
        (SceneError(SRC, "a.b", "as it was"), "pipe", "x.toml: a.b: as it was"),
    ]
    for exc, prefix, message in cases:
        with pytest.raises(SceneError) as info, f.guard(prefix):
            raise exc
        assert str(info.value) == message
    with pytest.raises(TypeError), f.guard("pipe"):  # a programming error is not bad input
        raise TypeError("bug")


def test_messages_stay_on_one_line_whatever_the_file_says() -> None:
    error = SceneError("x\n.toml", 'pipe."a\nb"', "bad\r\nvalue\t1")
    assert "\n" not in str(error) and "\r" not in str(error)
    assert str(error) == 'x\\n.toml: pipe."a\\nb": bad\\r\\nvalue\\t1'
