"""Tables for people, drawn with rich from output records.

Imported only when a table is asked for, so that machine formats never pay
for rich's import.  Numbers are rounded to ``digits`` decimals here and only
here; records keep full precision.
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

__all__ = ["TableWriter", "BasisTableWriter", "CheckTableWriter", "WRITERS", "console", "fmt_number", "fmt_vector"]


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


class TableWriter(_Writer):
    """A resolve record as tables of contacts and of each method, then a verdict."""

    def show(self, rec: dict) -> None:
        d = self.digits
        names = [c["name"] for c in rec["contacts"]]
        twist = rec["twist"]
        self.con.print(self.title(rec, "  twist ", (twist["name"], "bold"), f" = {fmt_vector(twist['screw'], d)}"))
        self.con.print(self._contacts(rec, d))
        off = rec.get("off_tangent", False)
        if off is not False:
            self.con.print(self._off_tangent(off, names, d))
        tan = rec.get("tangent")
        if tan is not None:
            self.con.print(self._tangent(tan, names, d))
        for line in _verdict(rec, names):
            self.con.print(line)
        for warning in rec["warnings"]:
            self.con.print(Text(f"warning: {warning}", style="yellow"))

    def _contacts(self, rec, d):
        t = _table("contact", "point", "normal (unit)", "velocity T(p_i)")
        tan = rec.get("tangent") or {}
        if "normal_velocity" in tan:
            t.add_column("normal velocity", justify="right")
        for i, c in enumerate(rec["contacts"]):
            row = [c["name"], fmt_vector(c["point"], d), fmt_vector(c["normal"], d)]
            row.append(fmt_vector(rec["contact_velocity"][i], d))
            if "normal_velocity" in tan:
                row.append(fmt_number(tan["normal_velocity"][i], d))
            t.add_row(*row)
        return t

    def _off_tangent(self, m, names, d):
        if m is None:
            return Text("off-tangent: skipped (the grasp has no wrist)", style="dim")
        if "error" in m:
            return _error_text("off-tangent", m)
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

    def _tangent(self, m, names, d):
        if "error" in m:
            return _error_text("tangent", m)
        t = _table(
            "i", "alpha_i", "beta_i", "Theta_i (keeps finger i fixed, others slide)", numbers=("alpha_i", "beta_i")
        )
        t.title = f"tangent (Proposition 2 + off-plane rest)   conditioning {m['conditioning']:.3g}"
        for i, n in enumerate(names):
            t.add_row(n, fmt_number(m["alpha"][i], d), fmt_number(m["beta"][i], d), fmt_vector(m["theta"][i], d))
        return t


def _table(*columns, numbers=()):
    """A plain table; the columns named in ``numbers`` are right-aligned."""
    t = Table(box=box.SIMPLE_HEAD, title_justify="left", title_style="bold")
    for c in columns:
        t.add_column(c, justify="right" if c in numbers else "left")
    return t


def _error_text(method, m):
    return Text(f"{method}: failed: {m['error']['code']}: {m['error']['message']}", style="red")


def _nonzero(names, values, reference):
    """Names whose value is not round-off next to the largest of ``reference``."""
    floor = 1e-9 * max((abs(float(v)) for v in _flat(reference)), default=0.0)
    return [n for n, v in zip(names, values) if abs(float(v)) > floor]


def _flat(values):
    for v in values:
        yield from (_flat(v) if hasattr(v, "__len__") else (v,))


def _verdict(rec, names):
    """Plain sentences on what the fingers must do."""
    lines = []
    tan = rec.get("tangent")
    if tan and "error" not in tan:
        if tan["in_tangent_planes"]:
            lines.append("verdict: tangent sliding alone realises this twist (every beta_i = 0).")
        else:
            off = _nonzero(names, tan["normal_velocity"], rec["contact_velocity"])
            lines.append(
                "verdict: not realisable by tangent sliding alone: "
                f"finger(s) {', '.join(off)} must also move off their tangent planes (the beta_i Sigma_i part)."
            )
    off = rec.get("off_tangent")
    if off and "error" not in off:
        amplitudes = list(off["x"]) + list(off["y"])
        held = _nonzero(names, off["y"], amplitudes)
        moved = _nonzero(names, off["x"], amplitudes)
        if held:
            lines.append(
                f"off-tangent: Psi part: finger(s) {', '.join(held)} each held fixed in turn while the object "
                "turns about the line from the wrist through it."
            )
        if moved:
            lines.append(
                f"off-tangent: Sigma part: finger(s) {', '.join(moved)} each moved alone, about the line through the other two."
            )
        elif held:
            lines.append("off-tangent: the twist is a rotation about the wrist: the wrist alone could make it.")
    return lines


class BasisTableWriter(_Writer):
    """A grasp's basis screws and their Klein products (cf. the paper's eq. 18)."""

    def show(self, rec: dict) -> None:
        d = self.digits
        names = [c["name"] for c in rec["contacts"]]
        self.con.print(self.title(rec))
        off, tan = rec.get("off_tangent", False), rec.get("tangent")
        if off is None:
            self.con.print(Text("off-tangent: skipped (the grasp has no wrist)", style="dim"))
        elif off is not False and "error" in off:
            self.con.print(_error_text("off-tangent", off))
        elif off is not False:
            self._screws(names, d, ("Sigma", off["sigma"]), ("Psi", off["psi"]))
            self._products("[Sigma_i | Psi_j]", names, off["sigma_psi"], d, off["conditioning"])
        if tan is not None and "error" in tan:
            self.con.print(_error_text("tangent", tan))
        elif tan is not None:
            self._screws(names, d, ("Theta", tan["theta"]), ("Sigma", tan["sigma"]))
            self._products("[Theta_i | Sigma_j]", names, tan["theta_sigma"], d, tan["conditioning"])
        for warning in rec["warnings"]:
            self.con.print(Text(f"warning: {warning}", style="yellow"))

    def _screws(self, names, d, *columns):
        t = _table("i", *(f"{name}_i" for name, _ in columns))
        for i, n in enumerate(names):
            t.add_row(n, *(fmt_vector(screws[i], d) for _, screws in columns))
        self.con.print(t)

    def _products(self, title, names, table, d, conditioning):
        self.con.print(Text(f"{title}   conditioning {conditioning:.3g}", style="bold"))
        t = _table("", *names, numbers=names)
        for i, n in enumerate(names):
            t.add_row(n, *(fmt_number(v, d) for v in table[i]))
        self.con.print(t)


class CheckTableWriter(_Writer):
    """One line per grasp: each method's verdict and conditioning."""

    def __init__(self, out, **options):
        super().__init__(out, **options)
        self.table = _table("file", "grasp", "off-tangent", "tangent")

    def write(self, rec: dict) -> None:
        if "error" not in rec:
            self.table.add_row(
                rec["file"],
                rec["grasp"],
                _verdict_cell(rec.get("off_tangent", False)),
                _verdict_cell(rec.get("tangent")),
            )

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
