"""Tables for people, drawn with rich from output records.

Imported only when a table is asked for, so that machine formats never pay
for rich's import.  Numbers are rounded to ``digits`` decimals here and only
here; records keep full precision.  Each result kind has a renderer class
(named by its registry entry's ``table``) giving its extra contact columns,
its ``resolve`` table, its verdict sentences and its ``basis`` tables; the
verdicts only print what the records say (``moves``, ``about_wrist``,
``in_tangent_planes``).
"""

from __future__ import annotations

import contextlib
import io
import os
from typing import IO

from rich import box
from rich.console import Console
from rich.table import Table
from rich.text import Text

from ..engine.degeneracy import CONDITION_WARNING
from ..results import KINDS

__all__ = [
    "TableWriter",
    "BasisTableWriter",
    "CheckTableWriter",
    "OffTangentTable",
    "TangentTable",
    "WRITERS",
    "console",
    "fmt_number",
    "fmt_vector",
]


class _TextView(io.TextIOWrapper):
    """A text view of a binary stream that leaves the stream open when it goes."""

    def __del__(self):
        with contextlib.suppress(ValueError):  # already detached, or the stream was closed by its owner
            self.detach()


def console(out: IO[bytes] | IO[str], color: bool | None = None, width: int | None = None) -> Console:
    """A rich console on ``out``: colour only on a terminal and never under NO_COLOR."""
    if isinstance(out, io.TextIOBase):
        text = out
    else:
        text = _TextView(out, encoding="utf-8", write_through=True)
    terminal = color if color is not None else (text.isatty() and not os.environ.get("NO_COLOR"))
    return Console(
        file=text,
        force_terminal=terminal,
        no_color=not terminal,
        highlight=False,
        width=width if width or terminal else 160,
        soft_wrap=False,
    )


def fmt_number(v, digits: int) -> str:
    """``v`` with ``digits`` decimals; no ``-0``; ``-`` for a missing value."""
    if v is None:
        return "-"
    s = f"{float(v):.{digits}f}"
    return s[1:] if s.startswith("-") and float(s) == 0 else s


def fmt_vector(v, digits: int) -> str:
    """A 3-vector as ``(a, b, c)`` or a screw as ``(a, b, c; d, e, f)``."""
    parts = [fmt_number(x, digits) for x in v]
    if len(parts) == 6:
        return f"({', '.join(parts[:3])}; {', '.join(parts[3:])})"
    return f"({', '.join(parts)})"


class _Writer:
    """Common start of the table writers: a console and a record counter."""

    def __init__(
        self,
        out: IO[bytes],
        digits: int = 4,
        color: bool | None = None,
        width: int | None = None,
        order: str = "omega-v",
    ):
        self.con = console(out, color, width)
        self.digits = digits
        self.count = 0
        # screws are printed in the order asked for; say which when it is not the paper's
        self.order_note = "  (screws as (v; omega))" if order == "v-omega" else ""

    def write(self, rec: dict) -> None:
        if "error" in rec:  # the error line is on stderr; tables carry results only
            return
        if self.count:
            self.con.print()
        self.count += 1
        self.show(rec)

    def close(self) -> None:
        pass

    def title(self, rec: dict, *more) -> Text:
        units = f" [{rec['units']}]" if rec.get("units") else ""
        return Text.assemble((rec["grasp"], "bold"), f" ({rec['file']}){units}", *more, self.order_note)


def _renderers(rec: dict) -> list:
    """``(kind, renderer)`` of every kind the record holds, in registry order."""
    return [(kind, globals()[kind.table]) for kind in KINDS if kind.key in rec]


def _shown(m) -> bool:
    """Whether a kind's object holds results (not skipped, not failed)."""
    return m is not None and "error" not in m


class TableWriter(_Writer):
    """A resolve record as tables of contacts and of each kind, then their verdicts."""

    def show(self, rec: dict) -> None:
        d = self.digits
        names = [c["name"] for c in rec["contacts"]]
        twist = rec["twist"]
        kinds = _renderers(rec)
        self.con.print(self.title(rec, "  twist ", (twist["name"], "bold"), f" = {fmt_vector(twist['screw'], d)}"))
        self.con.print(self._contacts(rec, kinds, d))
        for kind, render in kinds:
            m = rec[kind.key]
            self.con.print(_not_shown(kind, render, m) if not _shown(m) else render.resolve(m, names, d))
        for kind, render in kinds:
            if _shown(rec[kind.key]):
                for line in render.verdict(rec[kind.key], names):
                    self.con.print(line)
        for warning in rec["warnings"]:
            self.con.print(Text(f"warning: {warning}", style="yellow"))

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


def _table(*columns, numbers=()):
    """A plain table; the columns named in ``numbers`` are right-aligned."""
    t = Table(box=box.SIMPLE_HEAD, title_justify="left", title_style="bold")
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


def _products(title, names, table, d, conditioning) -> list:
    """A title line and a 3x3 table of Klein products."""
    t = _table("", *names, numbers=names)
    for i, n in enumerate(names):
        t.add_row(n, *(fmt_number(v, d) for v in table[i]))
    return [Text(f"{title}   conditioning {conditioning:.3g}", style="bold"), t]


def _screws(names, d, *columns):
    t = _table("i", *(f"{name}_i" for name, _ in columns))
    for i, n in enumerate(names):
        t.add_row(n, *(fmt_vector(screws[i], d) for _, screws in columns))
    return t


