"""Tables for people, laid out as plain lines from output records.

Imported only when a table is asked for, so that machine formats never pay
for rich's import.  Numbers are rounded by :mod:`.numbers` (``digits`` decimals; no digits
below the noise); records keep full precision.  Each result kind has a renderer class
(named by its registry entry's ``table``) giving its extra contact columns,
its ``resolve`` table, its verdict sentences and its ``basis`` tables; the
verdicts only print what the records say (``moves``, ``about_wrist``,
``in_tangent_planes``).

Renderers return :class:`Grid` tables (made by :func:`_table`, used like
rich's ``Table``), ``str`` or rich ``Text`` lines, or rich ``Group`` objects of
those; anything else rich draws is drawn by rich, more slowly.  A writer lays them out
itself, a record at a time, straight onto the output: drawing rich tables
cost milliseconds a record, which made tables of data sets unusable.  Every
text a table shows goes through :func:`~grasptwist.output.names.escaped`
and is never read as rich markup, so a name like ``[/]x`` or one holding an
escape sequence is shown as it is, escaped where it is not printable.  A
table wider than the output (``COLUMNS``, else the terminal; a pipe or
file without ``COLUMNS`` has no limit) is split into parts of whole
columns, each repeating the first column, so that no vector is ever cut.
"""

from __future__ import annotations

import contextlib
import io
import math
import os
import textwrap
from typing import IO

import orjson
from rich.cells import cell_len
from rich.color import ColorSystem
from rich.console import Console, Group
from rich.text import Text

from ..engine.degeneracy import CONDITION_WARNING
from ..results import KINDS
from .names import escaped
from .numbers import fmt_figure, fmt_number, fmt_vector

__all__ = [
    "TableWriter",
    "BasisTableWriter",
    "CheckTableWriter",
    "ForceTableWriter",
    "closure_cell",
    "OffTangentTable",
    "TangentTable",
    "Grid",
    "console",
    "output_width",
]


class _TextView(io.TextIOWrapper):
    """A text view of a binary stream that leaves the stream open when it goes."""

    def __del__(self):
        with contextlib.suppress(ValueError):  # already detached, or the stream was closed by its owner
            self.detach()


def _colour(text: IO, color: bool | None) -> bool:
    """Colour as asked, else only on a terminal and never under NO_COLOR."""
    return color if color is not None else (text.isatty() and not os.environ.get("NO_COLOR"))


def console(out: IO[bytes] | IO[str], color: bool | None = None, width: int | None = None) -> Console:
    """A rich console on ``out``: colour only on a terminal and never under NO_COLOR;
    lines are never wrapped by rich (the terminal folds what is too long)."""
    text = out if isinstance(out, io.TextIOBase) else _TextView(out, encoding="utf-8", write_through=True)
    terminal = _colour(text, color)
    return Console(
        file=text,
        force_terminal=terminal,
        no_color=not terminal,
        highlight=False,
        width=width or output_width(text) or 160,
        soft_wrap=True,
    )


def output_width(out: IO, width: int | None = None) -> int | None:
    """Columns a table on ``out`` may take: ``width`` if given, else ``COLUMNS``,
    else the terminal's width, else None (no limit: a pipe or a file).

    >>> output_width(io.BytesIO(), 72), output_width(io.BytesIO()) is None or "COLUMNS" in os.environ
    (72, True)
    """
    if width:
        return width
    columns = os.environ.get("COLUMNS", "")
    if columns.isdigit() and int(columns) > 0:
        return int(columns)
    try:
        return os.get_terminal_size(out.fileno()).columns or None if out.isatty() else None
    except (AttributeError, OSError, ValueError):  # not a real file (tests' buffers)
        return None


