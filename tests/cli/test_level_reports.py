"""What the command line says of a run with task priorities: per level, kept exactly or given
way (steps, worst error in mm and rad), in ``plan``'s summary and ``compare``'s footer and
``--wide`` table; a run of one level prints as before."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

from dvqp.cli import main
from dvqp.cli.limit_series import limit_series
from dvqp.run.levels import KEPT, level_figures
from tests.runs import run, scene

ROOT = Path(__file__).resolve().parents[2]
PRIORITIES = str(ROOT / "scenes" / "reach-priorities.toml")
ONE = str(ROOT / "scenes" / "joint-limit.toml")


def test_the_summary_says_per_level_whether_it_was_kept(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    assert main(["plan", PRIORITIES, "--backend", "daqp", "-o", str(tmp_path / "r.npz")]) == 0
    out = capsys.readouterr().out
    level1 = re.search(
        r"^level 1 +tool h, alpha: kept exactly \(within 0.05 mm, 0.1 mrad\); worst error (\S+) mm,"
        r"\s+(\S+) rad$",
        out,
        re.M,
    )
    level2 = re.search(
        r"^level 2 +tool l, z: gave way in (\d+) of (\d+) steps; worst error (\S+) mm$", out, re.M
    )
    assert level1 and level2, out
    assert float(level1.group(1)) <= 0.05 and float(level1.group(2)) <= 1e-4
    assert int(level2.group(1)) > 100 and float(level2.group(3)) >= 5.0
    traj = run("reach-priorities", "daqp")
    figures = level_figures(traj)
    assert int(level2.group(1)) == int((traj.level_error[:, 1] > KEPT).sum()) == figures[1].gave_way
    assert main(["plan", ONE, "--backend", "daqp"]) == 0
    assert "level 1" not in capsys.readouterr().out  # one level: the summary as before


def test_compare_tells_each_levels_fate_in_its_footer_and_wide_table(
    capsys: pytest.CaptureFixture[str],
) -> None:
    assert main(["compare", PRIORITIES, "--backends", "pinv,daqp"]) == 0
    out = capsys.readouterr().out
    table = out.split("\n  ")[0]
    assert max(len(line) for line in table.splitlines()) <= 100
    footer = " ".join(out.split())  # the footer wrapped to 100 columns, read as one text
    assert re.search(
        r"reach-priorities / daqp: level 1 \(tool h, alpha\) kept exactly \(within 0.05 mm, 0.1 "
        r"mrad\); worst error \S+ mm, "
        r"\S+ rad; level 2 \(tool l, z\) gave way in \d+ of \d+ steps; worst error \S+ mm",
        footer,
    ), footer
    assert main(["compare", PRIORITIES, "--backends", "daqp", "--wide"]) == 0
    wide = capsys.readouterr().out.splitlines()
    assert wide[0].split()[-5:] == ["levels", "gave", "way", "least", "squares"]
    assert re.fullmatch(r"0/\d+", wide[2].split()[-2])


def test_the_limits_page_draws_each_levels_error_over_time(tmp_path: Path) -> None:
    traj = run("reach-priorities", "daqp")
    page = limit_series(scene("reach-priorities"), traj)
    assert page.level_panels == ["task level error (m)", "task level error (rad)"]
    labels = {(c.panel, c.label) for c in page.levels}
    assert labels == {
        ("task level error (m)", "level 1: tool h, alpha"),
        ("task level error (m)", "level 2: tool l, z"),
        ("task level error (rad)", "level 1: tool h, alpha"),
    }
    for c in page.levels:
        assert c.values.shape == traj.t.shape and (c.values >= 0).all()
    path = tmp_path / "limits.png"
    traj.save(tmp_path / "r.npz")
    assert main(["plot", str(tmp_path / "r.npz"), "--limits", "-o", str(path)]) == 0
    assert path.stat().st_size > 10_000
