"""Reading ``.npz`` archives (scenes' arrays, film checkpoints) with limits.

:class:`NpzReader` opens the archive without reading its members; :meth:`NpzReader.get`
reads one member when it is referenced, after checking its ``.npy`` header: a plain numeric
dtype (never objects, so never pickles), a declared size within ``max_bytes`` for the
member and for all members read together, and a header that matches the member's size in
the archive. Every problem raises :class:`NpzError` naming the member.
"""
import zipfile

import numpy as np

MAX_ARRAY_BYTES = 1 << 33  # 8 GiB: one array
MAX_TOTAL_BYTES = 1 << 35  # 32 GiB: all arrays read from one archive
_KINDS = "biuf"  # bool, signed and unsigned integers, floats: what the formats store


class NpzError(ValueError):
    """An archive or one of its members cannot be read; the message names it."""


class NpzReader:
    """A read-only view of an ``.npz`` file; use as a context manager."""

    def __init__(self, path, max_array_bytes=MAX_ARRAY_BYTES, max_total_bytes=MAX_TOTAL_BYTES):
        self.path = path
        self.max_array_bytes = int(max_array_bytes)
        self.max_total_bytes = int(max_total_bytes)
        self.total = 0
        try:
            self.zf = zipfile.ZipFile(path)
            self.names = {n[:-4]: n for n in self.zf.namelist() if n.endswith(".npy")}
        except (OSError, zipfile.BadZipFile, ValueError, EOFError, RuntimeError) as e:
            raise NpzError(f"cannot read {path} ({e})") from None

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()

    def close(self):
        self.zf.close()

    def __contains__(self, key):
        return key in self.names

    @property
    def files(self):
        return list(self.names)

    def get(self, key):
        """The array stored as ``key``; NpzError if it is missing, too large or malformed."""
        if key not in self.names:
            raise NpzError(f"array {key!r} missing from {self.path}")
        member = self.names[key]
        try:
            info = self.zf.getinfo(member)
            with self.zf.open(member) as f:
                version = np.lib.format.read_magic(f)
                if version == (1, 0):
                    shape, fortran, dtype = np.lib.format.read_array_header_1_0(f)
                elif version == (2, 0):
                    shape, fortran, dtype = np.lib.format.read_array_header_2_0(f)
                else:
                    raise ValueError(f"unsupported .npy version {version}")
                if dtype.kind not in _KINDS or dtype.hasobject or dtype.fields is not None or dtype.subdtype:
                    raise ValueError(f"dtype {dtype} is not a plain number type")
                count = 1
                for s in shape:
                    count *= int(s)
                nbytes = count * dtype.itemsize
                if nbytes > self.max_array_bytes:
                    raise ValueError(f"declares {nbytes} bytes, more than the limit of {self.max_array_bytes}")
                if self.total + nbytes > self.max_total_bytes:
                    raise ValueError(f"the arrays read exceed the limit of {self.max_total_bytes} bytes")
                header = f.tell()
                if info.file_size != header + nbytes:
                    raise ValueError(f"its header declares {nbytes} bytes of data, the member holds "
                                     f"{info.file_size - header}")
                data = f.read(nbytes)
            if len(data) != nbytes:
                raise ValueError("truncated")
            a = np.frombuffer(data, dtype=dtype, count=count)
            a = a.reshape(shape[::-1]).transpose() if fortran else a.reshape(shape)
            self.total += nbytes
            return np.array(a, copy=True)  # writeable and owning its memory
        except NpzError:
            raise
        except MemoryError:
            raise NpzError(f"array {key!r} of {self.path}: not enough memory to read it") from None
        except Exception as e:  # zipfile.BadZipFile, zlib.error, ValueError, EOFError, OSError, ...
            raise NpzError(f"array {key!r} of {self.path}: cannot read ({type(e).__name__}: {e})") from None
