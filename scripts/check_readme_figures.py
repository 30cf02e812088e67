#!/usr/bin/env python3
"""Check that every figure a README quotes about results is on the page it links (issue 53).

Usage: python3 scripts/check_readme_figures.py [--root DIR] [--list] [MARKDOWN ...]
       (default: README.md and results/README.md of the repository)

What a figure is. The markdown is read in blocks (a paragraph, a list item, a table row;
fenced and indented code is skipped) and each block in sentences. A figure is
  - a number with a unit (s, ms, us, min, N, mN, N/mm, mm, mm/s, %, kPa, Hz, x, J/m^2, ...;
    in a list or range such as "1 / 3 / 10 mm/s" or "0.5-3 N" every number takes the unit;
    "x 973" and "1.7x" count as unit x),
  - a decimal number (0.080 of the FEM's peak, h^0.51), or
  - a count "N of M" (8 of 12 layer-cases), looked up as that phrase.
Bare integers without a unit (three layers, 246 load steps, Eq. 5) are not figures. Never
figures: link targets and link texts that are paths, inline code, HTML comments, dates and
clock times, version numbers (0.1.0), git hashes, "Eq. 5" / "Table 2" / "Sec. 3.3" / "Fig. 1" /
"seed 001" / "git 6554da2", powers of ten written 10^7, and the settings in ALLOWLIST.

Where a figure must be found:
  1. the results pages linked from its own sentence (or table row); else
  2. the pages a marker `<!-- figures: results/PAGE.md ... -->` on the line before its block
     names; else
  3. for a table row: the results pages of the table's header row, else of the last sentence
     of the paragraph that introduces the table; else
  4. the results pages linked anywhere in its paragraph.
A figure in a block that links no results page at all is reported: it quotes a result
without its page (or it is a setting, which belongs in ALLOWLIST). A link's page is the
markdown file it points to; for a folder its README.md; for another file (a plot, a CSV) the
README.md of its folder or the folder's only .md file (a figure that depends on a link to a
folder with several pages is reported: link the page itself). A results link whose target
does not exist is reported. results/CHANGES.md (history) is never a figure's page.

"Found" means the same number string stands on the page as a number of its own (8.5 is not
found in 8.512, nor 0.08 in 0.080): thousands separators ("1,000") and unicode minus signs
are normalised and a leading "+" is dropped; a figure written with a minus needs the minus
on the page, one without a sign matches either sign.

Exit status 0 when every figure is found, 1 otherwise (each miss named with its file, line,
figure and page), 2 on bad usage. CI: the ctest test docs.readme_figures (tests/CMakeLists.txt);
the self-test is tests/scripts/test_check_readme_figures.py.
"""
from __future__ import annotations

import argparse
import os
import re
import sys
from dataclasses import dataclass, field

# Settings and targets, not results, written "number unit" as the checker normalises them
# (units as in UNITS; us for microseconds). Keep it short: a result belongs on a results page.
ALLOWLIST = {
    "1 ms": "the haptic period: a target, not a measurement",
    "1 kHz": "the haptic rate: a setting",
    "60 Hz": "the view's frame rate: a setting",
    "10 mm/s": "the default scene's insertion speed: a setting",
    "30 mm": "the default scene's target depth: a setting",
}

# Results files that hold no current figure (history): a link to one is checked for
# existence only. Paths relative to the repository root.
NOT_FIGURE_PAGES = {"results/CHANGES.md"}

UNITS = [   # longest first: the first that matches wins
    r"N s/m\^2", r"J/m\^2", r"N/mm", r"mm/s", r"kPa", r"MPa", r"Pa", r"kHz", r"Hz",
    r"mN", r"mJ", r"ms", r"us", r"µs", r"μs", r"min", r"mm", r"MB", r"kB", r"fps",
    r"DoFs", r"dofs", r"N", r"s", r"%", r"x",
]
UNIT_RE = re.compile(r"[ \t]?(" + "|".join(UNITS) + r")(?![\w/^])")
GLUED_UNIT_RE = re.compile("(?:" + "|".join(UNITS) + ")")
UNIT_NORMAL = {"µs": "us", "μs": "us", "dofs": "DoFs"}
# What stands between two numbers of one list or range: "1 / 3", "0.5-3", "1, 3 and 10".
CONNECTOR_RE = re.compile(r"\s*(?:/|-|–|->|→|,|;|and|or|to|\+-|±)\s*(?:and\s+)?$")
SIGN_CONTEXT = set(" \t\n([{/;:,=~^|*<>")     # a "-" after these is a minus sign

