"""A small XML tree that remembers line numbers, and typed attribute readers.

ElementTree forgets where an element was; error messages must name the file and the line,
so the tree is built here from expat directly. Free text inside elements (Kautham's files
have plenty) is kept but never needed.

Every XML file the GUI reads (problems, robots, URDF, control and path files) comes through
here, and any of them may come from someone else, so the parser is hardened as defusedxml
hardens expat: a DTD may not declare entities (a "billion laughs" file expands a few lines
into gigabytes; Kautham's files declare none), external entities and parameter entities are
never resolved (an external entity would read another file, or a URL, into the problem), and
a file larger than odin_common.limits.MAX_INPUT_FILE_MB is refused before it is read.

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

from gui.core.sizes import check_file_size
from gui.errors import ProblemError


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
        what = f"<{self.tag} {name}=\"{raw}\">"
        try:
            return parse_number(raw, what, self.path, self.line)
        except ProblemError:
            leading = _LEADING_NUMBER.match(raw) if self.lenient is not None else None
            if leading is None or not math.isfinite(float(leading.group())):
                raise
        value = float(leading.group())
        self.lenient.append(LenientNumber(self.path, self.line, what, value))
        return value

    def flag(self, name: str, default: bool) -> bool:
        raw = self.get(name)
        if raw is None:
            return default
        low = raw.strip().lower()
        if low in ("true", "1", "yes"):
            return True
        if low in ("false", "0", "no"):
            return False
        raise self.error(f"<{self.tag} {name}=\"{raw}\"> is not true or false")

    def numbers(self, name: str, count: int, default: Optional[tuple] = None) -> tuple:
        """A space-separated vector attribute (URDF's xyz="0 0 1")."""
        raw = self.get(name)
        if raw is None:
            if default is None:
                raise self.error(f"<{self.tag}> has no attribute {name}=")
            return default
        parts = raw.split()
        if len(parts) != count:
            raise self.error(f"<{self.tag} {name}=\"{raw}\"> needs {count} numbers")
        return tuple(parse_number(p, f"<{self.tag} {name}=\"{raw}\">", self.path, self.line)
                     for p in parts)


def parse_number(raw: str, what: str, path: Optional[str], line: Optional[int]) -> float:
    try:
        value = float(raw.strip())
    except ValueError:
        raise ProblemError(f"{what}: {raw.strip()!r} is not a number", path, line) from None
    if not math.isfinite(value):
        raise ProblemError(f"{what}: {raw.strip()!r} is not finite", path, line)
    return value


def read_xml(path: os.PathLike | str, what: str = "file",
             lenient: Optional[list] = None) -> Node:
    """Parses ``path`` into a ``Node`` tree; a missing or malformed file is a ``ProblemError``
    naming the file and (for malformed XML) the line. ``lenient``: a list to record
    ``LenientNumber`` readings in (module docstring); None: numbers are strict."""
    p = pathlib.Path(path)
    check_file_size(p, what, ProblemError)
    try:
        data = p.read_bytes()
    except FileNotFoundError:
        raise ProblemError(f"{what} not found", p) from None
    except OSError as error:
        raise ProblemError(f"{what} cannot be read: {error.strerror}", p) from None
    return parse_xml_bytes(data, str(p), lenient)


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


def parse_xml_bytes(data: bytes, path: str, lenient: Optional[list] = None) -> Node:
    parser = xml.parsers.expat.ParserCreate()
    _harden(parser)
    stack: list[Node] = []
    root: list[Node] = []

    def start(tag, attrib):
        node = Node(tag, dict(attrib), parser.CurrentLineNumber, path, lenient=lenient)
        if stack:
            stack[-1].children.append(node)
        else:
            root.append(node)
        stack.append(node)

    def end(tag):
        stack.pop()

    def text(data_):
        if stack:
            stack[-1].text += data_

    parser.StartElementHandler = start
    parser.EndElementHandler = end
    parser.CharacterDataHandler = text
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
    if not root:
        raise ProblemError("no XML element", path)
    return root[0]
