"""A small XML tree that remembers line numbers, and typed attribute readers.

ElementTree forgets where an element was; error messages must name the file and the line,
so the tree is built here from expat directly. Free text inside elements (Kautham's files
have plenty) is kept but never needed.

Every XML file the GUI reads (problems, robots, URDF, control and path files) comes through
here, and any of them may come from someone else, so the parser is hardened as defusedxml
hardens expat: a DTD may not declare entities (a "billion laughs" file expands a few lines
into gigabytes; Kautham's files declare none), external entities and parameter entities are
never resolved (an external entity would read another file, or a URL, into the problem), a
file is read by ``gui.core.sizes.read_input_file`` (a regular file of at most
odin_common.limits.MAX_INPUT_FILE_MB, opened once), and the tree is bounded while it is built:
at most MAX_XML_ELEMENTS elements, MAX_XML_DEPTH deep, MAX_XML_ATTRIBUTES attributes on one
element, names of at most MAX_NAME_BYTES (odin_common.limits). A node of the tree costs a few
hundred bytes, so 200 MB of empty elements would need gigabytes: the parse stops at the first
element past a bound, having built a bounded tree.

Numbers: a malformed number is an error naming the file and line, except in a tree read with
``lenient`` (URDF files): there a value that starts with a number ("0.46 5") is read as that
leading number, as Kautham reads it (pugixml's ``as_double`` and ``atof`` are C's ``strtod``:
they stop at the first character that cannot continue the number), and each such reading is
recorded in the ``lenient`` list as a ``LenientNumber`` for the caller to warn about. A value
that does not start with a number is an error there too (C would read it as 0, silently).
"""
from __future__ import annotations

import math
import os
import pathlib
import re
import xml.parsers.expat
from dataclasses import dataclass, field
from typing import Iterator, Optional

import numpy as np

from gui.core.kautham.units import lengths_problem
from gui.core.sizes import read_input_file
from gui.errors import ProblemError
from odin_common.limits import (MAX_NAME_BYTES, MAX_SHOWN_CHARS, MAX_XML_ATTRIBUTES,
                                MAX_XML_DEPTH, MAX_XML_ELEMENTS, shown)


_LEADING_NUMBER = re.compile(r"\s*[+-]?(\d+\.?\d*|\.\d+)([eE][+-]?\d+)?")
"""The longest prefix C's strtod reads as a decimal number."""


@dataclass(frozen=True)
class LenientNumber:
    """A malformed number read as its leading number (module docstring)."""
    path: str
    line: int
    what: str          # the attribute as written: <inertia ixx="0.46 5">
    value: float       # what was read


