"""YAML for configuration, with limits: what a config file may cost to read.

``yaml.safe_load`` refuses arbitrary objects but not arbitrary cost (issue 17): a
"billion laughs" of nested aliases is a few hundred bytes that expand to gigabytes once
the data is serialised for validation; a deeply nested flow sequence ends in a
RecursionError; a non-UTF-8 file ends in a UnicodeDecodeError traceback. Here every
such document is refused before it is expanded, with one line naming the source:

- at most :data:`MAX_BYTES` of text;
- UTF-8 (a BOM is accepted);
- nesting at most :data:`MAX_DEPTH` levels, checked while composing (before recursion
  gets deep);
- at most :data:`MAX_NODES` nodes *after* alias expansion, counted on the composed node
  graph in linear time, so anchors and aliases keep working for ordinary reuse;
- no recursive aliases.

Exponent floats without a dot (``1e-9``) are floats, as in YAML 1.2 (YAML 1.1 reads
them as strings, and ``--set world.timestep=1e-9`` then failed as "not a number").
"""

from __future__ import annotations

import re
from typing import Any

import yaml
from yaml.nodes import MappingNode, Node, ScalarNode, SequenceNode

MAX_BYTES = 1 << 20
"""1 MiB: the shipped configs are under 2 kB; a scenario with the most obstacles allowed
(1000) is about 50 kB."""

MAX_DEPTH = 32
"""Nesting levels: the deepest valid key path is three (``obstacles.0.x``)."""

MAX_NODES = 100_000
"""Scalars, sequences and mappings after alias expansion: a scenario at the obstacle
limit has about 11,000."""


class YamlLimitError(ValueError):
    """A YAML document over one of the limits (the message names what and where)."""


_EXPONENT_FLOAT = re.compile(r"^[-+]?(?:[0-9][0-9_]*(?:\.[0-9_]*)?|\.[0-9_]+)[eE][-+]?[0-9]+$")


class _BoundedLoader(yaml.SafeLoader):
    """SafeLoader that bounds nesting depth while composing."""

    def __init__(self, stream: str) -> None:
        super().__init__(stream)
        self._otonav_depth = 0

    def compose_node(self, parent: Node | None, index: int) -> Node | None:
        self._otonav_depth += 1
        try:
            if self._otonav_depth > MAX_DEPTH:
                mark = self.peek_event().start_mark  # type: ignore[no-untyped-call]
                raise YamlLimitError(
                    f"nested deeper than {MAX_DEPTH} levels at line {mark.line + 1}, "
                    f"column {mark.column + 1}"
                )
            return super().compose_node(parent, index)
        finally:
            self._otonav_depth -= 1

    def construct_mapping(self, node: MappingNode, deep: bool = False) -> dict[Any, Any]:
        """A key given twice is an error (YAML says keys are unique; PyYAML let the last
        one win silently, issue 27). Merge keys (``<<``) may still be overridden."""
        first: dict[str, Node] = {}
        for key_node, _value in node.value:
            if not isinstance(key_node, ScalarNode) or key_node.tag == "tag:yaml.org,2002:merge":
                continue
            seen = first.setdefault(key_node.value, key_node)
            if seen is not key_node:
                raise YamlLimitError(
                    f"the key {key_node.value!r} is given twice (line {seen.start_mark.line + 1} "
                    f"and line {key_node.start_mark.line + 1}); keep one"
                )
        return super().construct_mapping(node, deep=deep)


_BoundedLoader.add_implicit_resolver(
    "tag:yaml.org,2002:float", _EXPONENT_FLOAT, list("-+0123456789.")
)


def _check_expansion(root: Node) -> None:
    """Count the nodes and the nesting of the document once every alias is expanded,
    memoised per node: linear in the composed graph, and the recursion here stays as
    shallow as the text (an anchor is always visited before its aliases). Raises on a
    recursive alias, more than :data:`MAX_NODES` nodes or :data:`MAX_DEPTH` levels."""
    known: dict[int, tuple[int, int]] = {}
    active: set[int] = set()

    def where(node: Node) -> str:
        return f"at line {node.start_mark.line + 1}, column {node.start_mark.column + 1}"

    def visit(node: Node) -> tuple[int, int]:
        key = id(node)
        seen = known.get(key)
        if seen is not None:
            return seen
        if key in active:
            raise YamlLimitError(f"a recursive alias {where(node)}")
        active.add(key)
        children: list[Node] = []
        if isinstance(node, SequenceNode):
            children = list(node.value)
        elif isinstance(node, MappingNode):
            children = [part for pair in node.value for part in pair]
        size, depth = 1, 1
        for child in children:
            child_size, child_depth = visit(child)
            size += child_size
            depth = max(depth, child_depth + 1)
        active.discard(key)
        if size > MAX_NODES:
            raise YamlLimitError(
                f"expands to more than {MAX_NODES:,} values (aliases of aliases?) {where(node)}"
            )
        if depth > MAX_DEPTH:
            raise YamlLimitError(
                f"nested deeper than {MAX_DEPTH} levels once aliases are expanded {where(node)}"
            )
        known[key] = (size, depth)
        return size, depth

    visit(root)


def decode(data: bytes) -> str:
    """``data`` as text: at most :data:`MAX_BYTES`, UTF-8 (BOM accepted)."""
    if len(data) > MAX_BYTES:
        raise YamlLimitError(f"larger than {MAX_BYTES // 1024} KiB; a config file is a few kB")
    try:
        return data.decode("utf-8-sig")
    except UnicodeDecodeError as exc:
        raise YamlLimitError(
            f"not UTF-8 text (byte 0x{data[exc.start]:02x} at offset {exc.start}); save it as UTF-8"
        ) from None


def load(text: str) -> Any:
    """Parse one YAML document within the limits above; ``None`` for an empty one.
    Raises :class:`YamlLimitError` or ``yaml.YAMLError``."""
    if len(text) > MAX_BYTES:
        raise YamlLimitError(f"longer than {MAX_BYTES // 1024} KiB of text")
    loader = _BoundedLoader(text)
    try:
        node = loader.get_single_node()
        if node is None:
            return None
        _check_expansion(node)
        return loader.construct_document(node)
    finally:
        loader.dispose()