class Grid:
    """A table of single-line cells, used like rich's ``Table`` (``add_column``,
    ``add_row``, ``title``) but laid out by the writers themselves.

    >>> g = Grid(title="t"); g.add_column("i"); g.add_column("x", justify="right"); g.add_row("1", "2.5")
    >>> print("\\n".join(line.rstrip() for line in g.lines(lambda c: (c, len(c)))))
    t
    <BLANKLINE>
      i     x
     ─────────
      1   2.5
    <BLANKLINE>
    """

    def __init__(self, title: str | Text | None = None):
        self.title = title
        self.headers: list[str] = []
        self.right: list[bool] = []
        self.rows: list[tuple] = []

    def add_column(self, header: str, justify: str = "left") -> None:
        self.headers.append(header)
        self.right.append(justify == "right")

    def add_row(self, *cells: str | Text) -> None:
        self.rows.append(cells)

    @property
    def row_count(self) -> int:
        return len(self.rows)

    def __rich_console__(self, console, options):
        """Drawn by rich too (inside a renderable of rich's own), without colour."""
        for line in self.lines(lambda c: (escaped(_plain(c)), _len(escaped(_plain(c)))), options.max_width):
            yield Text(line.rstrip())

    def lines(self, cell, width: int | None = None, bold: bool = False) -> list[str]:
        """The table as lines (``cell(c)`` gives a cell's text and its width on
        screen); wider than ``width``,
        as parts of whole columns, each with the first column again."""
        cells, sizes = [], []
        for row in self.rows:
            # most cells are numbers: plain ASCII, their own width (checked inline: this runs per cell)
            drawn = [(c, len(c)) if c.__class__ is str and c.isascii() and c.isprintable() else cell(c) for c in row]
            cells.append([text for text, _ in drawn])
            sizes.append([n for _, n in drawn])
        widths = [max([_len(h), *(row[i] for row in sizes)]) for i, h in enumerate(self.headers)]
        out = [cell(self.title)[0]] if self.title else []
        for part in _parts(widths, width):
            out += ["", *_lines(self, part, widths, cells, sizes, bold)]
        return [*out, ""]


def _plain(cell) -> str:
    return cell.plain if isinstance(cell, Text) else escaped(cell)


def _len(text: str) -> int:
    """Columns ``text`` takes on screen (two for a wide character)."""
    return len(text) if text.isascii() else cell_len(text)


def _parts(widths: list[int], width: int | None) -> list[list[int]]:
    """Column indices of each part of a table: all if it fits ``width``, else
    the first column and as many whole columns after it as fit, repeatedly."""
    if width is None or _span(widths) <= width or len(widths) < 3:
        return [list(range(len(widths)))]
    parts, part = [], [0]
    for i in range(1, len(widths)):
        if len(part) > 1 and _span([widths[j] for j in (*part, i)]) > width:
            parts.append(part)
            part = [0]
        part.append(i)
    return [*parts, part]


def _span(widths) -> int:
    """Width of a line of columns this wide: two spaces at each end, three between."""
    return sum(widths) + 3 * len(widths) + 1


def _lines(grid: Grid, part, widths, cells, sizes, bold: bool = False) -> list[str]:
    """Header, rule and rows of the columns ``part`` (rich's SIMPLE_HEAD look)."""
    out = _head(grid, part, widths, bold)
    # a part leaves out the rows that have nothing in its columns (continuation rows of other columns)
    rows = [(row, size) for row, size in zip(cells, sizes) if len(part) < 2 or any(size[i] for i in part[1:])]
    return out + [_row(row, size, widths, grid.right, part) for row, size in rows]


def _head(grid: Grid, part, widths, bold: bool = False) -> list[str]:
    """The header line of the columns ``part`` (``bold``: in bold, on a terminal) and the rule under it."""
    headers = [h if h.isprintable() else escaped(h) for h in grid.headers]
    lengths = [_len(h) for h in headers]
    if bold:
        headers = [f"\x1b[1m{h}\x1b[0m" if h else h for h in headers]
    rule = " " + "─" * (_span([widths[i] for i in part]) - 2)
    return [_row(headers, lengths, widths, grid.right, part), rule]


def _row(texts, lengths, widths, right, part) -> str:
    """One line of cells ``texts`` (``lengths`` wide on screen) padded to their columns' ``widths``."""
    pieces = []
    for i in part:
        pad = " " * (widths[i] - lengths[i])
        pieces.append(pad + texts[i] if right[i] else texts[i] + pad)
    return "  " + "   ".join(pieces)


