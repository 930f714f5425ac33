"""Sensor points in and results out: Radiance-style ``.pts`` files and the results CSV.

A ``.pts`` file (the input of Radiance's ``rtrace -I+``) holds one sensor point a line,
``x y z nx ny nz`` in metres, separated by white space; blank lines and everything after
a ``#`` are ignored. Normals are normalised on reading. The results CSV holds one row per
input point in input order with the header :data:`RESULTS_HEADER`.
"""

from __future__ import annotations

import math
import os
from pathlib import Path

import numpy as np

from ..io.atomic import write_text

RESULTS_HEADER = "x,y,z,nx,ny,nz,lux,std_error"


class LuxError(ValueError):
    """Bad input to a lighting calculation: a malformed file, surface or value array."""


def parse_pts(text: str, source: str = "<string>") -> tuple[np.ndarray, np.ndarray]:
    """Parse the text of a ``.pts`` file: ``(points (N, 3), unit normals (N, 3))``, float64.

    ``source`` names the file in error messages. A line with other than six fields, a
    field that is not a finite number or a zero normal raises :class:`LuxError` naming
    ``source`` and the line number (counted from 1); a file without points raises too.
    """
    rows = []
    for line_no, raw in enumerate(text.splitlines(), start=1):
        line = raw.split("#", 1)[0].strip()
        if not line:
            continue
        fields = line.split()
        if len(fields) != 6:
            raise LuxError(f"{source}, line {line_no}: expected 6 numbers (x y z nx ny nz), got {len(fields)}")
        try:
            row = [float(f) for f in fields]
        except ValueError:
            raise LuxError(f"{source}, line {line_no}: not a number in {fields}") from None
        if not all(math.isfinite(v) for v in row):
            raise LuxError(f"{source}, line {line_no}: non-finite number in {fields}")
        n = math.sqrt(row[3] ** 2 + row[4] ** 2 + row[5] ** 2)
        if not n > 0.0:
            raise LuxError(f"{source}, line {line_no}: the normal is zero")
        rows.append(row[:3] + [row[3] / n, row[4] / n, row[5] / n])
    if not rows:
        raise LuxError(f"{source}: no points")
    data = np.asarray(rows, dtype=np.float64)
    return data[:, :3].copy(), data[:, 3:].copy()


def read_pts(path: str | os.PathLike) -> tuple[np.ndarray, np.ndarray]:
    """Read a ``.pts`` file: ``(points (N, 3), unit normals (N, 3))`` (see :func:`parse_pts`)."""
    path = Path(path)
    try:
        text = path.read_text(encoding="utf-8")
    except FileNotFoundError:
        raise LuxError(f"{path}: no such points file") from None
    except UnicodeDecodeError as exc:
        raise LuxError(f"{path}: not a text file ({exc.reason})") from None
    return parse_pts(text, str(path))


def format_pts(points, normals) -> str:
    """The text of a ``.pts`` file for ``points`` and ``normals`` ((N, 3) each)."""
    p, n = check_points(points, normals)
    return "".join(" ".join(repr(float(v)) for v in (*a, *b)) + "\n" for a, b in zip(p, n))


def write_pts(path, points, normals) -> None:
    """Write a ``.pts`` file atomically."""
    write_text(path, format_pts(points, normals))


def check_points(points, normals) -> tuple[np.ndarray, np.ndarray]:
    """``points`` and ``normals`` as float64 (N, 3) arrays of finite numbers, normals non-zero
    and returned normalised; :class:`LuxError` names what is wrong."""
    p = np.asarray(points, dtype=np.float64)
    n = np.asarray(normals, dtype=np.float64)
    if p.ndim != 2 or p.shape[1] != 3:
        raise LuxError(f"points must be an (N, 3) array, got shape {p.shape}")
    if n.shape != p.shape:
        raise LuxError(f"normals must have the points' shape {p.shape}, got {n.shape}")
    if not (np.isfinite(p).all() and np.isfinite(n).all()):
        raise LuxError("points and normals must be finite")
    length = np.linalg.norm(n, axis=1)
    if p.shape[0] and not (length > 0.0).all():
        raise LuxError(f"normal {int(np.argmin(length))} is zero")
    return p, n / length[:, None] if p.shape[0] else n


def check_values(name: str, values, n: int, allow_none: bool = False) -> np.ndarray | None:
    """``values`` as a float64 (n,) array of finite numbers ≥ 0 (``None`` passes if allowed)."""
    if values is None and allow_none:
        return None
    v = np.asarray(values, dtype=np.float64)
    if v.shape != (n,):
        raise LuxError(f"{name} must have one value per point, shape ({n},), got {v.shape}")
    if not np.isfinite(v).all():
        raise LuxError(f"{name} must be finite (value {int(np.argmin(np.isfinite(v)))} is not)")
    if (v < 0.0).any():
        raise LuxError(f"{name} must be ≥ 0 (value {int(np.argmin(v))} is {float(v.min())})")
    return v


def format_results_csv(points, normals, lux, std_error) -> str:
    """The results CSV text: :data:`RESULTS_HEADER`, then one row per point in input order."""
    p, n = check_points(points, normals)
    e = check_values("lux", lux, p.shape[0])
    s = check_values("std_error", std_error, p.shape[0])
    lines = [RESULTS_HEADER]
    for i in range(p.shape[0]):
        lines.append(",".join(repr(float(v)) for v in (*p[i], *n[i], e[i], s[i])))
    return "\n".join(lines) + "\n"


def write_results_csv(path, points, normals, lux, std_error) -> None:
    """Write the results CSV atomically (the file is the old one or the complete new one)."""
    write_text(path, format_results_csv(points, normals, lux, std_error))


def read_results_csv(path) -> dict[str, np.ndarray]:
    """Read a results CSV back: ``{column: (N,) float64}`` for the columns of :data:`RESULTS_HEADER`."""
    path = Path(path)
    lines = [ln for ln in path.read_text(encoding="utf-8").splitlines() if ln.strip()]
    if not lines or lines[0].strip() != RESULTS_HEADER:
        raise LuxError(f"{path}: the header must be {RESULTS_HEADER!r}")
    cols = RESULTS_HEADER.split(",")
    rows = []
    for line_no, line in enumerate(lines[1:], start=2):
        fields = line.split(",")
        if len(fields) != len(cols):
            raise LuxError(f"{path}, line {line_no}: expected {len(cols)} fields, got {len(fields)}")
        try:
            rows.append([float(f) for f in fields])
        except ValueError:
            raise LuxError(f"{path}, line {line_no}: not a number in {fields}") from None
    data = np.asarray(rows, dtype=np.float64).reshape(-1, len(cols))
    return {c: data[:, i].copy() for i, c in enumerate(cols)}
