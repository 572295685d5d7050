"""Reading BehaviorTree.CPP XML as leniently as BT.CPP's tinyxml2 does.

BT.CPP accepts raw ``<``, ``>`` and ``&`` inside attribute values (``_skipIf="A<2"``, ``code="a && b"``)
and keeps newlines inside attribute values. A strict XML parser rejects the first and turns the second
into spaces, so the text goes through a pre-pass that escapes those characters inside quoted attribute
values, without changing the number of lines, before lxml parses it. Element line numbers
(``element.sourceline``) therefore match the original file.
"""

from __future__ import annotations

import re
from pathlib import Path

from lxml import etree

from kinema.errors import ObjectiveError, SourceLocation

# Marks a newline inside an attribute value during parsing (a private-use code point, so it never
# occurs in real files); the newline itself stays in the text so line numbers do not shift.
_NEWLINE_MARK = "\ue000"
_KNOWN_ENTITY = re.compile(r"&(?:amp|lt|gt|quot|apos|#[0-9]+|#x[0-9a-fA-F]+);")
MAX_DEPTH = 256


def _escape_ampersand(text: str, index: int) -> str:
    return "&" if _KNOWN_ENTITY.match(text, index) else "&amp;"


def make_strict(text: str) -> str:
    """Return ``text`` with attribute values escaped so a strict XML parser accepts it.

    The result has exactly as many newlines as ``text``, at the same places outside attribute values.
    """
    text = text.replace("\r\n", "\n").replace("\r", "\n")
    out: list[str] = []
    i = 0
    n = len(text)
    while i < n:
        c = text[i]
        if c != "<":
            out.append(_escape_ampersand(text, i) if c == "&" else c)
            i += 1
            continue
        for opener, closer in (("<!--", "-->"), ("<![CDATA[", "]]>"), ("<?", "?>"), ("<!", ">")):
            if text.startswith(opener, i):
                end = text.find(closer, i + len(opener))
                end = n if end < 0 else end + len(closer)
                out.append(text[i:end])
                i = end
                break
        else:
            i = _copy_tag(text, i, out)
    return "".join(out)


def _copy_tag(text: str, i: int, out: list[str]) -> int:
    """Copy one start or end tag starting at ``text[i] == '<'``, escaping inside quoted values."""
    n = len(text)
    out.append("<")
    i += 1
    quote: str | None = None
    while i < n:
        c = text[i]
        if quote is None:
            out.append(c)
            i += 1
            if c in "\"'":
                quote = c
            elif c == ">":
                return i
            continue
        if c == quote:
            quote = None
            out.append(c)
        elif c == "<":
            out.append("&lt;")
        elif c == ">":
            out.append("&gt;")
        elif c == "&":
            out.append(_escape_ampersand(text, i))
        elif c == "\n":
            # The parser turns this newline into a space; the mark before it says to restore it.
            out.append(_NEWLINE_MARK + "\n")
        elif c == "\t":
            out.append("&#9;")
        else:
            out.append(c)
        i += 1
    return i


def _restore_newlines(root: etree._Element) -> None:
    for element in root.iter():
        for key, value in element.attrib.items():
            if _NEWLINE_MARK in value:
                element.attrib[key] = value.replace(_NEWLINE_MARK + " ", "\n")


def parse_xml(text: str | bytes, filename: str = "<string>") -> etree._Element:
    """Parse BT.CPP XML text leniently and return the root element.

    Raises:
        ObjectiveError: the text is not XML even for BT.CPP, or nests deeper than 256 elements;
            the message carries ``filename:line``.
    """
    if isinstance(text, bytes):
        try:
            text = text.decode("utf-8-sig")
        except UnicodeDecodeError as error:
            raise ObjectiveError(
                f"the file is not UTF-8 (byte {error.start}: {error.reason})",
                location=SourceLocation(filename),
            ) from None
    elif text.startswith("\ufeff"):
        text = text[1:]
    strict = make_strict(text)
    parser = etree.XMLParser(remove_blank_text=False, resolve_entities=False, huge_tree=False)
    try:
        root = etree.fromstring(strict.encode("utf-8"), parser=parser)
    except etree.XMLSyntaxError as error:
        line = error.lineno or 0
        message = str(error.msg or error).split(", line")[0]
        if "Excessive depth" in message:
            # libxml2's own nesting guard fires first; say what BT.CPP would say.
            message = f"elements nest deeper than {MAX_DEPTH} levels"
        raise ObjectiveError(
            f"XML syntax error: {message}", location=SourceLocation(filename, line)
        ) from None
    if root is None:
        raise ObjectiveError("the XML document is empty", location=SourceLocation(filename))
    _check_depth(root, filename)
    _restore_newlines(root)
    return root


def _check_depth(root: etree._Element, filename: str) -> None:
    stack = [(root, 1)]
    while stack:
        element, depth = stack.pop()
        if depth > MAX_DEPTH:
            raise ObjectiveError(
                f"elements nest deeper than {MAX_DEPTH} levels",
                location=SourceLocation(filename, element.sourceline or 0),
            )
        stack.extend((child, depth + 1) for child in element if isinstance(child.tag, str))


def parse_xml_file(path: str | Path) -> etree._Element:
    """Read and parse an XML file leniently; errors name the file and line."""
    path = Path(path)
    try:
        data = path.read_bytes()
    except OSError as error:
        raise ObjectiveError(
            f"cannot read the file: {error.strerror}", location=SourceLocation(str(path))
        ) from None
    return parse_xml(data, str(path))
