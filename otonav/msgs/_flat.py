"""Messages of a fixed layout, made from the few numbers that vary (ADR 0033).

The bridge publishes /clock, /odom, /tf and /imu every 10 ms. Built eagerly, one instant
is 18 nested pydantic objects (an Odometry alone is 11: Header, Time, Pose, Point, ...),
~11 us, and the recorder then reads them back field by field to encode them, ~5 us more.
Yet in the stack nobody walks the nesting: the recorder wants CDR bytes, the safety
layer and the navigator want six numbers of an Odometry.

A :class:`FlatLayout` is a *template* message and the *paths* of the scalar fields that
vary (``header.stamp.sec``, ``pose.pose.position.x``, ``transforms.0.header.stamp.sec``).
``layout(*values)`` makes a message holding only those values (0.25 us). It is an
instance of a subclass of the template's class (``FlatOdometry`` for an Odometry), like
a lazily decoded replay input (:mod:`otonav.replay._lazy`): its first attribute access
of any kind (a field, a method, ``__dict__``, which every pydantic method goes through,
comparison, hashing, ``repr``, pickling, copying) builds the nested objects -- the
template's, with the values in place -- and switches the object's class to the message
class itself. From then on it *is* that message, field for field and type for type
(``type(m) is Odometry``), equal to the eagerly built one (tests check each operation).
Before its first use only ``type(m)`` tells it apart; ``isinstance`` holds throughout.

Three readers use the values without building anything:

- :func:`reader`: the values at some paths, from a flat message's values (or the
  template's constants), or through the attributes of any other message;
- :func:`otonav.record.cdr.encode`: the template's bytes with the values packed in
  place, by one precompiled ``struct.Struct`` per layout (the same bytes as the
  field-by-field encoder: tested with random values, -0.0, NaN, infinities, extremes);
- a publisher's type check (:attr:`FlatMessage.stands_for`).

The template must be an ordinary message (not flat); the values must be of the types
the fields hold (the stack's hot path: nothing is validated per message). A path may also
end at an array of bytes (a ``uint8[n]`` such as a CAN frame's ``data``, a tuple of ints
0..255 in the template): its value is then a ``bytes`` of that length, the message holds
``tuple(value)``, and the CDR packer writes it with one ``{n}s`` item.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from operator import attrgetter
from typing import Any, Generic, TypeVar

from otonav.msgs._base import Message
from otonav.msgs._stand_in import become, get, make, stand_in_class

__all__ = ("FlatLayout", "flat_state", "is_flat", "reader", "real_type")

M = TypeVar("M", bound=Message)

_KEY = "\0flat"
"""Where a flat message keeps ``(layout, values)`` in its ``__dict__``: no field can
have this name, so every field lookup misses and reaches ``__getattribute__``."""

_get, _make, _new = get, make, object.__new__

_FLAT: dict[type[Message], type[Message]] = {}
"""message class -> its flat subclass"""
_REAL: dict[type[Message], type[Message]] = {}
"""flat subclass -> its message class"""


def materialize(message: M) -> M:
    """Build a flat ``message``'s nested objects in place (no-op for any other); returns
    it, now of its message class."""
    real = _REAL.get(type(message))
    if real is None:
        return message
    state = _get(message, "__dict__").get(_KEY)
    if state is None:
        # A copy of an already built one (pydantic's __copy__ builds the copy with
        # type(self), read before the original built itself): it has its fields already.
        become(message, real, None)
        return message
    layout, values = state
    become(message, real, layout._build(values), layout._fields_set)
    return message


def _flat_class(real: type[Message]) -> type[Message]:
    def __getattribute__(self: Message, name: str) -> Any:
        materialize(self)
        return _get(self, name)

    cls = stand_in_class(
        real,
        f"Flat{real.__name__}",
        module=__name__,
        doc=f"A {real.__name__} of a fixed layout: built on first use.",
        getattribute=__getattribute__,
        materialize=materialize,
        stands_for=real,
    )
    _FLAT[real] = cls
    _REAL[cls] = real
    return cls


class FlatLayout(Generic[M]):
    """Messages like ``template`` with the scalar fields at ``paths`` given per message.

    A path is field names (and tuple indices) joined by dots: ``header.stamp.sec``,
    ``transforms.0.transform.translation.x``. Each must end at an ``int``, ``float`` or
    ``bool`` of the template, or at a tuple of ints 0..255 (an array of bytes, given as
    ``bytes`` of its length: :attr:`byte_paths`); no path may be given twice.
    ``layout(*values)`` makes one message, ``values`` in the order of ``paths``.
    """

    __slots__ = (
        "_build",
        "_cls",
        "_fields_set",
        "byte_paths",
        "cdr",
        "message_type",
        "paths",
        "template",
    )

    def __init__(self, template: M, paths: Sequence[str]) -> None:
        if type(template) in _REAL:
            raise TypeError("FlatLayout: the template must be an ordinary message, not a flat one")
        self.template = template
        self.message_type: type[M] = type(template)
        self.paths = tuple(paths)
        tree = _tree(self.paths)
        byte_paths: list[int] = []
        for i, path in enumerate(self.paths):
            leaf = _resolve(template, path)
            if isinstance(leaf, tuple) and all(
                type(item) is int and 0 <= item <= 255 for item in leaf
            ):
                byte_paths.append(i)
            elif not isinstance(leaf, int | float):
                raise ValueError(
                    f"FlatLayout of {self.message_type.__name__}: '{path}' is a "
                    f"{type(leaf).__name__}; a path must end at an int, float or bool "
                    "field, or at an array of bytes (a tuple of ints 0..255)"
                )
        self.byte_paths: frozenset[int] = frozenset(byte_paths)
        """Indices of the values that are ``bytes`` (the message holds them as tuples)."""
        self._build = _compile_builder(template, tree, self.byte_paths)
        self._cls = _FLAT.get(self.message_type) or _flat_class(self.message_type)
        self._fields_set = template.model_fields_set
        self.cdr: Callable[..., bytes] | None = None
        """Its CDR packer: set by :mod:`otonav.record.cdr` the first time it encodes one."""

    def __call__(self, *values: Any) -> M:
        """A message of this layout with ``values`` at ``paths`` (not checked)."""
        message: M = _new(self._cls)  # type: ignore[assignment]  # its flat subclass
        # Its pydantic state comes when it is built (materialize): until then every access
        # goes through its __getattribute__, and its own __dict__ (made on first touch)
        # holds only this. 0.15 us, against 0.55 with the state set now.
        _get(message, "__dict__")[_KEY] = (self, values)
        return message

    def index(self, path: str) -> int:
        """The position of ``path`` in :attr:`paths`."""
        return self.paths.index(path)

    def constant(self, path: str) -> Any:
        """The template's value at ``path`` (a field the layout does not vary)."""
        return _resolve(self.template, path)

    def __repr__(self) -> str:
        return f"FlatLayout({self.message_type.__name__}, {self.paths!r})"


