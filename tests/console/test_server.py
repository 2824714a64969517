"""The console server over real HTTP and WebSocket: token, Host, Origin, protocol, garbage,
clamping, reset, save, the arm stopped with its connection, and a 1 s JOG moving 5 cm."""

from __future__ import annotations

import asyncio
import time
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from dvqp import Trajectory
from tests.console.harness import PAPER, RunningConsole, aiohttp, latest_state, receive

STATE_KEYS = {"type", "t", "tool", "points", "status", "min_clearance", "task_error"}


@pytest.fixture(scope="module")
def server() -> Iterator[RunningConsole]:
    running = RunningConsole(PAPER)
    yield running
    running.close()


def run(coro: Any) -> Any:
    return asyncio.run(asyncio.wait_for(coro, timeout=20))


async def status(url: str, **headers: str) -> int:
    async with aiohttp.ClientSession() as http, http.get(url, headers=headers) as r:
        return r.status


@pytest.mark.parametrize("path", ["/", "/console.js", "/draw.js", "/trajectory.npz", "/ws"])
@pytest.mark.parametrize("token", ["", "wrong", "x" * 43])
def test_a_request_without_the_token_is_refused(server: RunningConsole, path: str, token: str):
    assert run(status(server.url(path, token))) == 401


def test_the_page_and_its_files_are_served_with_the_token(server: RunningConsole):
    async def go() -> None:
        async with aiohttp.ClientSession() as http:
            async with http.get(server.url("/")) as r:
                page = await r.text()
                assert (
                    r.status == 200 and "script-src 'self'" in r.headers["Content-Security-Policy"]
                )
                assert r.headers["Referrer-Policy"] == "no-referrer"
            assert f"console.js?token={server.token}" in page and "{{token}}" not in page
            for name in ("console.js", "draw.js", "panels.js", "console.css"):
                async with http.get(server.url(f"/{name}")) as r:
                    assert r.status == 200, name
            async with http.get(server.url("/../pyproject.toml")) as r:
                assert r.status == 404

    run(go())


def test_a_foreign_host_header_is_refused(server: RunningConsole):
    """DNS rebinding: a page of evil.example resolved to 127.0.0.1 names its own Host."""
    assert run(status(server.url("/"), Host=f"evil.example:{server.port}")) == 403
    assert run(status(server.url("/"), Host=f"localhost:{server.port}")) == 200


@pytest.mark.parametrize(
    ("origin", "accepted"),
    [
        (None, True),
        ("same", True),
        ("http://evil.example", False),
        ("http://127.0.0.1:1", False),
        ("null", False),
        ("file://", False),
    ],
)
def test_a_websocket_from_another_origin_is_refused(
    server: RunningConsole, origin: str | None, accepted: bool
):
    headers = {} if origin is None else {"Origin": server.base if origin == "same" else origin}

    async def go() -> int:
        async with aiohttp.ClientSession() as http:
            try:
                async with http.ws_connect(server.url("/ws"), headers=headers) as ws:
                    assert (await ws.receive_json())["type"] == "scene"
                    return 101
            except aiohttp.WSServerHandshakeError as exc:
                return exc.status

    assert run(go()) == (101 if accepted else 403)


def test_a_client_gets_the_scene_then_states_at_30_hz_or_more(server: RunningConsole):
    async def go() -> tuple[dict, list[dict], float]:
        async with aiohttp.ClientSession() as http, http.ws_connect(server.url("/ws")) as ws:
            scene = await ws.receive_json()
            started, states = time.perf_counter(), []
            while time.perf_counter() - started < 1.0:
                states.append(await receive(ws, "state"))
            return scene, states, time.perf_counter() - started

    scene, states, took = run(go())
    assert scene["type"] == "scene" and scene["pipe_radius"] == pytest.approx(0.254)
    assert [o["kind"] for o in scene["obstacles"]] == ["circle", "circle"]
    assert len(scene["obstacles"][0]["outline"]) > 50 and scene["weld"] == 0.35
    assert len(states) / took >= 30
    last = states[-1]
    assert set(last) >= STATE_KEYS and len(last["tool"]) == 4
    assert np.array(last["points"]).shape == (5, 3)
    assert last["status"] == "optimal" and last["min_clearance"] > 0.01
    assert last["closest"].endswith(("obstacles[0]", "obstacles[1]"))


