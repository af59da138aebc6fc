"""A griffe extension (``extensions:`` in mkdocs.yml): the docstrings' Sphinx roles as
links in the API reference (ADR 0072).

otonav's docstrings cross-reference in reST (``:class:`~otonav.runtime.System```), which
reads well in the source and in ``help()``; mkdocstrings reads Markdown, and showed the
roles as text (112 of them, issue 39). Here, once the package is loaded, each role
becomes an autorefs link to the object's page (its name resolved in the docstring's
scope, as Sphinx would), or plain code when that object is not on the site; a reST
literal-block marker (``Example::``) becomes a colon before the indented block, which
Markdown already shows as code. ``scripts/docs_screenshots.py`` fails on any role left.
"""

from __future__ import annotations

import html
import re
from typing import Any

import griffe

ROLE = re.compile(r":(?:py:)?(?:class|meth|func|data|attr|mod|exc|obj|const):`(~?)([^`<>]+)`")
"""A Sphinx role: ``:class:`~a.b.C``` (``~``: show only the last name)."""
LITERAL = re.compile(r"::$", flags=re.MULTILINE)


def convert(text: str, scope: griffe.Object | None) -> str:
    """``text`` with its roles made autorefs links and its ``::`` markers colons."""

    def link(match: re.Match[str]) -> str:
        short, target = match[1], match[2].strip().removesuffix("()")
        shown = target.rsplit(".", 1)[-1] if short else target
        path = target
        if scope is not None:
            try:
                path = scope.resolve(target)
            except (griffe.NameResolutionError, KeyError, AttributeError):
                path = target
        title = html.escape(shown + ("()" if match[2].strip().endswith("()") else ""))
        return f'<autoref identifier="{html.escape(path)}" optional><code>{title}</code></autoref>'

    text = ROLE.sub(link, text)
    lines = []
    for line in text.splitlines():
        if line.strip() == "::":
            continue  # a marker on its own line: the block follows
        lines.append(LITERAL.sub(":", line))
    return "\n".join(lines)


class SphinxRoles(griffe.Extension):
    """Rewrites every docstring of the loaded package (see the module docstring)."""

    def on_package(self, *, pkg: griffe.Module, **_kwargs: Any) -> None:
        seen: set[int] = set()
        self._walk(pkg, seen)

    def _walk(self, obj: griffe.Object, seen: set[int]) -> None:
        if id(obj) in seen:
            return
        seen.add(id(obj))
        if obj.docstring is not None:
            obj.docstring.value = convert(obj.docstring.value, obj)
        for member in obj.members.values():
            if not member.is_alias and isinstance(member, griffe.Object):
                self._walk(member, seen)
