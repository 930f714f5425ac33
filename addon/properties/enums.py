"""Enum items whose stored numbers do not depend on the position of an entry in its menu.

Blender saves an enum property as the number of the chosen item; an item given as
``(identifier, name, description)`` gets its position in the list. Menus built from
the preset data (ColorChecker patches, metals, glasses, photometric profiles) change
when a preset is added or removed, which would shift every saved choice after it. Their
items therefore carry a number derived from the identifier alone (``stable_number``);
numbers below ``FIRST_STABLE`` are positions, which is how files from before schema
version 1 stored these menus (``addon.versioning`` converts them).
"""
import zlib

FIRST_STABLE = 1 << 16  # derived numbers are at least this; smaller stored numbers are positions
_LARGEST = 0x7FFFFFFF  # Blender stores enum numbers as signed 32-bit integers


def stable_number(identifier, taken=()):
    """The number stored for ``identifier``: from its CRC-32, not below ``FIRST_STABLE``;
    the next free one when an identifier listed before it in the menu already has it."""
    n = (zlib.crc32(identifier.encode("utf-8")) & _LARGEST) | FIRST_STABLE
    while n in taken:
        n = n + 1 if n < _LARGEST else FIRST_STABLE
    return n


def numbered_items(items, fixed=None):
    """``(identifier, name, description, number)`` tuples for ``items`` (3-tuples): the
    numbers in ``fixed`` ({identifier: number below FIRST_STABLE}) for those listed there,
    ``stable_number`` for the others."""
    fixed = dict(fixed or {})
    taken = set(fixed.values())
    out = []
    for identifier, name, description in items:
        number = fixed.get(identifier)
        if number is None:
            number = stable_number(identifier, taken)
        taken.add(number)
        out.append((identifier, name, description, number))
    return out