class _Writer:
    """Common start of the table writers: where lines go, how wide and coloured, a record counter."""

    def __init__(
        self,
        out: IO[bytes],
        digits: int = 4,
        color: bool | None = None,
        width: int | None = None,
        order: str = "omega-v",
        contributions=(),
    ):
        self.out = out
        # what other families add to a command's records: a column each, where a table has columns
        self.contributions = contributions
        self.text = out if isinstance(out, io.TextIOBase) else None
        self.color = _colour(out, color)
        self.width = output_width(out, width)
        self._console = None  # made when a renderer returns something only rich can draw
        self.digits = digits
        self.count = 0
        # screws are printed in the order asked for; say which when it is not the paper's
        self.order_note = "  (screws as (v; omega))" if order == "v-omega" else ""

    def write(self, encoded: bytes) -> None:
        rec = orjson.loads(encoded)
        if "error" in rec:  # the error line is on stderr; tables carry results only
            return
        lines = [""] if self.count else []
        self.count += 1
        self.show(rec, lines)
        self._put(lines)

    def close(self) -> None:
        pass

    def _put(self, lines: list[str]) -> None:
        data = "\n".join(lines) + "\n"
        if self.text is not None:
            self.text.write(data)
        else:
            self.out.write(data.encode("utf-8"))

    def add(self, lines: list[str], item) -> None:
        """Lay out one thing a renderer returned: a Grid, a line, or any rich renderable."""
        if isinstance(item, Grid):
            lines += [line.rstrip() for line in item.lines(self.cell, self.width, self.color)]
        elif isinstance(item, str | Text):
            lines += self._prose(item)
        elif isinstance(item, Group):
            for part in item.renderables:
                self.add(lines, part)
        else:  # a renderer drawing with rich itself: let rich lay it out, after what is pending
            self._put(lines)
            lines.clear()
            self._rich().print(item)
            self.out.flush()

    def _rich(self) -> Console:
        if self._console is None:
            self._console = console(self.out, self.color, self.width)
        return self._console

    def cell(self, item) -> tuple[str, int]:
        """A text as it goes out (see :meth:`styled`) and the columns it takes."""
        if not isinstance(item, Text):
            item = str(item)  # a number a renderer did not format
        if isinstance(item, str):
            text = item if item.isprintable() else escaped(item)
            return text, _len(text)
        return self.styled(item), _len(escaped(item.plain))

    def styled(self, item) -> str:
        """A text as it goes out: control characters escaped, styles as ANSI codes when colour is on."""
        if isinstance(item, str):
            return escaped(item)
        if not self.color:
            return escaped(item.plain)
        return "".join(
            s.style.render(escaped(s.text), color_system=ColorSystem.STANDARD) if s.style else escaped(s.text)
            for s in item.render(self._rich())
            if s.text != "\n"
        )

    def _prose(self, item) -> list[str]:
        """A line, folded at spaces to the width when it is a sentence of one style."""
        plain = _plain(item)
        if self.width is None or _len(plain) <= self.width or (isinstance(item, Text) and item.spans):
            return [self.styled(item)]
        style = item.style if isinstance(item, Text) else ""
        folded = textwrap.wrap(
            plain, self.width, subsequent_indent="  ", break_long_words=False, break_on_hyphens=False
        )
        return [self.styled(Text(line, style=style)) for line in folded]

    def flow(self, lines: list[str], *parts: Text) -> None:
        """Parts of one line, each on a line of its own (indented) when together they are too wide."""
        whole = Text("  ").join(parts)
        if self.width is None or _len(whole.plain) <= self.width:
            lines.append(self.styled(whole))
        else:
            lines += [self.styled(p if i == 0 else Text("  ") + p) for i, p in enumerate(parts)]

    def title(self, rec: dict) -> Text:
        units = f" [{rec['units']}]" if rec.get("units") else ""
        return Text.assemble(
            (escaped(rec["grasp"]), "bold"), f" ({escaped(rec['file'])}){escaped(units)}", self.order_note
        )

    def warnings(self, lines: list[str], rec: dict) -> None:
        for warning in rec["warnings"]:
            self.add(lines, Text(f"warning: {warning}", style="yellow"))


def _renderers(rec: dict) -> list:
    """``(kind, renderer)`` of every kind the record holds, in registry order."""
    return [(kind, globals()[kind.table]) for kind in KINDS if kind.key in rec]


def _shown(m) -> bool:
    """Whether a kind's object holds results (not skipped, not failed)."""
    return m is not None and "error" not in m


