"""``did you mean`` hints for misspelt names (methods, parameters, databases, config keys)."""

from __future__ import annotations

import difflib
from collections.abc import Iterable


def did_you_mean(word: str, choices: Iterable[str]) -> str:
    """`` (did you mean 'x'?)`` naming the choice closest to ``word``, or "" when none is
    close (difflib's ratio below 0.6)."""
    close = difflib.get_close_matches(word, list(choices), n=1)
    return f" (did you mean {close[0]!r}?)" if close else ""


def unknown(what: str, word: str, choices: Iterable[str], otherwise: str = "") -> str:
    """One line for an unknown name: "unknown method 'sfit' (did you mean 'sift'?)" when a
    choice is close, else the list of every choice ("; known: a, b") and ``otherwise``."""
    choices = sorted(choices)
    listed = f"; known: {', '.join(choices) or 'none'}{otherwise}"
    return f"unknown {what} {word!r}" + (did_you_mean(word, choices) or listed)