@dataclass
class Node:
    """One XML element: tag, attributes, children, text, and its 1-based line. ``lenient``:
    the list that records lenient readings of the tree's numbers (None: numbers are strict)."""
    tag: str
    attrib: dict
    line: int
    path: str
    children: list = field(default_factory=list)
    text: str = ""
    lenient: Optional[list] = field(default=None, repr=False)

    def find(self, tag: str) -> Optional["Node"]:
        """The first child called ``tag`` (case-insensitive, as Kautham's readers are)."""
        low = tag.lower()
        for child in self.children:
            if child.tag.lower() == low:
                return child
        return None

    def findall(self, tag: str) -> Iterator["Node"]:
        low = tag.lower()
        return (child for child in self.children if child.tag.lower() == low)

    def get(self, name: str, default: Optional[str] = None) -> Optional[str]:
        if name in self.attrib:
            return self.attrib[name]
        low = name.lower()
        for key, value in self.attrib.items():
            if key.lower() == low:
                return value
        return default

    def error(self, reason: str) -> ProblemError:
        return ProblemError(reason, self.path, self.line)

    def require(self, name: str) -> str:
        value = self.get(name)
        if value is None:
            raise self.error(f"<{self.tag}> has no attribute {name}=")
        return value

    def number(self, name: str, default: Optional[float] = None) -> float:
        """The attribute as a finite float; a missing one gives ``default`` (or an error
        when no default is given); a malformed one ("0.01.0") is always an error."""
        raw = self.get(name)
        if raw is None:
            if default is None:
                raise self.error(f"<{self.tag}> has no attribute {name}=")
            return default
        what = f"<{self.tag} {name}=\"{cut(raw)}\">"
        try:
            return parse_number(raw, what, self.path, self.line)
        except ProblemError:
            leading = _LEADING_NUMBER.match(raw) if self.lenient is not None else None
            if leading is None or not math.isfinite(float(leading.group())):
                raise
        value = float(leading.group())
        self.lenient.append(LenientNumber(self.path, self.line, what, value))
        return value

    def scaled_lengths(self, what: str, values, scale: float = 1.0,
                       unit: str = "m") -> np.ndarray:
        """``values`` (file units) times ``scale`` (``unit`` per file unit) as an array, or
        an error naming ``what`` (the attributes) when one is not finite or reaches past the
        largest world (gui.core.kautham.units.lengths_problem)."""
        problem = lengths_problem(values, scale, unit)
        if problem is not None:
            raise self.error(f"{what} times the scale {scale:g} {problem}")
        return np.asarray(values, dtype=float) * scale

    def flag(self, name: str, default: bool) -> bool:
        raw = self.get(name)
        if raw is None:
            return default
        low = raw.strip().lower()
        if low in ("true", "1", "yes"):
            return True
        if low in ("false", "0", "no"):
            return False
        raise self.error(f"<{self.tag} {name}=\"{cut(raw)}\"> is not true or false")

    def numbers(self, name: str, count: int, default: Optional[tuple] = None) -> tuple:
        """A space-separated vector attribute (URDF's xyz="0 0 1")."""
        raw = self.get(name)
        if raw is None:
            if default is None:
                raise self.error(f"<{self.tag}> has no attribute {name}=")
            return default
        parts = raw.split()
        if len(parts) != count:
            raise self.error(f"<{self.tag} {name}=\"{cut(raw)}\"> needs {count} numbers")
        return tuple(parse_number(p, f"<{self.tag} {name}=\"{cut(raw)}\">", self.path,
                                  self.line) for p in parts)


def cut(raw: str) -> str:
    """An attribute's text as written, for an error message: cut to MAX_SHOWN_CHARS (saying
    how long it was), so that a huge value never makes a huge message."""
    if len(raw) <= MAX_SHOWN_CHARS:
        return raw
    return f"{raw[:MAX_SHOWN_CHARS - 1]}… ({len(raw):,} characters)"


def parse_number(raw: str, what: str, path: Optional[str], line: Optional[int]) -> float:
    try:
        value = float(raw.strip())
    except ValueError:
        raise ProblemError(f"{what}: {shown(raw.strip())} is not a number", path,
                           line) from None
    if not math.isfinite(value):
        raise ProblemError(f"{what}: {shown(raw.strip())} is not finite", path, line)
    return value


def read_xml(path: os.PathLike | str, what: str = "file",
             lenient: Optional[list] = None) -> Node:
    """Parses ``path`` into a ``Node`` tree; a missing, unreadable or malformed file is a
    ``ProblemError`` naming the file and (for malformed XML) the line. ``lenient``: a list to
    record ``LenientNumber`` readings in (module docstring); None: numbers are strict."""
    p = pathlib.Path(path)
    return parse_xml_bytes(read_input_file(p, what, ProblemError), str(p), lenient)


class _Refused(Exception):
    """Raised inside an expat handler; carries the line where the parse was refused."""

    def __init__(self, reason: str, line: int):
        super().__init__(reason)
        self.reason, self.line = reason, line


def _harden(parser) -> None:
    """Entity declarations refused, external and parameter entities never read."""
    def entity_declared(name, is_parameter, *_rest):
        kind = "parameter entity" if is_parameter else "entity"
        raise _Refused(f"declares the {kind} {name!r}: XML entities are refused (they can "
                       f"expand without bound or read other files)", parser.CurrentLineNumber)

    def unparsed_entity(name, *_rest):
        raise _Refused(f"declares the unparsed entity {name!r}: XML entities are refused",
                       parser.CurrentLineNumber)

    def external_reference(_context, _base, system_id, _public_id):
        raise _Refused(f"refers to the external entity {system_id!r}: external entities "
                       f"are never read", parser.CurrentLineNumber)

    parser.SetParamEntityParsing(xml.parsers.expat.XML_PARAM_ENTITY_PARSING_NEVER)
    parser.EntityDeclHandler = entity_declared
    parser.UnparsedEntityDeclHandler = unparsed_entity
    parser.ExternalEntityRefHandler = external_reference


