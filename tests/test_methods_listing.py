"""``homebench methods``: every parameter with type, default, meaning and its relation to the
paper; plugins without documentation still listed; a closed pipe ends the listing quietly."""

from __future__ import annotations

import subprocess
import sys
from dataclasses import dataclass, field
from typing import ClassVar

import pytest
from click.testing import CliRunner

from homebench.cli import main
from homebench.methods import registry
from homebench.methods.params import ParameterDoc, param, parameter_docs
from homebench.methods.sift import Sift


def _listing() -> str:
    result = CliRunner().invoke(main, ["methods"])
    assert result.exit_code == 0, result.output
    return result.stdout


def test_every_builtin_lists_its_summary_and_documented_parameters():
    out = _listing()
    for name, cls in registry.available().items():
        assert f"{name} ({cls.image_kind} images): " in out
        for doc in parameter_docs(cls):
            assert f"    {doc.name} = {doc.default} ({doc.type})" in out
            assert doc.meaning, f"{name}.{doc.name} has no meaning"
            assert " ".join(doc.meaning.split()[:4]) in out  # its start (the text is wrapped)


def test_the_entry_level_compass_is_listed_with_the_papers_reading():
    out = _listing()
    assert "Every method entry also takes:" in out
    assert "    compass = 'none' (one of none | visual | truth)" in out
    assert "external compass" in out


def test_departures_and_readings_are_marked():
    out = _listing()
    assert "    ahead_filter = False (bool)" in out
    assert "[departure, opt-in. Paper: keeps every triple eq. 3 solves" in out
    assert "    max_triples = 2000 (int | None)" in out
    assert "[reading: 'a number of parameter sets" in out
    assert "    normalize = 'none' (one of none | equalize | zscore)" in out
    assert "    prealign = False (bool)" in out


def test_a_parameter_records_its_status():
    docs = {doc.name: doc for doc in parameter_docs(Sift)}
    assert docs["ahead_filter"].status == "departure"
    assert docs["ratio"].status == "reading"
    assert docs["n_references"] == ParameterDoc(
        "n_references", "int", "5", "nR: reference landmarks per tested pair (Table 1)."
    )
    with pytest.raises(ValueError, match="either"):
        param(1, "both at once", paper="x", reading="y")


@dataclass(frozen=True)
class _Plugin:
    """A third-party method without parameter documentation.

    Second paragraph, not listed."""

    name: ClassVar[str] = "plugin"
    image_kind: ClassVar[str] = "unfolded"
    gain: float = 1.5
    mode: UndefinedAlias = "fast"  # noqa: F821  (an annotation that does not resolve)
    weights: list[float] = field(default_factory=lambda: [1.0, 2.0])


def test_a_plugin_without_metadata_lists_type_and_default(monkeypatch: pytest.MonkeyPatch):
    monkeypatch.setattr(registry, "available", lambda: {"plugin": _Plugin})
    out = _listing()
    assert "plugin (unfolded images): A third-party method without parameter documentation." in out
    assert "Second paragraph" not in out
    assert "    gain = 1.5 (float)" in out
    assert "    mode = 'fast' (UndefinedAlias)" in out
    assert "    weights = [1.0, 2.0] (list[float])" in out


def test_a_closed_pipe_ends_the_listing_quietly():
    """``homebench methods | head``: the reader goes away before the listing is written."""
    process = subprocess.Popen(
        [sys.executable, "-m", "homebench", "methods"],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
    )
    process.stdout.close()  # before the interpreter has started: every write meets a closed pipe
    stderr = process.stderr.read()
    process.stderr.close()
    assert process.wait(timeout=120) == 0
    assert stderr == b""


def test_a_method_entry_says_how_it_stands_to_its_paper():
    from homebench.methods import registry
    from homebench.methods.params import paper_statement

    sift = registry.get("sift")
    assert paper_statement(sift, registry.parameters("sift")) == "the paper's defaults"
    assert paper_statement(sift, {"ahead_filter": False}) == "the paper's defaults"
    statement = paper_statement(sift, {"horizon_constraint": False, "ahead_filter": True})
    assert statement == (
        "the paper's defaults except changed: horizon_constraint = False (default True); "
        "departures from the paper switched on: ahead_filter = True"
    )