def is_flat(message: object) -> bool:
    """Whether ``message`` is a flat message whose nested objects are not built yet."""
    return type(message) in _REAL and _KEY in _get(message, "__dict__")


def flat_state(message: object) -> tuple[FlatLayout[Any], tuple[Any, ...]] | None:
    """``(layout, values)`` of a flat message not built yet; None for any other."""
    if type(message) not in _REAL:
        return None
    state: tuple[FlatLayout[Any], tuple[Any, ...]] | None = _get(message, "__dict__").get(_KEY)
    return state


def real_type(cls: type[M]) -> type[M]:
    """The message class a flat class stands for; any other class itself."""
    real: type[M] = _REAL.get(cls, cls)  # type: ignore[assignment]
    return real


def reader(message_type: type[M], *paths: str) -> Callable[[M], tuple[Any, ...]]:
    """A function giving the values at ``paths`` of a ``message_type`` message, as a
    tuple: from a flat message's values and its template (nothing built), from any
    other message through its attributes. The same values either way: a path that
    holds varying values (``header.stamp`` of a layout that varies its ``sec``) or lies
    inside one is read from the built message."""
    if not paths:
        raise ValueError("reader: name at least one path")
    get = attrgetter(*paths)

    def through_attributes(m: Any) -> tuple[Any, ...]:
        return (get(m),) if len(paths) == 1 else get(m)

    picks: dict[FlatLayout[Any], Callable[[tuple[Any, ...]], tuple[Any, ...] | None]] = {}

    def pick_for(
        layout: FlatLayout[Any],
    ) -> Callable[[tuple[Any, ...]], tuple[Any, ...] | None]:
        names: dict[str, object] = {}
        parts = []
        for path in paths:
            if path not in layout.paths and any(
                varying.startswith(f"{path}.") or path.startswith(f"{varying}.")
                for varying in layout.paths
            ):
                picks[layout] = _no_pick
                return _no_pick
            if path in layout.paths:
                i = layout.paths.index(path)
                parts.append(f"tuple(v[{i}])" if i in layout.byte_paths else f"v[{i}]")
            else:
                name = f"_c{len(names)}"
                names[name] = layout.constant(path)
                parts.append(name)
        pick: Callable[[tuple[Any, ...]], tuple[Any, ...]] = eval(  # our own paths only
            f"lambda v: ({', '.join(parts)},)", names
        )
        picks[layout] = pick
        return pick

    def read(message: M) -> tuple[Any, ...]:
        if type(message) in _REAL:
            state = _get(message, "__dict__").get(_KEY)
            if state is not None:
                layout, values = state
                picked = (picks.get(layout) or pick_for(layout))(values)
                if picked is not None:
                    return picked
        result: tuple[Any, ...] = through_attributes(message)
        return result

    return read


