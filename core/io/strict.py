"""Strict parsing of numbers in text (command-line options, photometric and spectrum files).

Python's ``int`` and ``float`` accept more than a file format or an option means: digit
group underscores (``int("1_0") == 10``), ``nan``, ``inf``, ``infinity``, non-ASCII digits
and surrounding white space. These parsers accept plain ASCII decimal notation only:
``[+-]digits`` for integers, and ``[+-]digits[.digits][e[+-]digits]`` (or ``.digits``)
for reals, and reject anything else with ValueError.
"""
import math
import re

_INT = re.compile(r"[+-]?[0-9]+", re.ASCII)
_FLOAT = re.compile(r"[+-]?(?:[0-9]+\.?[0-9]*|\.[0-9]+)(?:[eE][+-]?[0-9]+)?", re.ASCII)
MAX_DIGITS = 400  # longer numbers are not numbers a file or option means


def parse_int(text):
    """An integer written in plain decimal; ValueError otherwise."""
    if not isinstance(text, str) or len(text) > MAX_DIGITS or not _INT.fullmatch(text):
        raise ValueError(f"{text!r} is not a whole number")
    return int(text)


def parse_float(text, finite=True):
    """A real number written in plain decimal or scientific notation; ValueError otherwise
    (and for values that overflow to infinity when ``finite``)."""
    if not isinstance(text, str) or len(text) > MAX_DIGITS or not _FLOAT.fullmatch(text):
        raise ValueError(f"{text!r} is not a number")
    v = float(text)
    if finite and not math.isfinite(v):
        raise ValueError(f"{text!r} is not a finite number")
    return v


def is_number_text(text):
    """Whether ``text`` is a real number :func:`parse_float` reads (finite or not)."""
    return isinstance(text, str) and len(text) <= MAX_DIGITS and _FLOAT.fullmatch(text) is not None
