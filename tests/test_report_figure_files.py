"""Figure files written by forked children are the files the report process would write."""

from __future__ import annotations

from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np
import pytest
from matplotlib.figure import Figure

from homebench.report.figure_files import FigureFiles
from homebench.report.style import report_style


def _figure() -> Figure:
    fig, ax = plt.subplots(layout="constrained")
    ax.plot(np.arange(10), np.arange(10) ** 2, label="squares")
    ax.set_title("a figure")
    ax.legend()
    return fig


@pytest.mark.parametrize("workers", [1, 2])
def test_forked_files_are_the_files_written_in_turn(tmp_path: Path, workers: int) -> None:
    written = {}
    with report_style():
        for name, count in (("turn", 0), ("forked", workers)):
            (tmp_path / name).mkdir()
            with FigureFiles(count) as files:
                paths = [files.save(_figure(), tmp_path / name / f"f{k}") for k in range(3)]
            written[name] = [path for group in paths for path in group]
    assert [p.name for p in written["turn"]] == [p.name for p in written["forked"]]
    assert [p.suffix for p in written["turn"][:3]] == [".png", ".pdf", ".svg"]
    for turn, forked in zip(written["turn"], written["forked"], strict=True):
        assert turn.read_bytes() == forked.read_bytes(), turn.name


def test_a_figure_whose_files_fail_fails_the_report(tmp_path: Path) -> None:
    (tmp_path / "taken").write_text("a file where the figures' folder should be")
    failing = pytest.raises(RuntimeError, match="figure files not written: f0")
    with failing, FigureFiles(2) as files:
        files.save(_figure(), tmp_path / "taken" / "f0")
        files.save(_figure(), tmp_path / "f1")
    assert (tmp_path / "f1.svg").is_file()
