"""PC2 point caches (Blender's Mesh Cache format, the one Hooke reads and writes).

Little-endian: the 12 bytes ``POINTCACHE2\\0``, ``i32`` version 1, ``i32`` point count,
``f32`` start frame, ``f32`` sampling (frames per sample), ``i32`` sample count, then each
sample's points as ``f32`` triples.
"""

import os
import struct
import sys
from array import array

MAGIC = b"POINTCACHE2\0"
HEADER = struct.Struct("<12siiffi")


class CacheError(Exception):
    """A cache that is not what it should be, said with its path."""


def write(path, samples):
    """Writes ``samples`` (each a sequence of ``(x, y, z)``, all of one length) to ``path``,
    through a file beside it that replaces it only once complete."""
    count = len(samples[0]) if samples else 0
    tmp = f"{path}.part"
    try:
        with open(tmp, "wb") as f:
            f.write(HEADER.pack(MAGIC, 1, count, 0.0, 1.0, len(samples)))
            for sample in samples:
                if len(sample) != count:
                    raise CacheError(f"{path}: a sample of {len(sample)} points among ones of {count}")
                flat = array("f", (c for p in sample for c in p))
                if sys.byteorder != "little":
                    flat.byteswap()
                f.write(flat.tobytes())
        os.replace(tmp, path)
    except BaseException:
        # An error or an interrupt half-way leaves neither a part file nor a changed `path`.
        if os.path.exists(tmp):
            os.remove(tmp)
        raise


def read(path):
    """The samples of the cache at ``path``, each a list of ``(x, y, z)``."""
    with open(path, "rb") as f:
        data = f.read()
    if len(data) < HEADER.size:
        raise CacheError(f"{path}: not a PC2 point cache (shorter than its header)")
    magic, version, count, _start, _sampling, samples = HEADER.unpack_from(data)
    if magic != MAGIC or version != 1:
        raise CacheError(f"{path}: not a PC2 point cache")
    if len(data) != HEADER.size + 12 * count * samples:
        raise CacheError(
            f"{path}: {len(data)} bytes, but {samples} samples of {count} points take "
            f"{HEADER.size + 12 * count * samples}"
        )
    values = array("f")
    values.frombytes(data[HEADER.size:])
    if sys.byteorder != "little":
        values.byteswap()
    return [
        [tuple(values[3 * (k * count + i) : 3 * (k * count + i) + 3]) for i in range(count)]
        for k in range(samples)
    ]
