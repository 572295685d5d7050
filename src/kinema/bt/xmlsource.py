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
_ENTITY = r"(?:amp|lt|gt|quot|apos|#[0-9]+|#x[0-9a-fA-F]+);"
MAX_DEPTH = 256

# The pre-pass works on runs, not characters: most of a file is text, comments and tags whose quoted
# values need no escaping, and one regex match copies such a run unchanged. Possessive quantifiers keep
# every pattern linear (no backtracking on unterminated tags or quotes).
# A quoted value that needs no escaping: no raw '<', '>', tab or newline, and '&' only as an entity.
_CLEAN_VALUE = r"""(?:"(?:[^"<>&\n\t]++|&(?=ENTITY))*+"|'(?:[^'<>&\n\t]++|&(?=ENTITY))*+')""".replace(
    "ENTITY", _ENTITY
)
_UNCHANGED = re.compile(
    r"(?:[^<&]++|&(?=" + _ENTITY + r")"
    r"|<!--.*?(?:-->|\Z)|<!\[CDATA\[.*?(?:\]\]>|\Z)|<\?.*?(?:\?>|\Z)|<!.*?(?:>|\Z)"
    r"""|<(?:[^"'>]++|""" + _CLEAN_VALUE + r""")*+>)++""",
    re.S,
)
# Something that may be an attribute value holding a newline or tab (a strict parser would turn those
# into spaces). It finds every such value; a false hit (in a comment or text) only costs the pre-pass.
_VALUE_WITH_BREAK = re.compile(r"""=[ \t\n]*+(?:"[^"]*[\n\t]|'[^']*[\n\t])""")
# A start or end tag up to its first '>' outside quotes; an unterminated quote runs to the end of the text.
_TAG = re.compile(r"""<(?:[^"'>]++|"[^"]*+(?:"|\Z)|'[^']*+(?:'|\Z))*+>?""")
_QUOTED = re.compile(r""""[^"]*+(?:"|\Z)|'[^']*+(?:'|\Z)""")
_LONE_AMPERSAND = re.compile(r"&(?!" + _ENTITY + ")")
_SPECIAL_IN_VALUE = re.compile(r"[<>\n\t]")
# A newline in a value would become a space; the mark before it says to restore it.
_VALUE_ESCAPES = {"<": "&lt;", ">": "&gt;", "\n": _NEWLINE_MARK + "\n", "\t": "&#9;"}


def make_strict(text: str) -> str:
    """Return ``text`` with attribute values escaped so a strict XML parser accepts it.

    The result has exactly as many newlines as ``text``, at the same places outside attribute values.
    """
    text = text.replace("\r\n", "\n").replace("\r", "\n")
    out: list[str] = []
    position, end = 0, len(text)
    while position < end:
        unchanged = _UNCHANGED.match(text, position)
        if unchanged is not None:
            out.append(unchanged.group())
            position = unchanged.end()
        elif text[position] == "&":
            out.append("&amp;")
            position += 1
        else:
            tag = _TAG.match(text, position)
            assert tag is not None  # text[position] == "<" always starts a tag
            out.append(_QUOTED.sub(_escape_value, tag.group()))
            position = tag.end()
    return "".join(out)


def _escape_value(match: re.Match[str]) -> str:
    value = match.group()
    body = _LONE_AMPERSAND.sub("&amp;", value[1:])
    return value[0] + _SPECIAL_IN_VALUE.sub(lambda special: _VALUE_ESCAPES[special.group()], body)


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
    parser = etree.XMLParser(remove_blank_text=False, resolve_entities=False, huge_tree=False)
    root = None
    strict = text
    breaks = "\n" in text or "\t" in text  # (no value can hold one if the text holds none)
    if "\r" not in text and (not breaks or _VALUE_WITH_BREAK.search(text) is None):
        # Most files are strict XML already, and where no attribute value holds a newline or tab,
        # lxml reads them exactly as it reads the pre-pass's output: skip the pre-pass (a third
        # of the parse) unless lxml refuses the text.
        try:
            root = etree.fromstring(text.encode("utf-8"), parser=parser)
        except etree.XMLSyntaxError:
            root = None
    if root is None:
        strict = make_strict(text)
        root = _parse_strict(strict, filename, parser)
    if root is None:
        raise ObjectiveError("the XML document is empty", location=SourceLocation(filename))
    # Both walks visit every element in Python; skip them when they cannot find anything (most files).
    if strict.count("<") > MAX_DEPTH:
        _check_depth(root, filename)
    if _NEWLINE_MARK in strict:
        _restore_newlines(root)
    return root


_TAG_MISMATCH = re.compile(r"Opening and ending tag mismatch: (\S+) line (\d+) and (\S+)")


def _parse_strict(strict: str, filename: str, parser: etree.XMLParser) -> etree._Element | None:
    try:
        return etree.fromstring(strict.encode("utf-8"), parser=parser)
    except etree.XMLSyntaxError as error:
        line = error.lineno or 0
        message = str(error.msg or error).split(", line")[0]
        if "Excessive depth" in message:
            # libxml2's own nesting guard fires first; say what BT.CPP would say.
            message = f"elements nest deeper than {MAX_DEPTH} levels"
        mismatch = _TAG_MISMATCH.fullmatch(message)
        if mismatch is not None:
            # libxml2's "Sequence line 3 and BehaviorTree" read as two lines in one message (the one at
            # the start of the message is where the closing tag is).
            opened, opened_line, closing = mismatch.groups()
            message = (
                f"</{closing}> here, while <{opened}> of line {opened_line} is still open: its closing tag "
                "is missing or misspelt"
            )
        raise ObjectiveError(
            f"XML syntax error: {message}", location=SourceLocation(filename, line)
        ) from None


def _check_depth(root: etree._Element, filename: str) -> None:
    # libxml2 answers "is any element deeper than MAX_DEPTH?" without a Python step per element;
    # only a document that has one is walked, to name the first such element in walk order.
    if not root.xpath("/*" * (MAX_DEPTH + 1)):
        return
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
