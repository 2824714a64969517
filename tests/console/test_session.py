"""The console's pieces without a server: message checks, clamping, token/Host/Origin rules,
the session's verified steps, its bounded record and the real-time clock."""

from __future__ import annotations

import json
import time
from pathlib import Path

import numpy as np
import pytest

from dvqp import load_scene
from dvqp.console import protocol, recording, security
from dvqp.console.clock import RealTimeClock
from dvqp.console.messages import scene_message
from dvqp.console.session import ConsoleSession
from dvqp.errors import BackendError

PAPER = Path(__file__).resolve().parents[2] / "scenes" / "paper-two-inlets.toml"


@pytest.fixture(scope="module")
def scene():  # type: ignore[no-untyped-def]
    return load_scene(PAPER)


def test_parse_accepts_the_three_messages() -> None:
    jog = protocol.parse('{"type": "jog", "velocity": [0.05, 0, -1, 2]}')
    assert jog.kind == "jog" and jog.velocity.tolist() == [0.05, 0.0, -1.0, 2.0]
    assert protocol.parse('{"type": "stop"}').kind == "stop"
    assert protocol.parse('{"type":"reset"}').kind == "reset"


@pytest.mark.parametrize(
    ("frame", "message"),
    [
        (b"{}", "binary frames are not accepted"),
        ("x" * 4097, "message too long: 4097 bytes"),
        ("{", "not JSON"),
        ("[1]", "expected a JSON object, got list"),
        ('{"type": "fly"}', 'unknown message type "fly"'),
        ('{"type": "stop", "v": 1}', 'stop: unknown key "v"'),
        ('{"type": "jog", "velocity": [1, 2]}', "velocity must be an array of 4 numbers"),
        ('{"type": "jog", "velocity": [1, 2, 3, NaN]}', "NaN is not a number"),
        ('{"type": "jog", "velocity": [1, 2, 3, 1e400]}', "velocity alpha: must be finite"),
        ('{"type": "jog", "velocity": [1, false, 3, 4]}', "velocity z: expected a number"),
        ('{"type": "jog", "velocity": [1, 2, ' + "9" * 400 + ", 4]}", "h: must be finite"),
    ],
)
def test_parse_refuses_in_one_line(frame: str | bytes, message: str) -> None:
    with pytest.raises(protocol.ProtocolError, match=message.replace("[", r"\[")) as info:
        protocol.parse(frame)
    assert "\n" not in str(info.value)


def test_clamp_names_what_it_clamped() -> None:
    applied, note = protocol.clamp(np.array([0.5, -0.05, -0.2, 3.0]))
    assert applied.tolist() == [0.1, -0.05, -0.1, 1.0]
    assert note == "clamped: l 0.5 -> 0.1 m/s, h -0.2 -> -0.1 m/s, alpha 3 -> 1 rad/s"
    assert protocol.clamp(np.array([0.1, 0, 0, -1.0]))[1] is None


def test_token_host_and_origin_rules() -> None:
    token = security.new_token()
    assert len(token) == 43 and token != security.new_token()
    assert security.token_ok(token, token) and not security.token_ok(token[:-1], token)
    assert not security.token_ok(None, token) and not security.token_ok("", token)
    for host in ("127.0.0.1:8765", "localhost:8765", "[::1]:8765", "127.0.0.2"):
        assert security.host_ok(host, "127.0.0.1"), host
    for host in ("evil.example:8765", "192.168.1.4:8765", None, ""):
        assert not security.host_ok(host, "127.0.0.1"), host
    assert security.host_ok("robot.lan:8765", "0.0.0.0")  # bound elsewhere: the token guards
    assert security.origin_ok(None, "127.0.0.1:8765")
    assert security.origin_ok("http://127.0.0.1:8765", "127.0.0.1:8765")
    for origin in ("http://evil.example", "http://127.0.0.1:9", "null", "ftp://127.0.0.1:8765"):
        assert not security.origin_ok(origin, "127.0.0.1:8765"), origin
    assert security.url("::1", 80, "t") == "http://[::1]:80/?token=t"


def test_the_scene_message_is_json_with_every_obstacle(scene) -> None:  # type: ignore[no-untyped-def]
    message = json.loads(protocol.encode(scene_message(scene, "daqp")))
    assert message["orbital_level"] == 0.08 and message["min_height"] == 0.02
    assert message["margin"] == 0.01 and len(message["obstacles"]) == 2
    assert message["speed_limits"] == {"linear": 0.1, "angular": 1.0}


def test_a_session_steps_like_plan_and_records_only_motion(scene) -> None:  # type: ignore[no-untyped-def]
    session = ConsoleSession(scene, "daqp")
    start = session.snapshot()
    for _ in range(10):  # no command: the arm may settle, idle steps are not recorded
        session.step()
    settled = len(session.trajectory().status)
    session.jog([0.05, 0.0, 0.0, 0.0])
    for _ in range(200):
        session.step()
    assert session.snapshot()["velocity"] == [0.05, 0, 0, 0]  # the ramp is over
    session.stop()
    for _ in range(100):  # the ramp down, then at rest
        session.step()
    state = session.snapshot()
    assert state["tool"][0] - start["tool"][0] == pytest.approx(0.05, abs=1e-4)
    assert state["status"] == "optimal" and state["seq"] == 310
    traj = session.trajectory()
    assert settled + 200 <= traj.n_steps <= settled + 300
    assert traj.q.shape == (traj.n_steps + 1, 13)
    assert traj.points.shape == (traj.n_steps + 1, 5, 3) and traj.ok
    assert np.abs(traj.tracking_error).max() < 1e-4
    session.reset()
    assert session.snapshot()["tool"] == start["tool"] and session.trajectory().n_steps == 0


def test_the_record_keeps_the_most_recent_steps(scene, monkeypatch) -> None:  # type: ignore[no-untyped-def]
    monkeypatch.setattr(recording, "MAX_RECORD_SECONDS", 20 * scene.dt)
    session = ConsoleSession(scene, "pinv")
    session.jog([0.0, 0.05, 0.0, 0.0])
    for _ in range(50):
        session.step()
    traj = session.trajectory()
    assert traj.n_steps == 20 and traj.t.shape == (21,)
    assert 0.0 < traj.tool[-1, 1] - traj.tool[0, 1] <= 20 * scene.dt * 0.05 + 1e-9
    assert np.abs(traj.tracking_error).max() < 1e-5  # against the commands of the kept steps
    assert traj.tool[-1, 1] == pytest.approx(session.snapshot()["tool"][1], abs=1e-6)


def test_an_unknown_backend_is_refused(scene) -> None:  # type: ignore[no-untyped-def]
    with pytest.raises(BackendError, match="unknown backend 'nope'"):
        ConsoleSession(scene, "nope")


def test_the_clock_keeps_real_time_and_holds_still_when_paused(scene) -> None:  # type: ignore[no-untyped-def]
    session = ConsoleSession(scene, "daqp")
    clock = RealTimeClock(session)
    clock.start()
    try:
        clock.resume()
        time.sleep(0.5)
        clock.pause()
        time.sleep(0.05)
        made = session.snapshot()["seq"]
        time.sleep(0.1)
        assert session.snapshot()["seq"] == made  # paused: no step
        assert made * scene.dt == pytest.approx(0.5, abs=0.06)
        assert clock.stats.realtime(scene.dt) == pytest.approx(1.0, abs=0.05)
    finally:
        clock.close()
