"""Numbers for people: every figure a table, a summary or a message shows.

Records keep full precision; what people read never shows digits below the
computation's noise, which differ from one processor to the next (numpy's
OpenBLAS picks a kernel per processor, and each rounds LAPACK's last digits
its own way and may turn ``0.0`` into ``-0.0``).  So a value is rounded to
what is meaningful, a zero never has a sign, and a figure under
:data:`~grasptwist.engine.degeneracy.NOISE_FLOOR` prints as ``< 1e-12``
whatever its digits were.  No rich here: machine formats import this too.
"""

from __future__ import annotations

import functools
import math

from ..engine.degeneracy import NOISE_FLOOR

__all__ = ["fmt_number", "fmt_vector", "fmt_figure", "UNDER_NOISE", "EXPONENT_FROM"]

#: How a figure under the noise floor prints.
UNDER_NOISE = f"< {NOISE_FLOOR:g}"

#: From this size on a number prints in exponent form, ``1.0000e+300``: in fixed point it
#: would be as many digits long as it is large (and show digits below the noise).
EXPONENT_FROM = 1e6


def fmt_number(v, digits: int) -> str:
    """``v`` with ``digits`` decimals, in exponent form from :data:`EXPONENT_FROM` on;
    no ``-0``; ``-`` for a missing value.

    >>> fmt_number(-0.00001, 4), fmt_number(-0.0, 4), fmt_number(2.5, 0), fmt_number(None, 3)
    ('0.0000', '0.0000', '2', '-')
    >>> fmt_number(12.5, 4), fmt_number(1e300, 4), fmt_number(-2.5e6, 2), fmt_number(float("inf"), 4)
    ('12.5000', '1.0000e+300', '-2.50e+06', 'inf')
    """
    if v is None:
        return "-"
    if abs(v) >= EXPONENT_FROM:
        return f"{v:.{digits}e}"
    s = f"{v:.{digits}f}"
    return s[1:] if s[0] == "-" and not s.strip("-0.") else s


def fmt_vector(v, digits: int) -> str:
    """A 3-vector as ``(a, b, c)`` or a screw as ``(a, b, c; d, e, f)``, each part as
    :func:`fmt_number` prints it; no ``-0``.

    >>> fmt_vector([1, 0, -0.00001, 0, -0.5, 2], 1), fmt_vector([1e300, -0.0, 2], 2)
    ('(1.0, 0.0, 0.0; 0.0, -0.5, 2.0)', '(1.00e+300, 0.00, 2.00)')
    """
    v = tuple(v)
    if any(abs(x) >= EXPONENT_FROM for x in v):  # rare: each part its own form
        parts = [fmt_number(x, digits) for x in v]
        return f"({', '.join(parts[:3])}; {', '.join(parts[3:])})" if len(v) == 6 else f"({', '.join(parts)})"
    form, negative_zero, zero = _vector_format(digits, len(v))
    return (form % v).replace(negative_zero, zero)


@functools.cache
def _vector_format(digits: int, n: int) -> tuple[str, str, str]:
    """The %-format of an ``n``-vector (a screw's halves split by ``;``), and
    zero printed with and without a sign: with exactly ``digits`` decimals,
    ``-0.00`` in a vector can only be a whole number, a negative zero."""
    number = f"%.{digits}f"
    form = f"({', '.join([number] * 3)}; {', '.join([number] * 3)})" if n == 6 else f"({', '.join([number] * n)})"
    zero = number % 0.0
    return form, "-" + zero, zero


def fmt_figure(v, significant: int = 3) -> str:
    """A figure whose size is the news (a residual, an error, a conditioning, a ratio) to
    ``significant`` digits; under the noise floor, zero included, ``< 1e-12``; ``-`` for a
    missing value.

    A residual of ``3e-16`` on one processor and ``6.1e-16`` on another prints the same:

    >>> fmt_figure(3e-16, 2), fmt_figure(6.1e-16, 2), fmt_figure(-0.0), fmt_figure(0.0123456)
    ('< 1e-12', '< 1e-12', '< 1e-12', '0.0123')
    >>> fmt_figure(8.3e-05, 2), fmt_figure(None), fmt_figure(float("nan"))
    ('8.3e-05', '-', 'nan')
    """
    if v is None:
        return "-"
    if math.isfinite(v) and abs(v) < NOISE_FLOOR:
        return UNDER_NOISE
    return f"{v:.{significant}g}"