GARBAGE = [
    "not json",
    "",
    "[0.05, 0, 0, 0]",
    "null",
    '"jog"',
    "{}",
    '{"type": "fly"}',
    '{"type": 3}',
    '{"type": "jog"}',
    '{"type": "jog", "velocity": [1, 2, 3]}',
    '{"type": "jog", "velocity": [NaN, 0, 0, 0]}',
    '{"type": "jog", "velocity": [Infinity, 0, 0, 0]}',
    '{"type": "jog", "velocity": [1e999, 0, 0, 0]}',
    '{"type": "jog", "velocity": ["1", 0, 0, 0]}',
    '{"type": "jog", "velocity": [true, 0, 0, 0]}',
    '{"type": "jog", "velocity": {"l": 1}}',
    '{"type": "jog", "velocity": [' + "9" * 4000 + ", 0, 0, 0]}",
    '{"type": "stop", "now": true}',
    '{"type": "reset", "type2": 1}',
    "[" * 2000 + "]" * 2000,
    '{"type": "jog", "velocity": [0.05, 0, 0, 0], "pad": "' + "x" * 5000 + '"}',
    '{"type": "jog" "velocity": []}',
    "\x00\xff",
]


def test_garbage_gets_error_replies_and_changes_nothing(server: RunningConsole):
    held = [0.01, 0.0, 0.0, 0.0]

    async def go() -> tuple[list[dict], dict]:
        async with aiohttp.ClientSession() as http, http.ws_connect(server.url("/ws")) as ws:
            await ws.send_json({"type": "jog", "velocity": held})
            replies = []
            for frame in GARBAGE:
                await ws.send_str(frame)
                replies.append(await receive(ws, "error"))
            await ws.send_bytes(b'{"type": "reset"}')
            replies.append(await receive(ws, "error"))
            state = await latest_state(ws)
            await ws.send_json({"type": "stop"})
            return replies, state

    replies, state = run(go())
    assert len(replies) == len(GARBAGE) + 1
    assert all(r["message"] and "\n" not in r["message"] for r in replies)
    assert state["command"] == held and state["t"] > 0  # neither stopped nor reset


def test_a_huge_frame_closes_only_its_connection(server: RunningConsole):
    async def go() -> bool:
        async with aiohttp.ClientSession() as http:
            async with http.ws_connect(server.url("/ws")) as ws:
                await ws.receive_json()
                await ws.send_str("x" * (2 << 20))
                while (await ws.receive()).type not in (
                    aiohttp.WSMsgType.CLOSE,
                    aiohttp.WSMsgType.CLOSED,
                ):
                    pass
            async with http.ws_connect(server.url("/ws")) as ws:
                return (await ws.receive_json())["type"] == "scene"

    assert run(go())


def test_velocities_beyond_the_limits_are_clamped_and_reported(server: RunningConsole):
    async def go() -> dict:
        async with aiohttp.ClientSession() as http, http.ws_connect(server.url("/ws")) as ws:
            await ws.send_json({"type": "jog", "velocity": [5.0, 0.0, 0.0, -9.0]})
            state = await latest_state(ws)
            await ws.send_json({"type": "stop"})
            return state

    state = run(go())
    assert state["command"] == [0.1, 0.0, 0.0, -1.0]
    assert state["clamped"].startswith("clamped: l 5 -> 0.1 m/s, alpha -9 -> -1 rad/s")


async def jog_for(ws: Any, velocity: list[float], seconds: float) -> tuple[dict, dict]:
    """States before and after holding ``velocity`` for ``seconds``, then stopping."""
    before = await latest_state(ws)
    await ws.send_json({"type": "jog", "velocity": velocity})
    await asyncio.sleep(seconds)
    await ws.send_json({"type": "stop"})
    return before, await latest_state(ws, settle=0.4)


