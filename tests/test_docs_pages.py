"""What the pages say of the code is the code's: the architecture page's code layout is the
package tree (docs/architecture.md, "Code layout"), and every ``kind:`` the README and the
pages name is a kind a config can declare."""

from __future__ import annotations

import re
from pathlib import Path

from homebench.config import ROBOT_KINDS

ROOT = Path(__file__).resolve().parents[1]
PAGE = ROOT / "docs" / "architecture.md"


def drawn_folders() -> set[str]:
    """The folders of the page's code layout block, as paths under the repository, from the
    indentation of each line whose first word ends in a slash."""
    block = PAGE.read_text().split("## Code layout", 1)[1].split("```text", 1)[1]
    block = block.split("```", 1)[0]
    stack: list[tuple[int, str]] = []
    folders = set()
    for line in block.splitlines():
        found = re.match(r"( *)(\w+)/(\s|$)", line)
        if not found:
            continue
        depth = len(found[1])
        while stack and stack[-1][0] >= depth:
            stack.pop()
        path = "/".join([name for _, name in stack] + [found[2]])
        stack.append((depth, found[2]))
        folders.add(path)
    return folders


def test_the_code_layout_draws_every_package_where_it_is() -> None:
    packages = {
        str(init.parent.relative_to(ROOT)) for init in (ROOT / "homebench").rglob("__init__.py")
    }
    assert drawn_folders() == packages


def test_every_kind_the_pages_name_is_a_kind_of_config() -> None:
    pages = [ROOT / "README.md", *sorted((ROOT / "docs").rglob("*.md"))]
    named = {
        (page.name, kind)
        for page in pages
        for kind in re.findall(r"\bkind: ([\w-]+)", page.read_text())
    }
    assert named, "no page names a kind"
    assert {(page, kind) for page, kind in named if kind not in {"grid", *ROBOT_KINDS}} == set()