NUMBER_RE = re.compile(
    r"(?<![\w.\\])"                                   # not the tail of a word or number
    r"(?P<sign>[+\-]?)"
    r"(?P<num>\d+(?:,\d{3})*(?:\.\d+)?(?:e[+-]?\d+)?)"
    r"(?P<glued>[A-Za-zµμ%][\w/^]*)?"
)
OF_RE = re.compile(r"(?<![\w.])(\d+) of (\d+)(?![\w.])")
PAGE_NUMBER_RE = re.compile(r"(?<![\w.])(-?)(\d+(?:\.\d+)?(?:e[+-]?\d+)?)(?![\d])")
LINK_RE = re.compile(r"(!?)\[([^\]]*)\]\(([^)\s]+)(?:\s+\"[^\"]*\")?\)")
MARKER_RE = re.compile(r"^\s*<!--\s*figures:\s*(.*?)\s*-->\s*$")
MASKS = [
    re.compile(r"<!--.*?-->", re.S),                                           # comments
    re.compile(r"`[^`]*`"),                                                    # inline code
    re.compile(r"\b\d{4}-\d{2}-\d{2}(?:[T ]\d{2}:\d{2}(?::\d{2})?Z?)?"),       # dates
    re.compile(r"\b\d{1,2}:\d{2}(?::\d{2})?\b"),                               # clock times
    re.compile(r"\b\d+\.\d+\.\d+\b"),                                          # versions
    re.compile(r"\b10\^-?\d+\b"),                                              # 10^7
    re.compile(r"\b(?:Eqs?|Tables?|Sec|Section|Fig|Figure|seed|issue|git|commit)\.?\s*"
               r"\d+(?:\.\d+)*(?:-\d+(?:\.\d+)*)?"),                           # names
]
ABBREVIATIONS = ("e.g.", "i.e.", "et al.", "Eq.", "Eqs.", "Sec.", "Fig.", "vs.", "cf.", "No.", "approx.")


@dataclass
class Figure:
    text: str            # as written, normalised: "-0.892 N", "8 of 12"
    number: str          # normalised number ("" for a phrase)
    unit: str            # "" when it has none
    signed: bool         # written with a minus
    line: int
    phrase: str = ""     # "N of M"


@dataclass
class Sentence:
    start: int
    end: int


@dataclass
class Block:
    kind: str            # "para", "row", "header", "heading"
    lines: list          # [(line number, text)]
    marker: list = field(default_factory=list)        # marker targets as written
    marker_pages: list = field(default_factory=list)  # resolved
    table_pages: list = field(default_factory=list)

    def text(self):
        return "\n".join(t for _, t in self.lines)

    def line_of(self, offset):
        pos, found = 0, self.lines[0][0]
        for no, t in self.lines:
            if pos > offset:
                break
            found = no
            pos += len(t) + 1
        return found


# ---- text ----------------------------------------------------------------------------

def normalise(text: str) -> str:
    """Unicode minus and en dash to "-", no-break spaces to spaces; one character for one,
    so offsets stay (thousands separators are dropped from each number on its own)."""
    text = text.replace("\u2212", "-").replace("\u2013", "-").replace("\u00a0", " ").replace("\u202f", " ")
    return text


def drop_thousands(num: str) -> str:
    return num.replace(",", "")


def mask(text: str) -> str:
    """The block's text with everything that holds no figure blanked, offsets kept."""
    out = list(normalise(text))

    def blank(a, b):
        for i in range(a, b):
            if out[i] != "\n":
                out[i] = " "
    for m in LINK_RE.finditer(text):
        blank(m.start(3) - 1, m.end())                     # the target
        if m.group(1) or re.fullmatch(r"[\w./#-]*[/.][\w./#-]*", m.group(2)):
            blank(m.start(), m.end())                      # an image, or a path as text
    for rx in MASKS:
        cur = "".join(out)
        for m in rx.finditer(cur):
            blank(m.start(), m.end())
    return "".join(out)