class OffTangentTable:
    """The off-tangent method (Proposition 1): amplitudes, basis screws, verdicts."""

    skipped = "the grasp has no wrist"

    @staticmethod
    def contact_columns(m, d) -> list:
        return []

    @staticmethod
    def resolve(m, names, d):
        t = _table(
            "i", "x_i", "y_i", "Sigma_i (moves finger i only)", "Psi_i (keeps finger i fixed)", numbers=("x_i", "y_i")
        )
        t.title = f"off-tangent (Proposition 1)   conditioning {m['conditioning']:.3g}"
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
            lines.append(
                f"off-tangent: Psi part: finger(s) {', '.join(held)} each held fixed in turn while the object "
                "turns about the line from the wrist through it."
            )
        if moved:
            lines.append(
                f"off-tangent: Sigma part: finger(s) {', '.join(moved)} each moved alone, about the line through the other two."
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

    @staticmethod
    def contact_columns(m, d) -> list:
        return [("normal velocity", [fmt_number(v, d) for v in m["normal_velocity"]])]

    @staticmethod
    def resolve(m, names, d):
        t = _table(
            "i", "alpha_i", "beta_i", "Theta_i (keeps finger i fixed, others slide)", numbers=("alpha_i", "beta_i")
        )
        t.title = f"tangent (Proposition 2 + off-plane rest)   conditioning {m['conditioning']:.3g}"
        for i, n in enumerate(names):
            t.add_row(n, fmt_number(m["alpha"][i], d), fmt_number(m["beta"][i], d), fmt_vector(m["theta"][i], d))
        return t

    @staticmethod
    def verdict(m, names) -> list[str]:
        """A plain sentence from the record's ``in_tangent_planes`` and ``moves``."""
        if m["in_tangent_planes"]:
            return ["verdict: tangent sliding alone realises this twist (every beta_i = 0)."]
        off = _fingers(names, m["moves"], (3, 4, 5))  # beta_i Sigma_i moves finger i off its plane
        return [
            "verdict: not realisable by tangent sliding alone: "
            f"finger(s) {', '.join(off)} must also move off their tangent planes (the beta_i Sigma_i part)."
        ]

    @staticmethod
    def basis(m, names, d) -> list:
        return [
            _screws(names, d, ("Theta", m["theta"]), ("Sigma", m["sigma"])),
            *_products("[Theta_i | Sigma_j]", names, m["theta_sigma"], d, m["conditioning"]),
        ]


class BasisTableWriter(_Writer):
    """A grasp's basis screws and their Klein products (cf. the paper's eq. 18)."""

    def show(self, rec: dict) -> None:
        d = self.digits
        names = [c["name"] for c in rec["contacts"]]
        self.con.print(self.title(rec))
        for kind, render in _renderers(rec):
            m = rec[kind.key]
            for item in render.basis(m, names, d) if _shown(m) else [_not_shown(kind, render, m)]:
                self.con.print(item)
        for warning in rec["warnings"]:
            self.con.print(Text(f"warning: {warning}", style="yellow"))


class CheckTableWriter(_Writer):
    """One line per grasp: each method's verdict and conditioning."""

    def __init__(self, out, **options):
        super().__init__(out, **options)
        self.table = _table("file", "grasp", *(k.label for k in KINDS))

    def write(self, rec: dict) -> None:
        if "error" not in rec:
            self.table.add_row(rec["file"], rec["grasp"], *(_verdict_cell(rec.get(k.key, False)) for k in KINDS))

    def close(self) -> None:
        if self.table.row_count:
            self.con.print(self.table)


def _verdict_cell(m):
    if m is False or m is None:
        return Text("skipped" if m is None else "-", style="dim")
    if "error" not in m:
        style = "yellow" if m["conditioning"] < CONDITION_WARNING else "green"
        return Text(f"ok ({m['conditioning']:.3g})", style=style)
    return Text(m["error"]["code"], style="red")


WRITERS = {"resolve": TableWriter, "basis": BasisTableWriter, "check": CheckTableWriter}


class HandTable:
    """A hand's joint rates: per finger its joints and their rates, rank, residual, conditioning."""

    skipped = "the grasp has no hand"

    @staticmethod
    def contact_columns(m, d) -> list:
        return [("finger", [f["name"] for f in m["fingers"]])]

    @staticmethod
    def resolve(m, names, d):
        from rich.console import Group

        ratio = m["velocity_limit_ratio"]
        title = "hand: joint rates" + ("" if ratio is None else f"   velocity-limit ratio {ratio:.3g}")
        t = _table("finger", "contact", "joint", "rate", "rank", "residual", "conditioning", numbers=("rate",))
        for f in m["fingers"]:
            for k, (joint, rate) in enumerate(zip(f["joints"], f["joint_rates"])):
                first = k == 0
                t.add_row(
                    f["name"] if first else "",
                    f["contact"] if first else "",
                    joint,
                    fmt_number(rate, d),
                    str(f["rank"]) if first else "",
                    f"{f['residual']:.2g}" if first else "",
                    f"{f['conditioning']:.3g}" if first else "",
                )
        return Group(Text(title, style="bold"), t)

    @staticmethod
    def verdict(m, names) -> list[str]:
        """Fingers at their velocity limits."""
        ratio = m["velocity_limit_ratio"]
        if ratio is not None and ratio > 1:
            return [f"hand: the joint rates exceed their velocity limits: slow the twist down by {ratio:.3g}."]
        return []

    @staticmethod
    def basis(m, names, d) -> list:
        return []
