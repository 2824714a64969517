"""End to end in real headless Chromium (Debian's ``chromium``) driven by Playwright: open the
console with its token, hold the l+ JOG key for one second, see the probe move in the drawing
and the status update, hold the on-screen z+ button, save the trajectory and load it, reset,
close the page and see the arm stop.

Skipped only where no Chromium is installed. On CI (``CI=true``) a missing Playwright or
console extra is an error, not a skip. A screenshot is kept in the test's tmp folder.
"""

from __future__ import annotations

import importlib
import os
import shutil
import time
from pathlib import Path
from typing import Any

import pytest

from dvqp import Trajectory

DEBIAN = "/usr/bin/chromium"
CHROMIUM = DEBIAN if Path(DEBIAN).exists() else shutil.which("chromium")
FLAGS = [
    "--headless",
    "--no-sandbox",
    "--disable-gpu",
    "--disable-quic",
    "--no-first-run",
    "--disable-background-networking",
    "--disable-component-update",
    "--disable-sync",
]

pytestmark = pytest.mark.skipif(
    CHROMIUM is None, reason="no Chromium installed (apt-get install chromium)"
)


def need(module: str, install: str) -> Any:
    """Import ``module``; skip without it, except on CI where it must be installed."""
    if os.environ.get("CI") == "true":
        return importlib.import_module(module)
    return pytest.importorskip(module, reason=f"{module} is not installed: {install}")


@pytest.fixture
def console():  # type: ignore[no-untyped-def]
    need("aiohttp", "pip install 'dvqp[console]'")
    from tests.console.harness import RunningConsole

    running = RunningConsole()
    yield running
    running.close()


def pixels(page: Any, rgb: tuple[int, int, int], tolerance: int) -> int:
    """Pixels of the developed view within ``tolerance`` of the colour ``rgb``."""
    return int(
        page.evaluate(
            """([rgb, tol]) => {
            const c = document.getElementById("dv");
            const d = c.getContext("2d").getImageData(0, 0, c.width, c.height).data;
            let n = 0;
            for (let i = 0; i < d.length; i += 4)
                if (Math.abs(d[i] - rgb[0]) <= tol && Math.abs(d[i + 1] - rgb[1]) <= tol
                    && Math.abs(d[i + 2] - rgb[2]) <= tol) n++;
            return n;
        }""",
            [list(rgb), tolerance],
        )
    )


def probe(page: Any) -> tuple[float, float]:
    x, y = page.get_attribute("#dv", "data-probe").split(",")
    return float(x), float(y)


def tool(page: Any) -> list[float]:
    return [float(v) for v in page.get_attribute("#dv", "data-tool").split(",")]


def test_jog_in_chromium_moves_the_probe_and_saves_a_trajectory(console, tmp_path: Path) -> None:  # type: ignore[no-untyped-def]
    sync_api = need("playwright.sync_api", "pip install playwright (no 'playwright install')")
    errors: list[str] = []
    with sync_api.sync_playwright() as p:
        browser = p.chromium.launch_persistent_context(
            str(tmp_path / "profile"),
            executable_path=CHROMIUM,
            headless=True,
            args=FLAGS,
            accept_downloads=True,
            viewport={"width": 1280, "height": 900},
        )
        page = browser.new_page()
        page.on("pageerror", lambda exc: errors.append(str(exc)))
        page.goto(console.url("/"))
        page.wait_for_function("() => window.dvqpMetrics && window.dvqpMetrics.frames > 5")
        assert page.inner_text("#connection") == "connected"
        assert pixels(page, (243, 194, 194), 6) > 2000  # the two inlets' fill
        before, t_before = probe(page), page.inner_text("#st-time")
        page.keyboard.down("ArrowRight")
        page.wait_for_timeout(1000)
        page.wait_for_function(  # a loaded machine draws fewer frames a second: waits more
            "(x0) => parseFloat(document.getElementById('dv').dataset.probe) > x0 + 16",
            arg=before[0],
            timeout=10_000,
        )
        page.keyboard.up("ArrowRight")
        page.wait_for_timeout(500)
        after = probe(page)
        assert after[0] - before[0] > 15 and abs(after[1] - before[1]) < 2  # pixels, l to the right
        assert page.inner_text("#st-time") != t_before
        assert page.inner_text("#st-step") == "optimal"
        assert page.inner_text("#st-clearance").startswith("min clearance +")
        metrics = page.evaluate("() => window.dvqpMetrics")
        page.screenshot(path=str(tmp_path / "console.png"))
        z_before = tool(page)[1]
        page.hover('[data-jog="z+1"]')  # the on-screen z+ button, held 0.4 s
        page.mouse.down()
        page.wait_for_timeout(400)
        page.mouse.up()
        page.wait_for_timeout(400)
        assert 0.01 < tool(page)[1] - z_before < 0.03
        with page.expect_download() as download:
            page.click("#save")
        download.value.save_as(tmp_path / "driven.npz")
        page.click("#reset")
        page.wait_for_function(
            "() => parseFloat(document.getElementById('st-time').textContent.slice(2)) < 0.5"
        )
        page.close()
        browser.close()
    traj = Trajectory.load(tmp_path / "driven.npz")
    assert 0.03 < traj.tool[-1, 0] - traj.tool[0, 0] < 0.07  # about 1 s at 0.05 m/s
    assert 0.01 < traj.tool[-1, 1] - traj.tool[0, 1] < 0.03  # and 0.4 s of z+
    assert traj.ok and traj.scene_text
    assert not errors and not metrics["errors"] and len(metrics["latencies"]) == 1
    print(
        f"key press to drawn motion: {metrics['latencies'][0]:.1f} ms; screenshot "
        f"{tmp_path / 'console.png'}"
    )
    deadline = time.monotonic() + 5
    while console.console.clock.running and time.monotonic() < deadline:
        time.sleep(0.02)
    assert not console.console.clock.running  # the page is gone: the arm holds still