def mask_page(text: str) -> str:
    text = normalise(text)
    for rx in MASKS:
        text = rx.sub(lambda m: " " * len(m.group(0)), text)
    return text


def split_sentences(text):
    """After . ! ? and a space before a capital, a bracket, emphasis or code; a table row
    or a heading is one sentence."""
    if text.lstrip().startswith(("|", "#")):
        return [Sentence(0, len(text))]
    out, start = [], 0
    for m in re.finditer(r"[.!?][\"')\]*]*\s+(?=[A-Z(\[*`!])", text):
        head = text[start:m.start() + 1]
        if head.endswith(ABBREVIATIONS) or re.search(r"\b[A-Z]\.$", head):
            continue
        out.append(Sentence(start, m.end()))
        start = m.end()
    if start < len(text):
        out.append(Sentence(start, len(text)))
    return out


def extract_figures(masked: str, start: int, end: int, block: Block):
    """The figures of masked[start:end], in order."""
    seg = masked[start:end]
    figs, taken = [], []
    for m in OF_RE.finditer(seg):
        figs.append((m.start(), Figure(m.group(0), "", "", False, block.line_of(start + m.start()),
                                       phrase=m.group(0))))
        taken.append((m.start(), m.end()))
    nums = []   # [match, minus, unit]
    for m in NUMBER_RE.finditer(seg):
        if any(a <= m.start() < b for a, b in taken):
            continue
        unit = ""
        glued = m.group("glued")
        if glued:
            if not GLUED_UNIT_RE.fullmatch(glued):
                continue                                   # 2a, 3D, 18G: part of a name
            unit = UNIT_NORMAL.get(glued, glued)
        minus = m.group("sign") == "-" and (m.start() == 0 or seg[m.start() - 1] in SIGN_CONTEXT)
        nums.append([m, minus, unit])
    for i in range(len(nums) - 1, -1, -1):                 # units: after, through a list, "x 973"
        m, minus, unit = nums[i]
        if unit:
            continue
        um = UNIT_RE.match(seg, m.end())
        if um:
            nums[i][2] = UNIT_NORMAL.get(um.group(1), um.group(1))
        elif (i + 1 < len(nums) and nums[i + 1][2]
              and CONNECTOR_RE.match(seg[m.end():nums[i + 1][0].start()])):
            nums[i][2] = nums[i + 1][2]
        elif re.search(r"(?<![\w])x\s*$", seg[:m.start()]):
            nums[i][2] = "x"
    for m, minus, unit in nums:
        num = drop_thousands(m.group("num"))
        if not unit and "." not in num:
            continue                                       # a bare integer: a count or a name
        text = ("-" if minus else "") + num + (f" {unit}" if unit else "")
        figs.append((m.start(), Figure(text, num, unit, minus, block.line_of(start + m.start()))))
    figs.sort(key=lambda t: t[0])
    return [f for _, f in figs]


def split_blocks(lines):
    blocks, cur, marker, fence = [], None, [], None
    for no, raw in enumerate(lines, start=1):
        line = raw.rstrip()
        stripped = line.strip()
        if fence:
            if stripped.startswith(fence):
                fence = None
            continue
        if stripped.startswith(("```", "~~~")):
            fence, cur = stripped[:3], None
            continue
        mk = MARKER_RE.match(line)
        if mk:
            marker, cur = mk.group(1).split(), None
            continue
        if not stripped:
            cur = None
            continue
        if cur is None and re.match(r"^(?: {4}|\t)", line) and not (blocks and blocks[-1].kind == "code"):
            blocks.append(Block("code", [(no, line)]))     # indented code: skipped
            cur = blocks[-1]
            continue
        if cur is not None and cur.kind == "code":
            continue
        if stripped.startswith("|"):
            if re.fullmatch(r"\|[\s:|-]*\|?", stripped):   # the separator: the row above is the header
                if blocks and blocks[-1].kind == "row":
                    blocks[-1].kind = "header"
                continue
            blocks.append(Block("row", [(no, line)], marker=marker))
            marker, cur = [], None
            continue
        if stripped.startswith("#"):
            blocks.append(Block("heading", [(no, line)]))
            cur = None
            continue
        if cur is None or re.match(r"^\s*(?:[-*+]|\d+\.)\s+", line):
            cur = Block("para", [], marker=marker)
            marker = []
            blocks.append(cur)
        cur.lines.append((no, line))
    return [b for b in blocks if b.kind != "code"]