class TableWriter(_Writer):
    """A resolve record as tables of contacts and of each kind, then their verdicts."""

    def show(self, rec: dict, lines: list[str]) -> None:
        d = self.digits
        names = [c["name"] for c in rec["contacts"]]
        twist = rec["twist"]
        kinds = _renderers(rec)
        spec = Text.assemble("twist ", (escaped(twist["name"]), "bold"), f" = {fmt_vector(twist['screw'], d)}")
        self.flow(lines, self.title(rec), spec)
        self.add(lines, self._contacts(rec, kinds, d))
        for kind, render in kinds:
            m = rec[kind.key]
            self.add(lines, _not_shown(kind, render, m) if not _shown(m) else render.resolve(m, names, d, rec))
        for kind, render in kinds:
            if _shown(rec[kind.key]):
                for line in render.verdict(rec[kind.key], names):
                    self.add(lines, line)
        self.warnings(lines, rec)

    def _contacts(self, rec, kinds, d):
        extra = [c for kind, render in kinds if _shown(rec[kind.key]) for c in render.contact_columns(rec[kind.key], d)]
        t = _table("contact", "point", "normal (unit)", "velocity T(p_i)")
        for header, _ in extra:
            t.add_column(header, justify="right")
        for i, c in enumerate(rec["contacts"]):
            row = [c["name"], fmt_vector(c["point"], d), fmt_vector(c["normal"], d)]
            row.append(fmt_vector(rec["contact_velocity"][i], d))
            t.add_row(*row, *(cells[i] for _, cells in extra))
        return t


def _table(*columns, numbers=()) -> Grid:
    """A plain table; the columns named in ``numbers`` are right-aligned."""
    t = Grid()
    for c in columns:
        t.add_column(c, justify="right" if c in numbers else "left")
    return t


def _not_shown(kind, render, m) -> Text:
    """The line of a kind that was skipped (``null``) or failed."""
    if m is None:
        return Text(f"{kind.label}: skipped ({render.skipped})", style="dim")
    return Text(f"{kind.label}: failed: {m['error']['code']}: {m['error']['message']}", style="red")


def _fingers(names, moves, components) -> list[str]:
    """Names of the fingers whose components (indices into ``moves``) move a finger."""
    return [names[i] for i, c in enumerate(components) if moves[c]]


def _finger_list(names: list[str]) -> str:
    """Fingers named in prose (a finger is named by its contact).

    >>> _finger_list(["1"]), _finger_list(["1", "2"]), _finger_list(["thumb", "index", "middle"])
    ('finger 1', 'fingers 1 and 2', 'fingers thumb, index and middle')
    """
    names = [escaped(n) for n in names]
    if len(names) == 1:
        return f"finger {names[0]}"
    return f"fingers {', '.join(names[:-1])} and {names[-1]}"


def _products(title, names, table, d, conditioning) -> list:
    """A title line and a 3x3 table of Klein products."""
    t = _table("", *names, numbers=names)
    for i, n in enumerate(names):
        t.add_row(n, *(fmt_number(v, d) for v in table[i]))
    return [Text(f"{title}   conditioning {fmt_figure(conditioning)}", style="bold"), t]


def _screws(names, d, *columns):
    t = _table("i", *(f"{name}_i" for name, _ in columns))
    for i, n in enumerate(names):
        t.add_row(n, *(fmt_vector(screws[i], d) for _, screws in columns))
    return t


class OffTangentTable:
    """The off-tangent method (Proposition 1): amplitudes, basis screws, verdicts."""

    skipped = "the grasp has no wrist"
    #: Its components in basis order (the order of ``moves`` and of ``joint_rates``).
    components = ("Sigma_1", "Sigma_2", "Sigma_3", "Psi_1", "Psi_2", "Psi_3")

    @staticmethod
    def contact_columns(m, d) -> list:
        return []

    @staticmethod
    def resolve(m, names, d, rec):
        t = _table(
            "i", "x_i", "y_i", "Sigma_i (moves finger i only)", "Psi_i (keeps finger i fixed)", numbers=("x_i", "y_i")
        )
        t.title = Text(f"off-tangent (Proposition 1)   conditioning {fmt_figure(m['conditioning'])}", style="bold")
        for i, n in enumerate(names):
            t.add_row(
                n,
                fmt_number(m["x"][i], d),
                fmt_number(m["y"][i], d),
                fmt_vector(m["sigma"][i], d),
                fmt_vector(m["psi"][i], d),
            )
        return t

    @staticmethod
    def verdict(m, names) -> list[str]:
        """Plain sentences from the record's ``moves`` and ``about_wrist``."""
        lines = []
        held = _fingers(names, m["moves"], (3, 4, 5))  # Psi_i holds finger i
        moved = _fingers(names, m["moves"], (0, 1, 2))  # Sigma_i moves finger i alone
        if held:
            each = "is held fixed" if len(held) == 1 else "are each held fixed in turn"
            lines.append(
                f"off-tangent: Psi part: {_finger_list(held)} {each} while the object "
                "turns about the line from the wrist through it."
            )
        if moved:
            each = "moves alone" if len(moved) == 1 else "each move alone"
            lines.append(
                f"off-tangent: Sigma part: {_finger_list(moved)} {each}, about the line through the other two."
            )
        if m["about_wrist"]:
            lines.append("off-tangent: the twist is a rotation about the wrist: the wrist alone could make it.")
        return lines

    @staticmethod
    def basis(m, names, d) -> list:
        return [
            _screws(names, d, ("Sigma", m["sigma"]), ("Psi", m["psi"])),
            *_products("[Sigma_i | Psi_j]", names, m["sigma_psi"], d, m["conditioning"]),
        ]