def test_a_jog_of_5_cm_per_s_for_1_s_moves_the_probe_5_cm_in_l(server: RunningConsole):
    async def go() -> tuple[dict, dict]:
        async with aiohttp.ClientSession() as http, http.ws_connect(server.url("/ws")) as ws:
            await ws.send_json({"type": "reset"})
            return await jog_for(ws, [0.05, 0.0, 0.0, 0.0], 1.0)

    before, after = run(go())
    moved = np.subtract(after["tool"], before["tool"])
    assert moved[0] == pytest.approx(0.05, abs=0.004)  # the wall clock's jitter, a few ms
    assert np.abs(moved[1:3]).max() < 1e-3 and abs(moved[3]) < 1e-2
    assert after["status"] == "optimal" and after["command"] == [0, 0, 0, 0]
    assert after["t"] - before["t"] == pytest.approx(1.4, abs=0.15)  # real time


def test_reset_returns_to_the_start_and_save_downloads_what_was_driven(
    server: RunningConsole, tmp_path: Path
):
    async def go() -> tuple[dict, bytes, dict, bytes]:
        async with aiohttp.ClientSession() as http, http.ws_connect(server.url("/ws")) as ws:
            await ws.send_json({"type": "reset"})
            start = await latest_state(ws)
            await jog_for(ws, [0.0, -0.05, 0.0, 0.0], 0.5)
            async with http.get(server.url("/trajectory.npz")) as r:
                assert r.headers["Content-Disposition"].endswith('-console.npz"')
                driven = await r.read()
            await ws.send_json({"type": "reset"})
            reset = await latest_state(ws, settle=0.2)
            async with http.get(server.url("/trajectory.npz")) as r:
                empty = await r.read()
            return start, driven, reset, empty

    start, driven, reset, empty = run(go())
    path = tmp_path / "driven.npz"
    path.write_bytes(driven)
    traj = Trajectory.load(path)
    assert traj.n_steps > 80 and traj.ok and traj.limits_kept.all()
    assert traj.tool[-1, 1] - traj.tool[0, 1] == pytest.approx(-0.025, abs=0.004)
    assert traj.scene_text == PAPER.read_text() and traj.backend == "daqp"
    assert np.abs(traj.tracking_error).max() < 1e-4
    assert reset["t"] < 0.3 and np.allclose(reset["tool"], start["tool"], atol=2e-4)
    (tmp_path / "empty.npz").write_bytes(empty)
    assert Trajectory.load(tmp_path / "empty.npz").n_steps < 60  # only what came after it


def test_dvqp_plot_reads_the_saved_file(server: RunningConsole, tmp_path: Path):
    pytest.importorskip("matplotlib")
    from dvqp.cli import main

    async def go() -> bytes:
        async with aiohttp.ClientSession() as http, http.ws_connect(server.url("/ws")) as ws:
            await jog_for(ws, [-0.05, 0.0, 0.0, 0.3], 0.3)
            async with http.get(server.url("/trajectory.npz")) as r:
                return await r.read()

    (tmp_path / "c.npz").write_bytes(run(go()))
    assert main(["plot", str(tmp_path / "c.npz"), "-o", str(tmp_path / "c.png")]) == 0
    assert (tmp_path / "c.png").stat().st_size > 10_000


def test_closing_the_connection_that_jogs_stops_the_arm(server: RunningConsole):
    console = server.console

    async def go() -> tuple[bool, list[float], bool]:
        async with aiohttp.ClientSession() as http, http.ws_connect(server.url("/ws")) as watcher:
            async with http.ws_connect(server.url("/ws")) as driver:
                await driver.send_json({"type": "jog", "velocity": [0.02, 0.0, 0.0, 0.0]})
                await receive(driver, "state")
                await asyncio.sleep(0.1)
                jogging = console.session.command[0] == 0.02
            await asyncio.sleep(0.2)
            return jogging, (await latest_state(watcher))["command"], console.clock.running

    jogging, command, running = run(go())
    assert jogging and command == [0, 0, 0, 0] and running  # the watcher still sees it live
    deadline = time.monotonic() + 3
    while console.clock.running and time.monotonic() < deadline:
        time.sleep(0.02)
    assert not console.clock.running  # no client left: no step at all