def is_image_only(block):
    return re.fullmatch(r"\s*(?:!\[[^\]]*\]\([^)]*\)\s*)+", block.text()) is not None


# ---- the check -----------------------------------------------------------------------

class Checker:
    def __init__(self, root: str):
        self.root = os.path.abspath(root)
        self.results_dir = os.path.join(self.root, "results")
        self.pages: dict = {}
        self.errors: list = []
        self.checked = 0
        self.allowlisted = 0
        self.listing: list = []

    def rel(self, path):
        return os.path.relpath(path, self.root).replace(os.sep, "/")

    def link_page(self, md_file, target):
        """(is a results link, its page or None, a problem or None, the problem is fatal)."""
        if re.match(r"^[a-z][a-z0-9+.-]*:", target) or target.startswith("#"):
            return False, None, None, False
        path = target.split("#", 1)[0]
        if not path:
            return False, None, None, False
        full = os.path.normpath(os.path.join(os.path.dirname(os.path.abspath(md_file)), path))
        if not (full == self.results_dir or full.startswith(self.results_dir + os.sep)):
            return False, None, None, False
        if not os.path.exists(full):
            return True, None, f"link target {self.rel(full)} does not exist", True
        if self.rel(full) in NOT_FIGURE_PAGES:
            return False, None, None, False
        if full.endswith(".md") and os.path.isfile(full):
            return True, full, None, False
        folder = full if os.path.isdir(full) else os.path.dirname(full)
        readme = os.path.join(folder, "README.md")
        if os.path.isfile(readme):
            return True, readme, None, False
        mds = sorted(f for f in os.listdir(folder) if f.endswith(".md"))
        if len(mds) == 1:
            return True, os.path.join(folder, mds[0]), None, False
        return True, None, (f"link {target} names no single page ({self.rel(folder)} has "
                            f"{len(mds) or 'no'} markdown files): link the page that holds the figure"), False

    def page_numbers(self, page):
        if page not in self.pages:
            with open(page, encoding="utf-8") as f:
                text = f.read()
            # the page's dates, clock times, versions, hashes and commands hold no figure either
            text = mask_page(text)
            text = re.sub(r"(?<=\d),(?=\d{3}(?!\d))", "", text)
            signed, unsigned = set(), set()
            for m in PAGE_NUMBER_RE.finditer(text):
                unsigned.add(m.group(2))
                if m.group(1) and (m.start() == 0 or text[m.start() - 1] in SIGN_CONTEXT):
                    signed.add(m.group(2))
            self.pages[page] = (text, signed, unsigned)
        return self.pages[page]

    def found(self, fig, page):
        text, signed, unsigned = self.page_numbers(page)
        if fig.phrase:
            return re.search(r"(?<![\w.])" + re.escape(fig.phrase) + r"(?![\w.])", text) is not None
        return fig.number in (signed if fig.signed else unsigned)

    def links(self, md_file, block, start=0, end=None):
        """[(offset, page, problem, fatal)] of the results links in block text[start:end]."""
        text = block.text()
        out = []
        for m in LINK_RE.finditer(text, start, len(text) if end is None else end):
            is_results, page, problem, fatal = self.link_page(md_file, m.group(3))
            if is_results:
                out.append((m.start(), page, problem, fatal))
        return out

    def check_file(self, md_file):
        with open(md_file, encoding="utf-8") as f:
            blocks = split_blocks(f.read().split("\n"))
        name = self.rel(os.path.abspath(md_file))
        for b in blocks:
            for target in b.marker:
                ok, page, problem, _ = self.link_page(md_file, target)
                if page:
                    b.marker_pages.append(page)
                else:
                    self.errors.append(f"{name}:{b.lines[0][0] - 1}: figures marker {target}: "
                                       f"{problem or 'not a results page'}")
        intro, table, in_table = [], [], False
        for b in blocks:
            if b.kind in ("row", "header"):
                if not in_table:
                    in_table, table = True, list(b.marker_pages)
                    if not table and b.kind == "header":
                        table = [p for _, p, _, _ in self.links(md_file, b) if p]
                    table = table or intro
                b.table_pages = table
            else:
                in_table = False
            self.check_block(md_file, name, b)
            if b.kind == "para" and not is_image_only(b):
                last = split_sentences(b.text())[-1]
                intro = [p for _, p, _, _ in self.links(md_file, b, last.start, last.end) if p]

    def check_block(self, md_file, name, block):
        text = block.text()
        links = self.links(md_file, block)
        for off, _, problem, fatal in links:
            if fatal:
                self.errors.append(f"{name}:{block.line_of(off)}: {problem}")
        paragraph = []
        for _, p, _, _ in links:
            if p and p not in paragraph:
                paragraph.append(p)
        masked = mask(text)
        for s in split_sentences(text):
            own_links = [(off, p, problem) for off, p, problem, _ in links if s.start <= off < s.end]
            own = [p for _, p, _ in own_links if p]
            if own:
                targets, how = own, "linked from its sentence"
            elif block.marker_pages:
                targets, how = block.marker_pages, "named by its figures marker"
            elif block.table_pages:
                targets, how = block.table_pages, "linked from the table's introduction"
            else:
                targets, how = paragraph, "linked from its paragraph"
            figures = []
            for f in extract_figures(masked, s.start, s.end, block):
                if f.unit and f"{f.number} {f.unit}" in ALLOWLIST:
                    self.allowlisted += 1
                else:
                    figures.append(f)
            if figures:
                for off, p, problem in own_links:
                    if problem and not p and "does not exist" not in problem:
                        self.errors.append(f"{name}:{block.line_of(off)}: {problem}")
            for fig in figures:
                self.checked += 1
                if not targets:
                    self.errors.append(f"{name}:{fig.line}: figure '{fig.text}' quotes no results page "
                                       f"(link the page that holds it; a setting goes in ALLOWLIST)")
                    continue
                where = [self.rel(p) for p in targets]
                self.listing.append(f"{name}:{fig.line}: {fig.text} -> {', '.join(where)}")
                if not any(self.found(fig, p) for p in targets):
                    self.errors.append(f"{name}:{fig.line}: figure '{fig.text}' not found on "
                                       f"{' or '.join(where)} ({how})")