class TangentTable:
    """The tangent method (Proposition 2 and the off-plane rest): amplitudes, bases, verdict."""

    skipped = "not asked for"
    #: Its components in basis order: ``alpha_i Theta_i``, then the off-plane rest ``beta_i Sigma_i``.
    components = ("Theta_1", "Theta_2", "Theta_3", "Sigma_1", "Sigma_2", "Sigma_3")

    @staticmethod
    def contact_columns(m, d) -> list:
        return [("normal velocity", [fmt_number(v, d) for v in m["normal_velocity"]])]

    @staticmethod
    def resolve(m, names, d, rec):
        t = _table(
            "i", "alpha_i", "beta_i", "Theta_i (keeps finger i fixed, others slide)", numbers=("alpha_i", "beta_i")
        )
        t.title = Text(
            f"tangent (Proposition 2 + off-plane rest)   conditioning {fmt_figure(m['conditioning'])}", style="bold"
        )
        for i, n in enumerate(names):
            t.add_row(n, fmt_number(m["alpha"][i], d), fmt_number(m["beta"][i], d), fmt_vector(m["theta"][i], d))
        return t

    @staticmethod
    def verdict(m, names) -> list[str]:
        """A plain sentence from the record's ``in_tangent_planes`` and ``moves``."""
        if m["in_tangent_planes"]:
            return ["verdict: tangent sliding alone realises this twist (every beta_i = 0)."]
        off = _fingers(names, m["moves"], (3, 4, 5))  # beta_i Sigma_i moves finger i off its plane
        planes = "its tangent plane" if len(off) == 1 else "their tangent planes"
        return [
            "verdict: not realisable by tangent sliding alone: "
            f"{_finger_list(off)} must also move off {planes} (the beta_i Sigma_i part)."
        ]

    @staticmethod
    def basis(m, names, d) -> list:
        return [
            _screws(names, d, ("Theta", m["theta"]), ("Sigma", m["sigma"])),
            *_products("[Theta_i | Sigma_j]", names, m["theta_sigma"], d, m["conditioning"]),
        ]


class BasisTableWriter(_Writer):
    """A grasp's basis screws and their Klein products (cf. the paper's eq. 18)."""

    def show(self, rec: dict, lines: list[str]) -> None:
        d = self.digits
        names = [c["name"] for c in rec["contacts"]]
        self.add(lines, self.title(rec))
        for kind, render in _renderers(rec):
            m = rec[kind.key]
            for item in render.basis(m, names, d) if _shown(m) else [_not_shown(kind, render, m)]:
                self.add(lines, item)
        self.warnings(lines, rec)


