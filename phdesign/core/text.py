r"""How results show themselves: numbers, matrices, sensors and small HTML tables.

One formatter per kind of value, shared by every result object (its ``__str__``, which is
the text the command line prints, its ``__repr__`` and its ``_repr_html_``), so that the
same number reads the same everywhere: a constant :math:`\\kappa^*` is printed with six
significant digits wherever it appears, an exact gain entry as the decimal the user wrote
(``0.1``, not ``1/10``) when it has one.  Standard library only: sympy values are read
through their attributes, never imported here.

Examples
--------
>>> from fractions import Fraction
>>> number_text(Fraction(1, 10)), number_text(Fraction(1, 3)), number_text(0.4000000000000001)
('0.1', '1/3', '0.4')
>>> html_table(["a", "b"], [[1, "<x>"]])
'<table><thead><tr><th>a</th><th>b</th></tr></thead><tbody><tr><td>1</td><td>&lt;x&gt;</td></tr></tbody></table>'
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence
from typing import Any

__all__ = [
    "REPR_LIMIT",
    "did_you_mean",
    "gain_text",
    "html_table",
    "kappa_text",
    "matrix_text",
    "measured_text",
    "number_text",
    "sensors_text",
    "shorten",
    "split_top_level",
    "text_table",
]

#: Longest ``repr`` of a result object.
REPR_LIMIT = 300


def _fraction(x: Any) -> tuple[int, int] | None:
    """``(numerator, denominator)`` of an exact rational (int, Fraction, sympy Rational)."""
    if isinstance(x, bool):
        return None
    if isinstance(x, int):
        return x, 1
    p, q = getattr(x, "numerator", None), getattr(x, "denominator", None)
    if getattr(x, "is_Rational", False):
        p, q = x.p, x.q
    if isinstance(p, int) and isinstance(q, int) and not isinstance(x, float):
        return p, q
    return None


#: Longest exact number printed in full; longer ones get six digits in scientific notation.
LONG_NUMBER = 28


def _scientific(p: int, q: int) -> str:
    """``p/q`` with six significant digits, never underflowing: 1/10**500 is ``1.0e-500``."""
    import mpmath

    return str(mpmath.nstr(mpmath.mpf(p) / q, 6))


def number_text(x: Any) -> str:
    """Return a number as a person writes it.

    Integers as integers; exact rationals as their decimal when it terminates within 20
    digits (``1/10`` is ``0.1``, a float read exactly shows as written), else as a
    fraction; floats with six significant digits;
    anything else (an expression of symbolic gains) as sympy prints it.
    """
    exact = _fraction(x)
    if exact is not None:
        p, q = exact
        if q == 1:
            return str(p) if len(str(p)) <= LONG_NUMBER else _scientific(p, 1)
        rest = q
        for prime in (2, 5):
            while rest % prime == 0:
                rest //= prime
        if rest == 1:
            digits = 0
            while (p * 10**digits) % q:
                digits += 1
            if digits <= 20:
                sign = "-" if p < 0 else ""
                whole, frac = divmod(abs(p) * 10**digits // q, 10**digits)
                return f"{sign}{whole}.{str(frac).rjust(digits, '0')}"
        text = f"{p}/{q}"
        return text if len(text) <= LONG_NUMBER else _scientific(p, q)
    if getattr(x, "is_Float", False) and x != 0 and float(x) in (0.0, float("inf"), -float("inf")):
        import mpmath  # a sympy Float beyond double range (a kappa* of 1e-500): never 0

        return str(mpmath.nstr(mpmath.mpf(x._mpf_), 6))
    if isinstance(x, float) or getattr(x, "is_Float", False):
        return f"{float(x):.6g}"
    return str(x)


def kappa_text(exact: Any, value: float | None, unbounded: bool = False) -> str:
    r"""Return :math:`\kappa^*` as text: ``unbounded``, six digits, or the expression."""
    if unbounded:
        return "unbounded"
    if value is not None:
        return f"{value:.6g}"
    if exact is None:
        return "—"
    return number_text(exact)


def matrix_text(M: Any) -> str:
    """Return a small matrix as text: ``diag(0.1, 1)`` when diagonal, else its rows."""
    rows = [list(r) for r in (M.tolist() if hasattr(M, "tolist") else M)]
    square = all(len(r) == len(rows) for r in rows)
    if square and all(
        rows[i][j] == 0 for i in range(len(rows)) for j in range(len(rows)) if i != j
    ):
        return f"diag({', '.join(number_text(rows[i][i]) for i in range(len(rows)))})"
    return "[" + ", ".join("[" + ", ".join(number_text(x) for x in r) + "]" for r in rows) + "]"


def sensors_text(C_m: Any) -> str:
    """Return the measurements ``C_m y`` as text: ``y3, y4``, or ``0.5·y3 + y4``."""
    parts = []
    for row in C_m.tolist() if hasattr(C_m, "tolist") else C_m:
        terms = []
        for j, c in enumerate(row):
            if c == 0:
                continue
            name = f"y{j + 1}"
            terms.append(name if c == 1 else f"-{name}" if c == -1 else f"{number_text(c)}·{name}")
        parts.append(" + ".join(terms).replace("+ -", "- "))
    return ", ".join(parts)


def _float_rows(M: Any) -> list[list[float]]:
    """Return a number, a vector or a matrix (numpy or nested lists) as rows of floats."""
    value = M.tolist() if hasattr(M, "tolist") else M
    if not isinstance(value, list | tuple):
        return [[float(value)]]
    if not value or not isinstance(value[0], list | tuple):
        return [[float(x) for x in value]]
    return [[float(x) for x in row] for row in value]


def gain_text(L: Any) -> str:
    """Return a numeric gain as text: ``diag(0.1, 1)`` (six digits), else its rows (eight).

    Examples
    --------
    >>> gain_text([[0.1, 0], [0, 1]]), gain_text([[1, 0.5], [0, 1]])
    ('diag(0.1, 1)', '[[1.0, 0.5], [0.0, 1.0]]')
    """
    rows = _float_rows(L)
    size = min(len(rows), len(rows[0]) if rows else 0)
    # diagonal: every other entry zero and the diagonal finite (x - x is NaN for inf and NaN)
    if all((x - x if i == j else x) == 0 for i, row in enumerate(rows) for j, x in enumerate(row)):
        return f"diag({', '.join(f'{rows[i][i]:.6g}' for i in range(size))})"
    return str([[float(f"{x:.8g}") for x in row] for row in rows])


def measured_text(C_m: Any) -> str:
    """Return numeric sensors as text: ``y3, y4`` when each row picks one output, else rows.

    Examples
    --------
    >>> measured_text([[0, 0, 1, 0], [0, 0, 0, 1]]), measured_text([[0.5, 1]])
    ('y3, y4', 'C_m = [[0.5, 1.0]]')
    """
    rows = _float_rows(C_m)
    if all([x for x in row if x != 0] == [1.0] for row in rows):
        return sensors_text(rows)
    return f"C_m = {rows}"


def shorten(text: str, limit: int) -> str:
    """Cut ``text`` to ``limit`` characters, marking the cut with an ellipsis."""
    return text if len(text) <= limit else text[: limit - 1] + "…"


def html_table(
    headers: Sequence[str],
    rows: Iterable[Sequence[Any]],
    caption: str | None = None,
    footer: str | None = None,
) -> str:
    """Return a small HTML table (escaped), for the ``_repr_html_`` of result objects.

    The package's one table: ``headers`` name the columns (none: a table of name and value
    rows), ``caption`` goes above it and ``footer`` below.

    Examples
    --------
    >>> html_table([], [["order", 12]], caption="export")
    '<p><b>export</b></p><table><tbody><tr><td>order</td><td>12</td></tr></tbody></table>'
    """
    import html  # the notebook view only; the command line prints text

    head = "".join(f"<th>{html.escape(str(h))}</th>" for h in headers)
    body = "".join(
        "<tr>" + "".join(f"<td>{html.escape(str(c))}</td>" for c in row) + "</tr>" for row in rows
    )
    thead = f"<thead><tr>{head}</tr></thead>" if head else ""
    out = f"<table>{thead}<tbody>{body}</tbody></table>"
    if caption:
        out = f"<p><b>{html.escape(caption)}</b></p>" + out
    if footer:
        out += f"<p>{html.escape(footer)}</p>"
    return out


def text_table(headers: Sequence[str], rows: Iterable[Sequence[Any]]) -> list[str]:
    """Return the lines of a plain-text table: columns padded to their widest cell.

    The text twin of :func:`html_table`, for the ``__str__`` of result objects.

    Examples
    --------
    >>> text_table(["mode", "ω"], [[1, "3.516"], [2, "22.03"]])
    ['mode  ω', '1     3.516', '2     22.03']
    """
    cells = [[str(h) for h in headers]] + [[str(c) for c in row] for row in rows]
    widths = [max(len(row[j]) for row in cells) for j in range(len(headers))]
    return [
        "  ".join(c.ljust(w) for c, w in zip(row, widths, strict=True)).rstrip() for row in cells
    ]


def did_you_mean(name: object, choices: Iterable[str]) -> str:
    """Return ``" (did you mean 'x'?)"`` for the choice closest to ``name``, or "".

    :func:`difflib.get_close_matches` with its default cutoff (0.6).

    Examples
    --------
    >>> did_you_mean("euler-bernouli", ["wave", "euler-bernoulli"])
    " (did you mean 'euler-bernoulli'?)"
    >>> did_you_mean("xyz", ["wave"])
    ''
    """
    import difflib  # only on a miss: every command's start would pay for it

    close = difflib.get_close_matches(str(name), list(choices), n=1)
    return f" (did you mean {close[0]!r}?)" if close else ""


def split_top_level(text: str) -> list[str]:
    """Split on commas that are not inside parentheses or brackets."""
    parts: list[str] = []
    cur: list[str] = []
    depth = 0
    for ch in text:
        if ch in "([":
            depth += 1
        elif ch in ")]":
            depth -= 1
        if ch == "," and depth == 0:
            parts.append("".join(cur))
            cur = []
        else:
            cur.append(ch)
    parts.append("".join(cur))
    return [p for p in parts if p.strip()]
