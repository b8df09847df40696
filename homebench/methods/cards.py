"""A method as a card: what ``homebench methods`` prints and the documentation's method
reference shows, in text, Markdown or JSON, from the method's class alone.

A card holds the method's name, image kind, summary (the class docstring's first paragraph),
citation (the class attribute ``citation`` where a plugin sets one, else the first paragraph of
its module's docstring, which names the paper) and its parameters
(:func:`~homebench.methods.params.parameter_docs`: type, default, bounds, meaning and standing).
The JSON keys are stable: :data:`CARD_KEYS` and :data:`PARAMETER_KEYS`.
"""

from __future__ import annotations

import json
import sys
import textwrap
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any, Literal

from homebench.methods.image_difference.visual_compass import CompassMode
from homebench.methods.params import (
    WIDTH,
    ParameterDoc,
    ParamInfo,
    first_paragraph,
    parameter_docs,
    parameter_lines,
    summary,
    type_text,
)

Format = Literal["text", "md", "json"]
FORMATS: tuple[Format, ...] = ("text", "md", "json")

#: Keys of a method's JSON object (the last two only for one method, not in the list).
CARD_KEYS = (
    "name", "image_kind", "summary", "citation", "gives_direction", "parameters",
    "entry_parameters",
)  # fmt: skip
#: Keys of a parameter's JSON object.
PARAMETER_KEYS = ("name", "type", "default", "required", "bounds", "standing", "meaning", "note")

_COMPASS = ParamInfo(
    "How the current view is aligned with the goal's before the method sees it (grid, route "
    "and closed-loop configs). none: as stored (a grid database taken at one heading; in the "
    "robot experiments the robot's own heading). visual: turned back by this visual compass's "
    "estimate (the RIDF minimum). truth: turned back by the true heading change in whole "
    "columns, an ideal compass.",
    reading="the papers of alv, snapshot, block-matching and mfdid align their views with an "
    "external compass: none on a grid database, truth for a robot",
)
#: The keys every method entry of a config takes beside ``method`` and ``params``.
ENTRY_PARAMETERS = (
    ParameterDoc(
        "compass", type_text(CompassMode), repr("none"), _COMPASS.meaning, "reading",
        _COMPASS.reading, value="none",
    ),
)  # fmt: skip
ENTRY_HEADER = "Every method entry also takes:"


@dataclass(frozen=True)
class MethodCard:
    """One method as documented: see the module docstring."""

    name: str
    image_kind: str
    summary: str
    citation: str
    gives_direction: bool
    parameters: tuple[ParameterDoc, ...]


def citation(cls: type) -> str:
    """The paper a method implements: its ``citation`` attribute, else the first paragraph of
    its module's docstring ("Franz et al. (1998) 1-D warping on the horizon signal.")."""
    own = getattr(cls, "citation", None)
    if isinstance(own, str) and own:
        return own
    module = sys.modules.get(cls.__module__)
    return first_paragraph(getattr(module, "__doc__", None))


def card(name: str, cls: type) -> MethodCard:
    """The card of method class ``cls`` registered as ``name``."""
    return MethodCard(
        name=name,
        image_kind=str(getattr(cls, "image_kind", "?")),
        summary=summary(cls),
        citation=citation(cls),
        gives_direction=bool(getattr(cls, "gives_direction", True)),
        parameters=tuple(parameter_docs(cls)),
    )


# --------------------------------------------------------------------------- text


def _wrapped(text: str, indent: str) -> list[str]:
    return textwrap.wrap(text, WIDTH, initial_indent=indent, subsequent_indent=indent + " ")


def card_text(one: MethodCard) -> str:
    """A method for the terminal: header, citation, parameters, then the entry-level keys."""
    return "\n".join(
        [
            f"{one.name} ({one.image_kind} images): {one.summary}",
            *_wrapped(f"paper: {one.citation}", "    "),
            *parameter_lines(one.parameters),
            "",
            ENTRY_HEADER,
            *parameter_lines(ENTRY_PARAMETERS),
        ]
    )


def listing_text(cards: Sequence[MethodCard], broken: Mapping[str, str]) -> str:
    """Every method on one line (name, image kind, summary), then the broken plugins."""
    width = max((len(c.name) for c in cards), default=0)
    lines = [f"{c.name:<{width}}  {c.image_kind:<8}  {c.summary}" for c in cards]
    lines += [f"{name} (broken plugin): {reason}" for name, reason in broken.items()]
    lines.append("homebench methods NAME shows a method's parameters, defaults and standing.")
    return "\n".join(lines)


# --------------------------------------------------------------------------- Markdown

