"""Names from outside (file names, grasp and data-set names), made safe to write.

Whoever filled a folder chose its file names: one may hold bytes that are
not UTF-8 (Python keeps them as lone surrogates, ``os.fsdecode``), which no
JSON or CSV text can carry, and control characters (a newline, a terminal
escape) that must not split a diagnostic line or reach a terminal.  Every
writer escapes names through :func:`escaped`, so a name reads the same in
every format.
"""

from __future__ import annotations

__all__ = ["escaped", "escaped_each"]

_SURROGATES = range(0xD800, 0xE000)
_ESCAPED_BYTES = range(0xDC80, 0xDD00)  # what surrogateescape makes of the bytes 0x80-0xff


def escaped(text, controls: bool = True):
    r"""``text`` as valid UTF-8: each byte that was not UTF-8 as ``\xNN`` and,
    with ``controls``, control and separator characters escaped too.

    Data formats (JSON, CSV) escape only what they cannot hold
    (``controls=False``): a newline in a name is data there.  Values that
    are not text (None, numbers) are returned as they are.

    >>> escaped("b\udcff.yaml"), escaped("a\nb"), escaped("a\nb", controls=False)
    ('b\\xff.yaml', 'a\\nb', 'a\nb')
    >>> escaped(b"caf\xc3\xa9 \xff")
    'café \\xff'
    """
    if isinstance(text, bytes):
        text = text.decode("utf-8", "surrogateescape")
    if not isinstance(text, str) or text.isprintable() or (not controls and text.isascii()):
        return text
    return "".join(_char(c, controls) for c in text)


def _char(c: str, controls: bool) -> str:
    code = ord(c)
    if code in _ESCAPED_BYTES:
        return f"\\x{code - 0xDC00:02x}"
    if code in _SURROGATES or (controls and not c.isprintable()):
        return c.encode("unicode_escape").decode("ascii")
    return c


def escaped_each(values, controls: bool = False) -> list[str]:
    r""":func:`escaped` of each value, each distinct one escaped once (labels repeat).

    >>> escaped_each(["a", "b\udcff", "a"])
    ['a', 'b\\xff', 'a']
    """
    safe = {v: escaped(v, controls) for v in set(values)}
    return [safe[v] for v in values]
