"""Griffe extension: the API page's docstrings as Markdown.

The code's docstrings are reStructuredText-flavoured (``:func:`name```, ``:class:``,
``:mod:``, ``:data:``, double-backtick literals) while mkdocstrings renders them as Markdown
(``docstring_style: null``): the roles would show raw. Each docstring is rewritten with
:func:`schema.markdown_doc`, the reference pages' own conversion, before it is rendered.
"""

from __future__ import annotations

import sys
from pathlib import Path
from typing import Any

import griffe

sys.path.insert(0, str(Path(__file__).parent))  # schema.py beside this file

import schema  # noqa: E402


class MarkdownDocstrings(griffe.Extension):
    """Rewrite every loaded object's docstring with :func:`schema.markdown_doc`."""

    def on_instance(self, *, obj: griffe.Object, **kwargs: Any) -> None:
        if obj.docstring is not None:
            obj.docstring.value = schema.markdown_doc(obj.docstring.value)