def run(files, root, show_list=False, out=sys.stdout):
    for md in files:
        if not os.path.isfile(md):
            print(f"check_readme_figures: no such file: {md}", file=sys.stderr)
            return 2
    checker = Checker(root)
    for md in files:
        checker.check_file(md)
    if show_list:
        for line in checker.listing:
            print(line, file=out)
    names = ", ".join(checker.rel(os.path.abspath(f)) for f in files)
    summary = (f"{checker.checked} figures in {names} checked against {len(checker.pages)} results pages"
               f" ({checker.allowlisted} allowlisted settings skipped)")
    if checker.errors:
        for e in checker.errors:
            print(e, file=out)
        print(f"check_readme_figures: FAILED, {len(checker.errors)} problem(s); {summary}", file=out)
        return 1
    print(f"check_readme_figures: OK, every figure found; {summary}", file=out)
    return 0


def main(argv=None):
    here = os.path.dirname(os.path.abspath(__file__))
    ap = argparse.ArgumentParser(description=__doc__.split("\n", 1)[0])
    ap.add_argument("files", nargs="*", help="markdown files (default: README.md results/README.md)")
    ap.add_argument("--root", default=os.path.dirname(here), help="repository root, results/ below it")
    ap.add_argument("--list", action="store_true", help="print every figure with the pages it is looked up on")
    args = ap.parse_args(argv)
    files = args.files or [os.path.join(args.root, "README.md"), os.path.join(args.root, "results", "README.md")]
    return run(files, args.root, args.list)


if __name__ == "__main__":
    sys.exit(main())
