"""Edit a block's items in place, for words `edit_words` cannot spell (`IX+5`, `CR=5`, `X=AC(1)`)."""

from __future__ import annotations

from collections.abc import Mapping

from ncpp.program.blocks import Block, Item
from ncpp.program.writer import _leads, _past_blanks


def splice(block: Block, texts: Mapping[int, str | None], append: str = "", after: Item | None = None) -> str:
    """The raw text of `block` with the item at each index of `texts` replaced by
    its text (None: removed with the blanks before it, or after it when it leads the
    block), and `append` inserted after the item `after` (default: the last item
    that is not a comment)."""
    raw = block.raw
    anchor = after
    if anchor is None and append:
        anchor = next((i for i in reversed(block.items) if type(i).__name__ != "Comment"), None)
    pieces: list[str] = []
    cursor = 0
    for index, item in enumerate(block.items):
        if index in texts:
            before = raw[cursor : item.start]
            text = texts[index]
            cursor = item.end
            if text is None and _leads(pieces, before):  # no separator before it: the one after it goes
                cursor = _past_blanks(raw, item.end)
            elif text is None:
                before = before.rstrip(" \t")
            pieces.append(before + (text or ""))
        else:
            pieces.append(raw[cursor : item.end])
            cursor = item.end
        if item is anchor:
            pieces.append(append)
    if append and anchor is None:
        pieces.append(append)
    return "".join(pieces) + raw[cursor:]
