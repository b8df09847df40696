"""``homebench methods [NAME]``: one line per method; one method's every parameter with type,
default, bounds, meaning and its relation to the paper, and its citation; text, Markdown or JSON
(stable keys); an unknown name is a usage error; plugins without documentation still listed; a
closed pipe ends the listing quietly."""

from __future__ import annotations

import json
import subprocess
import sys
from dataclasses import dataclass, field
from typing import ClassVar

import pytest
from click.testing import CliRunner

from homebench.cli import main
from homebench.methods import registry
from homebench.methods.cards import CARD_KEYS, PARAMETER_KEYS, citation
from homebench.methods.params import ParameterDoc, param, parameter_docs
from homebench.methods.sift.method import Sift


def _output(*args: str) -> str:
    result = CliRunner().invoke(main, ["methods", *args])
    assert result.exit_code == 0, result.output
    return result.stdout


def test_every_builtin_lists_its_summary_and_documented_parameters():
    for name, cls in registry.available().items():
        out = _output(name)
        assert out.startswith(f"{name} ({cls.image_kind} images): ")
        assert "    paper: " in out
        for doc in parameter_docs(cls):
            assert f"    {doc.name} = {doc.default} ({doc.type})" in out
            assert doc.meaning, f"{name}.{doc.name} has no meaning"
            assert " ".join(doc.meaning.split()[:4]) in out  # its start (the text is wrapped)


def test_without_a_name_every_method_is_one_line():
    lines = _output().splitlines()
    methods = registry.available()
    assert len(lines) == len(methods) + 1  # and the line that says how to see one
    for line, (name, cls) in zip(lines, methods.items(), strict=False):
        assert line.split()[:2] == [name, cls.image_kind]
    assert "homebench methods NAME" in lines[-1]


def test_the_entry_level_compass_is_listed_with_the_papers_reading():
    out = _output("alv")
    assert "Every method entry also takes:" in out
    assert "    compass = 'none' (one of none | visual | truth)" in out
    assert "external compass" in out


def test_departures_and_readings_are_marked():
    sift, warping = _output("sift"), _output("warping")
    assert "    ahead_filter = False (bool)" in sift
    assert "[departure, opt-in. Paper: keeps every triple eq. 3 solves" in sift
    assert "    max_triples = 2000 (int | None)" in sift
    assert "[reading: 'a number of parameter sets" in sift
    assert "    normalize = 'none' (one of none | equalize | zscore)" in warping
    assert "    prealign = False (bool)" in _output("klt-sector")


def test_bounds_and_citation_are_shown():
    out = _output("infomax")
    assert "    seed = 0 (int >= 0)" in out
    assert "paper: Infomax route navigation (Baddeley, Graham, Husbands & Philippides 2012" in out
    assert "paper: Franz et al. (1998) 1-D warping" in _output("warping")


def test_json_has_stable_keys_and_the_defaults_as_values():
    one = json.loads(_output("infomax", "--format", "json"))
    assert tuple(one) == CARD_KEYS
    assert all(tuple(p) == PARAMETER_KEYS for p in one["parameters"])
    seed = next(p for p in one["parameters"] if p["name"] == "seed")
    assert seed["default"] == 0
    assert seed["bounds"] == ">= 0"
    assert seed["required"] is False
    standings = {p["standing"] for name in ("sift", "warping") for p in _json(name)}
    assert standings == {"paper", "reading", "departure"}
    listing = json.loads(_output("--format", "json"))
    assert [m["name"] for m in listing["methods"]] == list(registry.available())
    assert tuple(listing["methods"][0]) == CARD_KEYS[:-2]
    assert listing["broken"] == []


def _json(name: str) -> list[dict[str, object]]:
    return json.loads(_output(name, "--format", "json"))["parameters"]


def test_markdown_lists_methods_as_a_table_and_one_method_as_a_section():
    table = _output("--format", "md")
    assert table.startswith("| method | images | what it is |")
    assert "| `warping` | unfolded | " in table
    section = _output("sift", "--format", "md")
    assert section.startswith("## sift\n")
    assert "- **`ahead_filter`** = `False` · *bool* · departure (opt-in): " in section
    assert "*Paper:* keeps every triple eq. 3 solves" in section


def test_an_unknown_name_is_a_usage_error_naming_the_closest_or_all():
    close = CliRunner().invoke(main, ["methods", "warpin"])
    assert close.exit_code == 2
    assert "unknown method 'warpin' (did you mean 'warping'?)" in close.stderr
    far = CliRunner().invoke(main, ["methods", "xyzzy"])
    assert far.exit_code == 2
    assert "known: alv, block-matching" in far.stderr


def test_one_method_as_json_from_a_process_of_its_own():
    done = subprocess.run(
        [sys.executable, "-m", "homebench", "methods", "warping", "--format", "json"],
        capture_output=True, text=True, timeout=120, check=True,
    )  # fmt: skip
    card = json.loads(done.stdout)
    assert card["name"] == "warping"
    assert {p["name"] for p in card["parameters"]} == set(registry.parameters("warping"))


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
    monkeypatch.setattr(registry, "get", lambda name: {"plugin": _Plugin}[name])
    assert _output().startswith("plugin  unfolded  A third-party method without parameter")
    out = _output("plugin")
    assert "plugin (unfolded images): A third-party method without parameter documentation." in out
    assert "Second paragraph" not in out
    assert "paper: homebench methods [NAME]: one line per method" in out  # its module's docstring
    assert "    gain = 1.5 (float)" in out
    assert "    mode = 'fast' (UndefinedAlias)" in out
    assert "    weights = [1.0, 2.0] (list[float])" in out


def test_a_plugin_may_name_its_paper():
    cited = type("Cited", (_Plugin,), {"citation": "Doe et al. (2031), J. Homing 1."})
    assert citation(cited) == "Doe et al. (2031), J. Homing 1."


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
