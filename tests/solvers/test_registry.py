"""Tests of the backend registry: names, fresh instances, errors, versions."""

from __future__ import annotations

import dataclasses
from importlib import metadata

import pytest

import solvers
from solvers import Backend, SolverError, UnknownBackendError, available_backends, make_backend

qpsolvers = pytest.importorskip("qpsolvers")

DIRECT = {"osqp": "osqp", "clarabel": "clarabel", "daqp": "daqp", "proxqp": "proxsuite"}


def test_unknown_backend_error_lists_installed_names_on_one_line() -> None:
    with pytest.raises(UnknownBackendError) as info:
        make_backend("nope")
    error = info.value
    assert error.name == "nope"
    assert error.installed == available_backends()
    message = str(error)
    assert "\n" not in message
    assert message.startswith("unknown QP backend 'nope'; installed: ")
    assert message.endswith("; more with: pip install 'dvqp[solvers]'")
    for name in available_backends():
        assert name in message


def test_unknown_backend_error_is_a_solver_error_and_a_value_error() -> None:
    assert issubclass(UnknownBackendError, SolverError)
    assert issubclass(UnknownBackendError, ValueError)
    assert not issubclass(UnknownBackendError, KeyError)


def test_every_qpsolvers_solver_has_a_plain_and_a_forced_name() -> None:
    names = available_backends()
    for solver in qpsolvers.available_solvers:
        assert solver in names
        assert f"qpsolvers:{solver}" in names


@pytest.mark.parametrize(("name", "module"), sorted(DIRECT.items()))
def test_plain_name_of_directly_adapted_solver_is_the_direct_adapter(
    name: str, module: str
) -> None:
    pytest.importorskip(module)
    backend = make_backend(name)
    assert backend.name == name
    assert type(backend).__module__ == f"solvers.{name}_"
    forced = make_backend(f"qpsolvers:{name}")
    assert forced.name == f"qpsolvers:{name}"
    assert type(forced).__module__ == "solvers.qpsolvers_"


def test_other_solvers_use_the_generic_path_under_their_plain_name() -> None:
    for solver in set(qpsolvers.available_solvers) - set(DIRECT):
        backend = make_backend(solver)
        assert backend.name == solver
        assert type(backend).__module__ == "solvers.qpsolvers_"


@pytest.mark.parametrize("name", available_backends())
def test_make_backend_returns_a_fresh_backend_each_call(name: str) -> None:
    first, second = make_backend(name), make_backend(name)
    assert first is not second
    assert isinstance(first, Backend)
    assert first.tolerance > 0


def test_options_reach_the_backend() -> None:
    backend = make_backend(available_backends()[0], tolerance=1e-4)
    assert backend.tolerance == 1e-4


def test_backend_versions_name_installed_packages() -> None:
    versions = solvers.backend_versions()
    assert versions["qpsolvers"] == qpsolvers.__version__
    assert all(isinstance(v, str) and v for v in versions.values())


@pytest.mark.parametrize(("name", "module"), sorted(DIRECT.items()))
def test_direct_adapter_rejects_unknown_settings(name: str, module: str) -> None:
    pytest.importorskip(module)
    with pytest.raises(SolverError, match=rf"^{name}: unknown setting 'bogus' \(accepted: "):
        make_backend(name, bogus=1)


def test_describe_backends_has_one_entry_per_available_name_in_order() -> None:
    infos = solvers.describe_backends()
    assert [info.name for info in infos] == available_backends()
    for info in infos:
        assert isinstance(info, solvers.BackendInfo)
        assert info.distribution and info.version


def test_describe_backends_names_distribution_version_and_path() -> None:
    versions = solvers.backend_versions()
    via = f"via qpsolvers {qpsolvers.__version__}"
    for info in solvers.describe_backends():
        solver = info.name.removeprefix("qpsolvers:")
        assert info.version == versions[info.distribution]
        assert info.distribution == DIRECT.get(solver, "highspy" if solver == "highs" else solver)
        assert info.note == ("" if info.name in DIRECT else via), info


def test_describe_backends_marks_an_unknown_version(monkeypatch: pytest.MonkeyPatch) -> None:
    def missing(dist: str) -> str:
        raise metadata.PackageNotFoundError(dist)

    monkeypatch.setattr(metadata, "version", missing)
    infos = solvers.describe_backends()
    assert infos and all(info.version == "?" for info in infos)
    assert all(info.note in ("", "via qpsolvers ?") for info in infos)


def test_backend_info_is_frozen() -> None:
    info = solvers.describe_backends()[0]
    with pytest.raises(dataclasses.FrozenInstanceError):
        info.version = "0"  # type: ignore[misc]