class CheckTableWriter(_Writer):
    """One line per grasp, streamed: each method's verdict and conditioning in
    columns of fixed width, then the file and the grasp, as wide as in the
    first :data:`SIZING_ROWS` rows (a longer cell later pushes the rest of
    its row; the grasp is last, so it pushes nothing)."""

    def __init__(self, out, **options):
        super().__init__(out, **options)
        self.kinds = [k for k in KINDS if k.check_fields]  # a kind with nothing to check has no column
        self.cells = [globals()[c.cell] for c in self.contributions]  # named, as a kind's renderer is
        # a method's cell is "ok (its basis's conditioning)" or the code of its degeneracy
        headers = (*(f"{k.label} (conditioning)" for k in self.kinds), *(c.header for c in self.contributions))
        self.grid = _table(*headers, "file", "grasp")
        self.widths: list[int] = []

    def write(self, encoded: bytes) -> None:
        rec = orjson.loads(encoded)
        if "error" in rec:
            return
        self.count += 1
        self.grid.add_row(
            *(_verdict_cell(rec.get(k.key, False)) for k in self.kinds),
            *(cell(rec) for cell in self.cells),
            rec["file"],
            rec["grasp"],
        )
        if self.widths or self.grid.row_count >= SIZING_ROWS:
            self._rows()

    def _rows(self) -> None:
        """The rows held, under the header when they are the first."""
        rows = [list(zip(*(self.cell(c) for c in row))) for row in self.grid.rows]
        self.grid.rows.clear()
        lines, part = [], range(len(self.grid.headers))
        if not self.widths:
            # every column as wide as its header and its cells in the first rows (an 80-column
            # terminal holds both methods' verdicts and a short file and grasp name)
            self.widths = [max(_len(h), *(n[i] for _, n in rows)) for i, h in enumerate(self.grid.headers)]
            lines = ["", *(line.rstrip() for line in _head(self.grid, part, self.widths, self.color))]
        for texts, lengths in rows:
            widths = [max(w, n) for w, n in zip(self.widths, lengths)]  # an overlong cell pushes the rest of its row
            lines.append(_row(texts, lengths, widths, self.grid.right, part).rstrip())
        self._put(lines)

    def close(self) -> None:
        if self.grid.rows:
            self._rows()
        if self.count:
            self._put([""])


#: Rows of a ``check`` table held back to size its file and grasp columns.
SIZING_ROWS = 64


def closure_cell(rec):
    """The least friction for force closure; with the grasp's own friction, whether that closes it."""
    if "closure_friction" not in rec:
        return Text("-", style="dim")
    least = rec["closure_friction"]
    text = "none" if least is None else fmt_figure(least)
    if "force_closure" in rec:
        text += " closed" if rec["force_closure"] else " open"
    return Text(text)


def _verdict_cell(m):
    if m is False or m is None:
        return Text("skipped" if m is None else "-", style="dim")
    if "error" not in m:
        style = "yellow" if m["conditioning"] < CONDITION_WARNING else "green"
        return Text(f"ok ({fmt_figure(m['conditioning'])})", style=style)
    return Text(m["error"]["code"], style="red")


def _coefficient(mu: float | None) -> float:
    """A contact's friction coefficient from a record, where an infinite one (no limit)
    is ``null``, as every infinity is (the output contract).

    >>> _coefficient(0.5), _coefficient(None)
    (0.5, inf)
    """
    return math.inf if mu is None else mu


class ForceTableWriter(_Writer):
    """A forces record: per contact its forces and how close each is to slipping, then the totals and closure.

    Forces in N, moments in N times the file's length unit (``units``; ``N m`` with
    metres, ``N mm`` with millimetres, ``N length`` when the file names none)."""

    def show(self, rec: dict, lines: list[str]) -> None:
        d = self.digits
        w = rec["wrench"]
        parts = [self.title(rec)]
        if w is not None:
            parts.append(
                Text.assemble(
                    "wrench ",
                    (escaped(w["name"]), "bold"),
                    f" = force {fmt_vector(w['wrench'][:3], d)} N; moment {fmt_vector(w['wrench'][3:], d)} "
                    f"N {escaped(rec['units'] or 'length')}",
                )
            )
        self.flow(lines, *parts)
        grip, m = rec["grip"], rec["manipulating"]
        friction = rec["friction"]
        t = _table("contact", "mu")
        shown_m = _shown(m)
        shown_g = _shown(grip)
        if shown_m:
            t.add_column("manipulating force (N)")
        if shown_g:
            for header in ("grip force (N)", "normal (N)", "tangential (N)", "friction used", "of mu/s"):
                t.add_column(header, justify="left" if header == "grip force (N)" else "right")
        for i, c in enumerate(rec["contacts"]):
            mu = None if friction is None else _coefficient(friction[i])
            row = [c["name"], fmt_number(mu, d)]
            if shown_m:
                row.append(fmt_vector(m["force"][i], d))
            if shown_g:
                used, limit = grip["friction_used"][i], mu / grip["safety"]  # no limit: 0% of it used
                row += [
                    fmt_vector(grip["force"][i], d),
                    fmt_number(grip["normal_force"][i], d),
                    fmt_number(grip["tangential_force"][i], d),
                    fmt_number(used, d),
                    "-" if limit == 0 else f"{100 * used / limit:.0f}%",
                ]
            t.add_row(*row)
        self.add(lines, t)
        for name, part in (("manipulating", m), ("grip", grip)):
            if part is not None and "error" in part:
                self.add(lines, Text(f"{name}: {part['error']['code']}: {part['error']['message']}", style="red"))
        length = escaped(rec["units"] or "length")
        if shown_g:
            if grip["contact_model"] == "soft":  # no three squeezes over soft cones: each contact's torsion instead
                inner = f"soft contacts, torsions {fmt_vector(grip['torsion'], d)} N {length}"
            elif grip["squeeze"] is None:
                inner = "no squeezes (collinear contacts)"
            else:
                inner = f"squeezes {fmt_vector(grip['squeeze'], d)} N"
            self.add(
                lines,
                f"total normal force {fmt_number(grip['total_normal_force'], d)} N (safety {grip['safety']:g}); {inner}",
            )
        c = rec["closure"]
        verdict = {True: "yes", False: "no", None: "- (no friction)"}[c["force_closure"]]
        least = "none" if c["closure_friction"] is None else fmt_number(c["closure_friction"], d)
        judged = [] if c["safety"] == 1 or c["force_closure"] is None else [f"with mu/{c['safety']:g}"]
        judged += ["soft contacts"] if c.get("contact_model") == "soft" else []
        judged = f" ({', '.join(judged)})" if judged else ""
        text = f"closure{judged}: force closure {verdict}; closure friction {least}"
        if c["epsilon"] is not None:
            text += f"; epsilon {fmt_number(c['epsilon'], d)}"
        self.add(lines, text)
        self.warnings(lines, rec)


