"""A strict reading of an HTML5 document with :mod:`html.parser`: structure and images."""

from __future__ import annotations

import base64
from html.parser import HTMLParser

VOID = {"meta", "img", "br", "hr", "link", "input", "col", "source", "wbr"}


class StrictHtml(HTMLParser):
    """Records images and text; raises on a closing tag that does not match the open one."""

    def __init__(self) -> None:
        super().__init__(convert_charrefs=True)
        self.open: list[str] = []
        self.doctype = ""
        self.images: list[tuple[str, bytes]] = []  # (MIME type, decoded data)
        self.text: list[str] = []
        self.ids: list[str] = []

    def handle_decl(self, decl: str) -> None:
        self.doctype = decl

    def handle_starttag(self, tag: str, attrs: list[tuple[str, str | None]]) -> None:
        attributes = dict(attrs)
        if "id" in attributes:
            self.ids.append(str(attributes["id"]))
        if tag == "img":
            source = str(attributes["src"])
            header, _, payload = source.partition(",")
            assert header.startswith("data:"), header
            assert header.endswith(";base64"), header
            self.images.append((header[5:-7], base64.b64decode(payload, validate=True)))
        if tag not in VOID:
            self.open.append(tag)

    def handle_endtag(self, tag: str) -> None:
        assert self.open[-1:] == [tag], f"</{tag}> closes <{self.open[-1:]}>"
        self.open.pop()

    def handle_data(self, data: str) -> None:
        self.text.append(data)


def parse_html(text: str) -> StrictHtml:
    """Parse ``text``; assert a doctype and every element closed."""
    parser = StrictHtml()
    parser.feed(text)
    parser.close()
    assert parser.doctype.lower() == "doctype html"
    assert parser.open == [], f"unclosed elements {parser.open}"
    return parser
