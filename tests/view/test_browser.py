"""``dvqp view`` of the paper scene's trajectory end to end in real headless Chromium (Debian's
``chromium``, WebGL on SwiftShader) driven by Playwright: the screenshot shows the pipe and
the arm (counted by pixels of their colours), with the baseline's links at the lower inlet's
margin in red at the last sample; typing sample 0 into the slider's box puts the arm at its
start pose, where no link is at its margin; ticking play runs the time on. The page asks
nothing of any other server.

Skipped only where no Chromium is installed. On CI (``CI=true``) a missing Playwright or
viser is an error, not a skip. The screenshots are kept in the test's tmp folder.
"""

from __future__ import annotations

import signal
import subprocess
import sys
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from tests import runs
from tests.console.test_browser import CHROMIUM, FLAGS, need

ROOT = Path(__file__).resolve().parents[2]
WEBGL = [
    "--use-gl=angle",
    "--use-angle=swiftshader",
    "--enable-unsafe-swiftshader",
    "--ignore-gpu-blocklist",
]
"""WebGL without a GPU: ANGLE on SwiftShader (instead of the console's ``--disable-gpu``)."""

pytestmark = pytest.mark.skipif(
    CHROMIUM is None, reason="no Chromium installed (apt-get install chromium)"
)


def counts(png: Path) -> dict[str, int]:
    """Pixels of the pipe's blue, the arm's orange and the margin's red, as the browser shades
    them (the lines' and the meshes' lighting change the shades, not the hues), between the
    page's panels (the notice and the axes on the left, the controls on the right)."""
    from PIL import Image

    rgb = np.asarray(Image.open(png).convert("RGB")).astype(int)[:, 320:940]  # not the panels
    r, g, b = rgb[..., 0], rgb[..., 1], rgb[..., 2]
    return {
        "pipe": int(np.sum((b > r + 50) & (b > g + 30) & (g > r))),
        "arm": int(np.sum((r > 190) & (g > 120) & (g < 215) & (b < 130) & (r - b > 90))),
        "margin": int(np.sum((r > 180) & (g < 90) & (b < 110))),
    }


def shot(page: Any, path: Path, enough: dict[str, int]) -> dict[str, int]:
    """Screenshots until the colours reach ``enough`` (the client draws progressively), or
    30 s; the last one's counts."""
    for _ in range(60):
        page.screenshot(path=str(path))
        found = counts(path)
        if all(found[k] >= v for k, v in enough.items()):
            break
        page.wait_for_timeout(500)
    return found


@pytest.fixture
def served(tmp_path: Path):  # type: ignore[no-untyped-def]
    need("viser", "pip install 'dvqp[view]'")
    traj = tmp_path / "pinv.npz"
    runs.run("paper-two-inlets", "pinv").save(traj)
    proc = subprocess.Popen(
        [sys.executable, "-m", "dvqp", "view", str(traj), "--port", "0"],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        cwd=ROOT,
    )
    try:
        yield proc.stdout.readline().strip()  # type: ignore[union-attr]
        proc.send_signal(signal.SIGINT)
        proc.communicate(timeout=15)
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait()
    assert proc.returncode == 130


def test_view_in_chromium_shows_the_pipe_and_the_arm(served: str, tmp_path: Path) -> None:
    sync_api = need("playwright.sync_api", "pip install playwright (no 'playwright install')")
    assert served.startswith("http://127.0.0.1:")
    errors: list[str] = []
    with sync_api.sync_playwright() as p:
        browser = p.chromium.launch_persistent_context(
            str(tmp_path / "profile"),
            executable_path=CHROMIUM,
            headless=True,
            args=[f for f in FLAGS if f != "--disable-gpu"] + WEBGL,
            viewport={"width": 1280, "height": 800},
        )
        page = browser.new_page()
        page.on("pageerror", lambda exc: errors.append(str(exc)))
        asked: list[str] = []
        page.on("request", lambda request: asked.append(request.url))
        page.goto(served)
        last = shot(page, tmp_path / "view-last.png", {"pipe": 50_000, "arm": 2_000, "margin": 300})
        assert last["pipe"] > 50_000, last  # the pipe fills a good part of the page
        assert last["arm"] > 2_000, last  # the arm's links
        assert last["margin"] > 300, last  # the baseline's links at the lower inlet's margin
        shown_t = page.locator("input.mantine-TextInput-input[disabled]").first  # t (s)
        assert shown_t.input_value() == f"{runs.run('paper-two-inlets', 'pinv').t[-1]:.3f}"
        box = page.locator("input.mantine-NumberInput-input").first  # the slider's own box
        box.fill("0")
        box.press("Enter")
        page.wait_for_function("(e) => e.value === '0.000'", arg=shown_t.element_handle())
        page.wait_for_timeout(1000)  # the arm's new pose, drawn
        start = shot(page, tmp_path / "view-start.png", {"pipe": 50_000, "arm": 2_000})
        assert start["margin"] < 10 and start["arm"] > 2_000 and start["pipe"] > 50_000, start
        page.locator("input.mantine-Checkbox-input").last.check()  # play
        page.wait_for_function("(e) => parseFloat(e.value) > 0.2", arg=shown_t.element_handle())
        browser.close()
    assert not errors
    away = [u for u in asked if not u.startswith((served, "data:", "blob:"))]
    assert not away  # viser's client is served whole by the view: no network needed