def _no_pick(values: tuple[Any, ...]) -> None:
    """A reader's pick for a layout whose values it cannot take apart: read the built
    message instead."""
    return None


# -- building ----------------------------------------------------------------------------

_Tree = dict[str, "int | _Tree"]


def _tree(paths: Sequence[str]) -> _Tree:
    """The paths as a tree of names; a leaf holds the value's index."""
    root: _Tree = {}
    for i, path in enumerate(paths):
        node = root
        *parents, last = path.split(".")
        for name in parents:
            child = node.setdefault(name, {})
            if not isinstance(child, dict):
                raise ValueError(f"FlatLayout: '{path}' is inside '{paths[child]}', a number")
            node = child
        if last in node:
            raise ValueError(f"FlatLayout: '{path}' is given twice or has paths inside it")
        node[last] = i
    return root


def _resolve(value: Any, path: str) -> Any:
    """The value at ``path`` inside ``value`` (a message or a tuple)."""
    for name in path.split("."):
        if isinstance(value, tuple):
            if not name.isdigit() or int(name) >= len(value):
                raise ValueError(f"FlatLayout: no element '{name}' of {len(value)} in '{path}'")
            value = value[int(name)]
        elif isinstance(value, Message):
            if name not in type(value).model_fields:
                raise ValueError(
                    f"FlatLayout: {type(value).__name__} has no field '{name}' (path '{path}')"
                )
            value = getattr(value, name)
        else:
            raise ValueError(f"FlatLayout: '{path}' goes inside a {type(value).__name__}")
    return value


def _compile_builder(
    template: Message, tree: _Tree, byte_paths: frozenset[int]
) -> Callable[[tuple[Any, ...]], dict[str, Any]]:
    """One generated function: the template's top-level field dict with the nested
    objects on each path rebuilt around the values (``v[i]``, ``tuple(v[i])`` for an
    array of bytes); every other subtree is the template's own (frozen) object, shared."""
    names: dict[str, object] = {"_make": _make}

    def leaf(i: int) -> str:
        return f"tuple(v[{i}])" if i in byte_paths else f"v[{i}]"

    def const(value: object) -> str:
        name = f"_k{len(names)}"
        names[name] = value
        return name

    def code(value: Any, sub: int | _Tree | None) -> str:
        """The value unchanged (the template's), a leaf's value, or a subtree rebuilt."""
        if sub is None:
            return const(value)
        return leaf(sub) if isinstance(sub, int) else expr(value, sub)

    def fields(message: Message, node: _Tree) -> str:
        parts = [
            f"{name!r}: {code(value, node.get(name))}"
            for name, value in ((n, getattr(message, n)) for n in type(message).model_fields)
        ]
        return "{" + ", ".join(parts) + "}"

    def expr(value: Any, node: _Tree) -> str:
        if isinstance(value, tuple):
            items = [code(item, node.get(str(i))) for i, item in enumerate(value)]
            return "(" + "".join(f"{item}, " for item in items) + ")"
        cls = const(type(value))
        fields_set = const(value.model_fields_set)
        return f"_make({cls}, {fields(value, node)}, {fields_set})"

    source = f"lambda v: {fields(template, tree)}"
    build: Callable[[tuple[Any, ...]], dict[str, Any]] = eval(source, names)  # our paths only
    return build