_MD_SPECIAL = str.maketrans({c: f"\\{c}" for c in "\\`*_[]"} | {"<": "&lt;", ">": "&gt;"})


def md_text(text: str) -> str:
    """Plain text as Markdown that shows it as written (no emphasis, links or tags)."""
    return text.translate(_MD_SPECIAL)


def _standing(doc: ParameterDoc) -> str:
    return {"departure": "departure (opt-in)", "reading": "reading"}.get(doc.status, "paper")


def parameter_markdown(docs: Sequence[ParameterDoc]) -> list[str]:
    """One list item per parameter: name, default, type, standing, meaning and note."""
    lines = []
    for doc in docs:
        head = f"- **`{doc.name}`** = `{doc.default}` · *{md_text(doc.type)}* · {_standing(doc)}"
        lines.append(f"{head}: {md_text(doc.meaning)}" if doc.meaning else head)
        if doc.note:
            label = "Paper" if doc.status == "departure" else "Reading"
            lines.append(f"    <br>*{label}:* {md_text(doc.note)}")
    return lines


def card_markdown(one: MethodCard, level: int = 2) -> str:
    """A method as a Markdown section whose heading (``level`` hashes) is its name."""
    return "\n".join(
        [
            f"{'#' * level} {one.name}",
            "",
            md_text(one.summary),
            "",
            f"- **Images:** {one.image_kind}",
            f"- **Paper:** {md_text(one.citation)}",
            f"- **Gives a home direction:** {'yes' if one.gives_direction else 'no'}",
            "",
            f"{'#' * (level + 1)} Parameters of {one.name}",
            "",
            *(parameter_markdown(one.parameters) or ["No parameters."]),
            "",
        ]
    )


def listing_markdown(cards: Sequence[MethodCard], broken: Mapping[str, str]) -> str:
    """Every method as a row of a Markdown table, then the broken plugins."""
    lines = ["| method | images | what it is |", "| --- | --- | --- |"]
    lines += [f"| `{c.name}` | {c.image_kind} | {md_text(c.summary)} |" for c in cards]
    lines += [f"\n- `{name}` (broken plugin): {md_text(why)}" for name, why in broken.items()]
    return "\n".join(lines) + "\n"


# --------------------------------------------------------------------------- JSON


def _json_value(value: Any) -> Any:
    """``value`` as JSON holds it (a tuple as a list), or its repr where JSON cannot."""
    try:
        return json.loads(json.dumps(value, allow_nan=False))
    except (TypeError, ValueError):
        return repr(value)


def parameter_json(doc: ParameterDoc) -> dict[str, Any]:
    """A parameter as a JSON object with the keys :data:`PARAMETER_KEYS`."""
    return {
        "name": doc.name,
        "type": doc.type,
        "default": _json_value(doc.value),
        "required": doc.required,
        "bounds": doc.bounds,
        "standing": doc.status or "paper",
        "meaning": doc.meaning,
        "note": doc.note,
    }


def card_json(one: MethodCard, parameters: bool = True) -> dict[str, Any]:
    """A method as a JSON object with the keys :data:`CARD_KEYS` (``parameters`` only when
    asked for)."""
    out: dict[str, Any] = {
        "name": one.name,
        "image_kind": one.image_kind,
        "summary": one.summary,
        "citation": one.citation,
        "gives_direction": one.gives_direction,
    }
    if parameters:
        out["parameters"] = [parameter_json(doc) for doc in one.parameters]
        out["entry_parameters"] = [parameter_json(doc) for doc in ENTRY_PARAMETERS]
    return out


def listing_json(cards: Sequence[MethodCard], broken: Mapping[str, str]) -> dict[str, Any]:
    """``{"methods": [...], "broken": [{"name", "reason"}]}``: the methods without their
    parameters."""
    return {
        "methods": [card_json(c, parameters=False) for c in cards],
        "broken": [{"name": name, "reason": why} for name, why in broken.items()],
    }


# --------------------------------------------------------------------------- one entry point


def render_card(one: MethodCard, fmt: Format) -> str:
    """One method in format ``fmt``."""
    if fmt == "json":
        return json.dumps(card_json(one), indent=2, ensure_ascii=False)
    return card_markdown(one) if fmt == "md" else card_text(one)


def render_listing(cards: Sequence[MethodCard], broken: Mapping[str, str], fmt: Format) -> str:
    """Every method in format ``fmt``, one line (row, object) each."""
    if fmt == "json":
        return json.dumps(listing_json(cards, broken), indent=2, ensure_ascii=False)
    return (listing_markdown if fmt == "md" else listing_text)(cards, broken)
