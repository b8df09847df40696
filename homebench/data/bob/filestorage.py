"""OpenCV FileStorage YAML (``%YAML:1.0``) read as YAML: safely, within homebench's limits.

OpenCV starts its files with ``%YAML:1.0``, which is no YAML directive (YAML's is ``%YAML
1.0``), and tags matrices ``!!opencv-matrix`` (``-nd-matrix``, ``-sparse-matrix``), which a
safe loader refuses. Both are blanked character for character, so that the lines and columns
of errors stay the file's, and the text goes to :func:`homebench.yamlio.parse_model`: a file of
at most 4 MiB, 64 levels and 200,000 nodes (aliases expanded), duplicate keys refused, errors
as ``file:line: key.path: message``. A matrix is then the mapping it is written as (``rows``,
``cols``, ``dt``, ``data``); any other tag (``!!python/object``) is refused and nothing is
constructed from it.
"""

from __future__ import annotations

import contextlib
import re
from pathlib import Path
from typing import TypeVar

import yaml
from pydantic import BaseModel

from homebench.fileio import read_small_text
from homebench.yamlio import MAX_YAML_BYTES, parse_model

M = TypeVar("M", bound=BaseModel)

#: OpenCV's first line.
_OPENCV_HEADER = re.compile(r"%YAML:[0-9]+\.[0-9]+[ \t]*(?=\r?\n|$)")
#: The tags of OpenCV's matrix types, by their suffix after ``!!``.
_MATRIX_TAG = re.compile(r"opencv-(?:nd-|sparse-)?matrix")

try:  # libyaml's scanner; the same tokens as PyYAML's, faster
    from yaml import CSafeLoader as _Scanner
except ImportError:  # a PyYAML built without libyaml
    from yaml import SafeLoader as _Scanner  # type: ignore[assignment]


def read_filestorage(path: Path, model: type[M], what: str) -> M:
    """The OpenCV FileStorage YAML file ``path`` validated against ``model`` (``what`` names
    it in errors); DataError or ConfigError naming the file (and line) otherwise."""
    text = read_small_text(path, MAX_YAML_BYTES, what)
    return parse_model(model, as_yaml(text), str(path), what)


def as_yaml(text: str) -> str:
    """``text`` with OpenCV's header line and matrix tags replaced by spaces (same length)."""
    header = _OPENCV_HEADER.match(text)
    if header is not None:
        text = " " * header.end() + text[header.end() :]
    chars = list(text)
    # text that does not scan is left as it is from there on: the parser reports the same
    # error, at its line
    with contextlib.suppress(yaml.YAMLError):
        for token in yaml.scan(text, Loader=_Scanner):
            if isinstance(token, yaml.TagToken) and _is_matrix_tag(token, text):
                start, end = token.start_mark.index, token.end_mark.index
                chars[start:end] = " " * (end - start)
    return "".join(chars)


def _is_matrix_tag(token: yaml.TagToken, text: str) -> bool:
    """Whether ``token`` is ``!!opencv-matrix`` (or an nd or sparse one), spelt so in ``text``."""
    handle, suffix = token.value
    written = text[token.start_mark.index : token.end_mark.index]
    return (
        handle == "!!" and _MATRIX_TAG.fullmatch(suffix) is not None and written == handle + suffix
    )
