"""Layout defects of a typeset PDF, read back with pdfplumber (tests only).

:func:`layout_problems` lists, page by page, every word outside the page, every word in
the bottom margin other than the page number, and every pair of words whose glyphs
overlap beyond what mathematics needs (a sub- or superscript, set smaller, may touch
its base). Each problem names the page and the words, so a failing test says what to
look at.
"""

from __future__ import annotations

from pathlib import Path

import pdfplumber

#: Bottom margin of article.typ (2.4 cm) in points; a word starting below the page
#: height minus this, other than the page number, runs into the footer.
BOTTOM_MARGIN_PT = 2.4 / 2.54 * 72
#: Two glyphs overlap when their common area exceeds this share of the smaller box
#: (kerning and italic overhang stay well below).
OVERLAP_SHARE = 0.3
#: A word this much smaller than its neighbour is a sub- or superscript, which may touch.
SCRIPT_RATIO = 0.85
#: Slack for glyph boxes that touch the page edge or the margin's line, in points.
SLACK_PT = 0.5
#: Typst ends a line's box at its baseline (``text(bottom-edge: "baseline")``), so the
#: glyph boxes of a page's last line hang below the text area by the font's descender:
#: about 0.25 em, 2.6 pt at the article's 10.5 pt. A word whose box ends further down
#: than that has run into the margin.
DESCENDER_PT = 3.0


def _overlap(a: dict, b: dict) -> float:
    """Common area of the boxes of words ``a`` and ``b`` over the smaller box's area."""
    width = min(a["x1"], b["x1"]) - max(a["x0"], b["x0"])
    height = min(a["bottom"], b["bottom"]) - max(a["top"], b["top"])
    if width <= 0 or height <= 0:
        return 0.0
    smaller = min(
        (a["x1"] - a["x0"]) * (a["bottom"] - a["top"]),
        (b["x1"] - b["x0"]) * (b["bottom"] - b["top"]),
    )
    return width * height / smaller if smaller > 0 else 0.0


def _is_maths_pair(a: dict, b: dict) -> bool:
    """A sub- or superscript and its base (sizes differ), or a tall mathematical glyph
    (a radical, a big operator or delimiter: one character, neither letter nor digit)
    whose box reaches into the line above."""
    small, large = sorted((a["size"], b["size"]))
    glyph = any(len(w["text"]) == 1 and not w["text"].isalnum() for w in (a, b))
    return small < SCRIPT_RATIO * large or glyph


def _overlapping(chars: list[dict]) -> list[tuple[dict, dict]]:
    """Pairs of overlapping characters that are not mathematics. Characters, not words:
    pdfplumber joins overprinted text into one word ("exponentexponenthead")."""
    chars = sorted((c for c in chars if c["text"].strip()), key=lambda c: c["top"])
    pairs = []
    for i, a in enumerate(chars):
        for b in chars[i + 1 :]:
            if b["top"] >= a["bottom"]:
                break  # sorted by top: no later character reaches a
            if _overlap(a, b) > OVERLAP_SHARE and not _is_maths_pair(a, b):
                pairs.append((a, b))
    return pairs


def _word_at(words: list[dict], char: dict) -> str:
    """The word whose box holds the centre of ``char`` (the character if none)."""
    x, y = (char["x0"] + char["x1"]) / 2, (char["top"] + char["bottom"]) / 2
    for word in words:
        if word["x0"] <= x <= word["x1"] and word["top"] <= y <= word["bottom"]:
            return word["text"]
    return char["text"]


def _unrotated(obj: dict) -> bool:
    """Everything but characters set at an angle. Rotated text (a figure's slanted tick
    labels) comes out of pdfplumber letter by letter, each letter a word whose upright
    box overlaps its neighbours' (pdfminer even calls 55° upright): not a defect."""
    if obj.get("object_type") != "char":
        return True
    _, b, c, *_ = obj["matrix"]
    return abs(b) < 1e-6 and abs(c) < 1e-6


def page_problems(page, number: int) -> list[str]:
    """The layout problems of one pdfplumber ``page`` (page ``number``, from 1)."""
    words = page.extract_words(extra_attrs=["size"], use_text_flow=False)
    problems = []
    outside = [
        w["text"]
        for w in words
        if w["x0"] < -SLACK_PT
        or w["top"] < -SLACK_PT
        or w["x1"] > page.width + SLACK_PT
        or w["bottom"] > page.height + SLACK_PT
    ]
    if outside:
        problems.append(f"page {number}: words outside the page: {outside}")
    footer = page.height - BOTTOM_MARGIN_PT + DESCENDER_PT
    in_margin = [w["text"] for w in words if w["bottom"] > footer and w["text"] != str(number)]
    if in_margin:
        problems.append(f"page {number}: words in the bottom margin: {in_margin}")
    pairs = _overlapping(page.filter(_unrotated).chars)
    if pairs:
        shown = sorted({f"{_word_at(words, a)!r}/{_word_at(words, b)!r}" for a, b in pairs})
        problems.append(f"page {number}: overprinted words ({len(pairs)} glyphs): {shown}")
    return problems


def layout_problems(path: str | Path) -> list[str]:
    """Every layout problem of the PDF at ``path`` (empty list: none)."""
    with pdfplumber.open(path) as pdf:
        return [
            problem
            for number, page in enumerate(pdf.pages, start=1)
            for problem in page_problems(page, number)
        ]
