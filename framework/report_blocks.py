"""The blocks a report is made of: sections of text, tables, preformatted and collapsed
text, and PNG images (rendered by :mod:`pointatlas.report`)."""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Union


@dataclass(frozen=True)
class Text:
    text: str


@dataclass(frozen=True)
class Pre:
    text: str


@dataclass(frozen=True)
class Table:
    headers: tuple[str, ...]
    rows: tuple[tuple[str, ...], ...]


@dataclass(frozen=True)
class Image:
    title: str
    png: bytes


@dataclass(frozen=True)
class Details:
    """Collapsed preformatted text (``<details>``): the resolved configuration."""

    summary: str
    text: str


Block = Union[Text, Pre, Table, Image, Details]


@dataclass
class Section:
    heading: str
    blocks: list[Block] = field(default_factory=list)


@dataclass
class Report:
    title: str
    sections: list[Section] = field(default_factory=list)

    def images(self) -> list[Image]:
        return [b for s in self.sections for b in s.blocks if isinstance(b, Image)]