def _bounds(parser, depth: int, elements: int, attributes: int) -> None:
    """Raises _Refused when an element opened at ``depth`` (1: the root), the ``elements``-th
    of the file, with ``attributes`` attributes, goes past a bound of the tree."""
    for value, bound, name, what in (
            (elements, MAX_XML_ELEMENTS, "MAX_XML_ELEMENTS", "elements"),
            (depth, MAX_XML_DEPTH, "MAX_XML_DEPTH", "levels of nested elements"),
            (attributes, MAX_XML_ATTRIBUTES, "MAX_XML_ATTRIBUTES", "attributes on one element")):
        if value > bound:
            raise _Refused(f"holds more than {bound:,} {what} (odin_common.limits.{name})",
                           parser.CurrentLineNumber)


def _check_names(parser, tag: str, attrib: dict) -> None:
    """Raises _Refused for an element or attribute name longer than MAX_NAME_BYTES: names
    are quoted in warnings and in what the tools print (Kautham's: a few dozen bytes)."""
    for name in (tag, *attrib):
        if len(name) > MAX_NAME_BYTES // 4 and len(name.encode("utf-8")) > MAX_NAME_BYTES:
            raise _Refused(f"has an element or attribute name of {len(name):,} characters "
                           f"{shown(name)}, longer than {MAX_NAME_BYTES} bytes "
                           f"(odin_common.limits.MAX_NAME_BYTES)", parser.CurrentLineNumber)


def parse_xml_bytes(data: bytes, path: str, lenient: Optional[list] = None) -> Node:
    """Parses an XML file's bytes (``path`` names it in errors) into a bounded ``Node`` tree
    (module docstring); raises ``ProblemError`` naming the file and line."""
    parser = xml.parsers.expat.ParserCreate()
    _harden(parser)
    stack: list[Node] = []
    texts: list[list] = []          # per open element, its text's pieces (joined at its end)
    root: list[Node] = []
    count = [0]

    def start(tag, attrib):
        count[0] += 1
        _bounds(parser, len(stack) + 1, count[0], len(attrib))
        _check_names(parser, tag, attrib)
        node = Node(tag, dict(attrib), parser.CurrentLineNumber, path, lenient=lenient)
        if stack:
            stack[-1].children.append(node)
        else:
            root.append(node)
        stack.append(node)
        texts.append([])

    def end(tag):
        stack.pop().text = "".join(texts.pop())

    def text(data_):
        if texts:
            texts[-1].append(data_)

    parser.StartElementHandler = start
    parser.EndElementHandler = end
    parser.CharacterDataHandler = text
    _parse(parser, data, path)
    if not root:
        raise ProblemError("no XML element", path)
    return root[0]


def check_xml_bounds(data: bytes, path: str, error=ProblemError) -> None:
    """Raises ``error`` (a ProblemError class) naming ``path`` unless an XML file another
    library will parse (Collada, by lxml) is within the bounds of the module docstring and
    declares no entity; nothing is built (expat counts elements as they start)."""
    parser = xml.parsers.expat.ParserCreate()
    _harden(parser)
    depth, count = [0], [0]

    def start(tag, attrib):
        count[0] += 1
        depth[0] += 1
        _bounds(parser, depth[0], count[0], len(attrib))
        _check_names(parser, tag, attrib)

    def end(_tag):
        depth[0] -= 1

    parser.StartElementHandler = start
    parser.EndElementHandler = end
    try:
        _parse(parser, data, path)
    except ProblemError as refused:
        raise error(refused.reason, path, refused.line) from None


def _parse(parser, data: bytes, path: str) -> None:
    """Runs ``parser`` over ``data``: its errors as ProblemErrors naming ``path``."""
    try:
        parser.Parse(data, True)
    except xml.parsers.expat.ExpatError as error:
        reason = xml.parsers.expat.ErrorString(error.code)
        raise ProblemError(f"malformed XML: {reason} (column {error.offset + 1})", path,
                           error.lineno) from None
    except _Refused as refused:
        raise ProblemError(refused.reason, path, refused.line) from None
    except (LookupError, ValueError) as error:   # an unknown or wrong encoding="..."
        raise ProblemError(f"malformed XML: {error}", path, parser.CurrentLineNumber) from None