class HandTable:
    """A hand's joint rates: per finger its joints with their positions and rates, rank, residual,
    conditioning and tip error.

    A finger is named by its contact, as in every line of the tables; the hand's own name for
    it (TriFinger's ``0``, ``120``, ``240``) is shown once, beside it.
    """

    skipped = "the grasp has no hand"

    @staticmethod
    def contact_columns(m, d) -> list:
        return []

    @staticmethod
    def resolve(m, names, d, rec):
        from rich.console import Group

        ratio = m["velocity_limit_ratio"]
        title = "hand: joint rates" + ("" if ratio is None else f"   velocity-limit ratio {fmt_figure(ratio)}")
        # where the hand is (its joint positions given or solved, each tip's distance to its target p - r n)
        placed = "joint_positions" in m["fingers"][0]
        where = ("position",) if placed else ()
        tip = ("tip error",) if placed else ()
        t = _table(
            "finger", "in hand", "joint", *where, "rate", "rank", "residual", "conditioning", *tip,
            numbers=("rate", *where),
        )  # fmt: skip
        for f in m["fingers"]:
            positions = f.get("joint_positions", ())
            for k, (joint, rate) in enumerate(zip(f["joints"], f["joint_rates"])):
                first = k == 0
                error = fmt_figure(f.get("tip_error"), 2)
                t.add_row(
                    f["contact"] if first else "",
                    f["name"] if first else "",
                    joint,
                    *((fmt_number(positions[k], d),) if placed else ()),
                    fmt_number(rate, d),
                    str(f["rank"]) if first else "",
                    fmt_figure(f["residual"], 2) if first else "",
                    fmt_figure(f["conditioning"]) if first else "",
                    *(((error if first else ""),) if placed else ()),
                )
        return Group(Text(title, style="bold"), t, *HandTable._moved_by(m, rec))

    @staticmethod
    def _moved_by(m, rec) -> list[Text]:
        """Per finger, the components of each method that move it (the records' ``moves``): what a
        controller running the components one after another asks of that finger's joints."""
        methods = [(kind.label, render, rec[kind.key]) for kind, render in _renderers(rec) if kind.key != "hand"]
        lines = []
        for f, finger in enumerate(m["fingers"]):
            parts = [
                f"{label} {' '.join(c for c, fingers in zip(render.components, r['moves']) if f in fingers) or 'none'}"
                for label, render, r in methods
                if _shown(r)
            ]
            lines.append(Text(f"finger {escaped(finger['contact'])} is moved by: {'; '.join(parts)}"))
        return lines

    @staticmethod
    def verdict(m, names) -> list[str]:
        """Fingers at their velocity limits."""
        ratio = m["velocity_limit_ratio"]
        if ratio is not None and ratio > 1:
            return [f"hand: the joint rates exceed their velocity limits: slow the twist down by {fmt_figure(ratio)}."]
        return []

    @staticmethod
    def basis(m, names, d) -> list:
        return []
