"""Fuzzing the command line's options: every value either parses into the option's bounded
type (a whole number, a finite real within the option's range, a bin count the spectral EXR
layout can store) or ends in one line ``spectral-gi: error: ...`` with exit status 2."""
import contextlib
import io
import math

import pytest
from hypothesis import given
from hypothesis import strategies as st

from spectral_gi import cli
from spectral_gi.core.film import MAX_SPECTRAL_BINS

pytestmark = pytest.mark.fuzz

OPTIONS = {  # option: (kind, lo, hi)
    "--spp": ("int", 1, cli.MAX_OPTION_INT), "--width": ("int", 1, cli.MAX_OPTION_INT),
    "--height": ("int", 1, cli.MAX_OPTION_INT), "--max-depth": ("int", 0, cli.MAX_OPTION_INT),
    "--seed": ("int", 0, cli.MAX_OPTION_INT), "--threads": ("int", 0, cli.MAX_THREADS),
    "--spectral-bins": ("int", 0, MAX_SPECTRAL_BINS), "--time-limit": ("float", 0.0, 1e9),
    "--noise-target": ("float", 0.0, 1e6), "--exposure": ("float", -cli.MAX_EXPOSURE, cli.MAX_EXPOSURE),
}
DEST = {k: k[2:].replace("-", "_") for k in OPTIONS}
values = st.one_of(
    st.sampled_from(["1_0", "1e9", "1e999", "nan", "inf", "-0", "0x10", "٣", " 5", "5 ", "", "+7", "1.0", "50000",
                     "471", "472", "-1", "9" * 300, "1e-400", "0.5e1"]),
    st.integers(-10 ** 12, 10 ** 12).map(str), st.floats(allow_nan=True, allow_infinity=True).map(repr),
    st.text(max_size=8))


@given(st.sampled_from(sorted(OPTIONS)), values)
def test_numeric_options_parse_within_bounds_or_give_one_line(option, text):
    kind, lo, hi = OPTIONS[option]
    buf = io.StringIO()
    try:
        with contextlib.redirect_stderr(buf):
            args = cli._parser().parse_args(["render", f"{option}={text}"])
    except SystemExit as e:
        assert e.code == 2
        err = buf.getvalue()
        assert len(err.strip().splitlines()) == 1 and err.startswith("spectral-gi: error:"), err
        return
    v = getattr(args, DEST[option])
    if kind == "int":
        assert type(v) is int and lo <= v <= hi and text.strip().lstrip("+-").isdigit() and "_" not in text
    else:
        assert type(v) is float and math.isfinite(v) and lo <= v <= hi and "_" not in text
