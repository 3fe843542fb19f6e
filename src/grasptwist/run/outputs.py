"""What a run gives back per piece of work: encoded records, their stderr lines and counts.

Every command's run (the pipeline's groups and data sets, ``follow``'s
paths) yields :class:`Output` objects; the command line writes their
records and tells their lines (:func:`grasptwist.cli.records.write_records`).
"""

from __future__ import annotations

from dataclasses import dataclass, field

from ..output.records import diagnostics, failure_codes

__all__ = ["Output"]


@dataclass(eq=False)  # never compared: a run adds to it
class Output:
    """The encoded records of one group, with their stderr lines and counts."""

    encoded: list = field(default_factory=list)
    errors: list[str] = field(default_factory=list)  # always printed
    row_errors: list[str] = field(default_factory=list)  # of a data set's or stream's rows: printed like warnings
    warnings: list[str] = field(default_factory=list)
    notes: list[str] = field(default_factory=list)  # what a run says of itself (synthesize's search): not with -q
    records: int = 0
    failed: int = 0  # records not ok: inputs that failed, and grasps (or rows) with a degenerate method
    inputs_failed: int = 0  # of ``failed``: inputs (files, documents, lines of a stream) that could not be read
    degenerate: dict = field(default_factory=dict)  # of the other failed records: per (kind, code), how many
    done: int = 0  # progress: files read, or data-set records made
    extra_work: int = 0  # progress: work found beyond the one unit an input was counted as
    spool: str | None = None  # a file holding ``encoded`` (see _sealed)
    rows: bool = False  # records of a data set's or stream's rows: their errors are row_errors

    def add(self, rec: dict, encode) -> None:
        self._note(rec)
        self.records += 1
        self.encoded.append(encode(rec))

    def add_encoded(self, texts: list[bytes], talking: list[dict]) -> None:
        """Records already encoded; ``talking`` are those with errors or warnings."""
        for rec in talking:
            self._note(rec)
        self.records += len(texts)
        self.encoded += texts

    def _note(self, rec: dict) -> None:
        errors, warnings = diagnostics(rec)
        # a whole input that cannot be read (no line: a data set, a stream's file) is never a row
        row = self.rows and not ("error" in rec and rec["error"]["line"] is None)
        (self.row_errors if row else self.errors).extend(errors)
        self.warnings += warnings
        self.count(rec)

    def count(self, rec: dict) -> None:
        """Count a record that is not ok: an input that failed, or by the codes of its failed kinds."""
        self.failed += not rec["ok"]
        if "error" in rec:
            self.inputs_failed += 1
        elif not rec["ok"]:
            for code in failure_codes(rec):
                self.degenerate[code] = self.degenerate.get(code, 0) + 1
