"""The ``follow`` table: a compact timeline per path, then its summary in words.

Plain fixed-width text, written as the records come (one line per sample),
so a long path streams and needs no memory; it reads the records only (see
:mod:`grasptwist.output.follow_records`).  Each sample line holds the time,
the segment, the pose (position, quaternion w first), and per method its
amplitudes and conditioning, or the code of its failure; with a hand, a
line under it holds each finger's joint positions and tip error.
"""

from __future__ import annotations

from typing import IO

from .follow_records import crossing_text, hand_event_texts, hold_text, unjudged_text
from .names import escaped
from .numbers import fmt_figure, fmt_number

__all__ = ["FollowTable"]

#: Per method: its record key, label and the amplitudes shown.
_METHODS = (("off_tangent", "off-tangent", ("x", "y")), ("tangent", "tangent", ("alpha", "beta")))


class FollowTable:
    """A writer of follow records as a table (``write(record)``, ``close()``)."""

    def __init__(self, out: IO[bytes], digits: int = 4, order: str = "omega-v", **_):
        self.out = out
        self.digits = digits
        self.width = digits + 4  # sign, up to two digits before the point, the point
        self.current = None  # (file, grasp, path) of the timeline being written
        self.names = ("1", "2", "3")  # its contacts' names

    def _number(self, v) -> str:
        return "-" if v is None else f"{fmt_number(v, self.digits):>{self.width}}"

    def _vector(self, v) -> str:
        return " ".join(self._number(float(a)) for a in v)

    def _line(self, text: str = "") -> None:
        self.out.write(text.encode() + b"\n")

    def _header(self, rec, methods):
        vector = 3 * (self.width + 1) - 1
        cells = [
            f"{'t':>{self.width}}",
            "seg",
            f"{'position':<{vector}}",
            f"{'rotation (w x y z)':<{vector + self.width + 1}}",
        ]
        for _, label, amplitudes in methods:
            cells += [f"{f'{label} {a}':<{vector}}" for a in amplitudes] + [f"{'cond':>{self.width}}"]
        if self.current is not None:
            self._line()
        self._line(f"{escaped(rec['file'])}: grasp '{escaped(rec['grasp'])}', path '{escaped(rec['path'])}'")
        self._line("  ".join(cells).rstrip())

    def write(self, rec: dict) -> None:
        if "error" in rec:  # the error line is on stderr; tables carry results only
            return
        if "summary" in rec:
            self._summary(rec)
            self.current = None
            return
        methods = [m for m in _METHODS if m[0] in rec]
        here = (rec["file"], rec["grasp"], rec["path"])
        if here != self.current:
            self._header(rec, methods)
            self.current = here
            self.names = tuple(c["name"] for c in rec["contacts"])
        pose = rec["pose"]
        cells = [
            self._number(rec["t"]),
            f"{rec['segment']:>3}",
            self._vector(pose["position"]),
            self._vector(pose["rotation"]),
        ]
        vector = 3 * (self.width + 1) - 1
        for key, _, amplitudes in methods:
            m = rec[key]
            if m is None or "error" in m:
                text = "-" if m is None else m["error"]["code"]
                cells += [f"{text:<{len(amplitudes) * (vector + 2) - 2}}", f"{'-':>{self.width}}"]
            else:
                cells += [self._vector(m[a]) for a in amplitudes] + [self._number(m["conditioning"])]
        self._line("  ".join(cells).rstrip())
        if isinstance(rec.get("hand"), dict):
            self._hand_line(rec["hand"])

    def _hand_line(self, hand) -> None:
        """Under a sample, where its fingers are: each one's joint positions and tip error, and for a
        fingertip with a radius its gap to the surface (< 0: into it)."""
        parts = []
        for f in hand["fingers"]:
            if "joint_positions" not in f:
                continue
            error = fmt_figure(f["tip_error"])
            limits = "" if f["within_limits"] else " (outside its limits)"
            q = " ".join(fmt_number(v, self.digits) for v in f["joint_positions"])
            gap = f", tip gap {fmt_figure(f['tip_gap'])}" if f.get("tip_radius") else ""
            parts.append(f"finger {escaped(f['contact'])}: q {q}{limits}, tip error {error}{gap}")
        if parts:
            self._line(f"{'':>{self.width}}  hand  " + "; ".join(parts))

    def _summary(self, rec):
        s = rec["summary"]
        self._line(f"summary: duration {fmt_number(s['duration'], self.digits)}, {s['samples']} samples")
        for c in s["degenerate"]:
            self._line(f"  {crossing_text(c, self.names, self.digits)} ({c['method']} degenerate)")
        if not s["degenerate"]:
            self._line("  no degeneracy along the path")
        smallest = [
            f"{key.replace('_', '-')} {fmt_figure(m['value'], self.digits)} at t = {fmt_number(m['t'], self.digits)}"
            for key, m in s["min_conditioning"].items()
            if m is not None and m["value"] == m["value"]  # a failed method may have none (NaN)
        ]
        if smallest:
            self._line(f"  smallest conditioning: {'; '.join(smallest)}")
        w = s["first_warning"]
        self._line(
            "  no conditioning warning"
            if w is None
            else f"  first warning: {w['method']} at t = {fmt_number(w['t'], self.digits)}"
        )
        if "cannot_hold" in s:
            for c in s["cannot_hold"]:
                self._line(f"  {hold_text(c, self.digits)}")
            for u in s["hold_unjudged"]:
                self._line(f"  {unjudged_text(u, self.digits)}")
            if not s["cannot_hold"] and not s["hold_unjudged"]:
                self._line("  the weight is held all along the path")
        if "hand" in s:
            errors, warnings = hand_event_texts(s["hand"], self.names, self.digits)
            for text in errors + warnings:
                self._line(f"  hand: {text}")
            if not errors and not warnings:
                self._line("  hand: every finger follows, within its joint limits and well conditioned")

    def close(self) -> None:
        self.out.flush()
