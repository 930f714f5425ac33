"""A minimal 8-bit RGB PNG writer (zlib + struct), so no imaging library is needed."""
import struct
import zlib

import numpy as np

from ..colour import sRGB_encode
from .atomic import write_bytes


def _chunk(tag, data):
    return struct.pack(">I", len(data)) + tag + data + struct.pack(">I", zlib.crc32(tag + data) & 0xFFFFFFFF)


def encode_png(rgb8):
    """PNG bytes of an (H, W, 3) uint8 array (rows top to bottom)."""
    a = np.ascontiguousarray(rgb8, dtype=np.uint8)
    if a.ndim != 3 or a.shape[2] != 3:
        raise ValueError(f"expected an (H, W, 3) image, got {a.shape}")
    h, w, _ = a.shape
    raw = np.concatenate([np.zeros((h, 1), np.uint8), a.reshape(h, w * 3)], axis=1).tobytes()
    ihdr = struct.pack(">IIBBBBB", w, h, 8, 2, 0, 0, 0)
    return b"\x89PNG\r\n\x1a\n" + _chunk(b"IHDR", ihdr) + _chunk(b"IDAT", zlib.compress(raw, 6)) + \
        _chunk(b"IEND", b"")


def to_srgb8(linear_rgb, exposure=0.0):
    """Linear Rec.709 → 8-bit sRGB with an exposure in stops; clips, NaN → 0."""
    x = np.nan_to_num(np.asarray(linear_rgb, dtype=np.float64), nan=0.0, posinf=1.0, neginf=0.0)
    x = np.clip(x * (2.0 ** exposure), 0.0, 1.0)
    return np.round(sRGB_encode(x) * 255.0).astype(np.uint8)


def write_png(path, linear_rgb, exposure=0.0):
    write_bytes(path, encode_png(to_srgb8(linear_rgb, exposure)))
