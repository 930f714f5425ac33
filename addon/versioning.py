"""Schema versioning of the settings the add-on stores in .blend files.

What is stored
    Every scene's ``Scene.spectral_gi.schema_version`` holds the layout version of the
    add-on's settings in that file (``properties.scene.SCHEMA_VERSION`` is the current
    one). It is written (stamped) on every local scene when a file is saved
    (``save_pre``) and after a file is loaded and updated (``load_post``). A new scene
    reads the current version (the property's default) but stores nothing until then, so
    a file saved before versioning existed, which stores no version, is version 0.

When migrations run
    After a file is loaded (``load_post``), before a file is saved (``save_pre``: covers
    a file that was open when the add-on was enabled or updated) and once just after the
    add-on registers (a timer, for the file open at that moment). ``update_file`` takes
    the lowest version stored on the file's local scenes and applies every migration
    above it, in order, to the file's local datablocks (linked library data is read-only
    and left alone); then it stamps the current version. A file up to date is not
    touched. A file whose stored version is newer than this add-on knows is read as it
    is: nothing is migrated or stamped, and a warning is printed (stderr, Blender's console).

    Migrations read the old values as raw ID properties, ``datablock.spectral_gi.get(name)``
    (a renamed or redefined RNA property no longer exposes them; in Blender 5 the add-on's
    storage is reached through its property group, not ``datablock.get("spectral_gi")``).
    A value of an unexpected type or out of range is skipped with a warning; nothing
    raises out of a handler. Every migration must be idempotent, harmless on data already
    in the new layout (a file can be updated again on save, and a file's scenes can
    carry different versions).

Version 1
    The preset menus (material ``reflectance_preset``, ``metal_preset``, ``glass_preset``;
    light ``profile``) store a number derived from the item's identifier
    (``properties.enums``) instead of the item's position in the menu, which shifted
    whenever a preset was added. Version 0 files stored positions: each is turned into the
    entry at that position of the menu as this add-on builds it (the same entry those
    files showed), then stored by its stable number.

Version 2
    The default of Max Bounces (``Scene.spectral_gi.max_bounces``) is 64, the command
    line's and the scene format's default. A scene of an older file that stores Spectral GI
    settings but never set this one rendered with the old default, 16: it is given 16
    explicitly, so it renders as before. A scene that stores no settings at all (a new
    file, or one never rendered with the add-on) takes the current default.

How to add a migration
    1. Raise ``SCHEMA_VERSION`` in ``properties/scene.py`` to N and change the properties.
    2. Write ``def _to_N(warn)``: walk ``_local(bpy.data.<collection>)``, read the old
       values with ``group.get("old_name")``, check their type (``warn(text)`` and skip
       the value when it is not what the old layout stored), write the new property;
       return the number of values changed.
    3. Append ``(N, "what changed", _to_N)`` to ``MIGRATIONS``.
    4. Test it in ``tests/addon/test_addon_versioning.py`` with a file in the old layout.
"""
import sys

import bpy
from bpy.app.handlers import persistent

from .properties.enums import FIRST_STABLE
from .properties.scene import SCHEMA_VERSION

classes = ()

PREFIX = "Spectral GI"
LAST_MESSAGES = []  # what the last update printed (warnings and what was changed)


def _local(collection):
    """The datablocks of ``collection`` stored in this file (not linked from a library)."""
    return [d for d in collection if getattr(d, "library", None) is None]


def _group(datablock):
    return getattr(datablock, "spectral_gi", None)


def _is_int(value):
    return isinstance(value, int) and not isinstance(value, bool)


def stored_version(scene, warn):
    """The settings version stored on ``scene``: 0 when none is stored (a file from before versioning)."""
    group = _group(scene)
    raw = group.get("schema_version") if group is not None else None
    if raw is None:
        return 0
    if not _is_int(raw) or raw < 0:
        warn(f"scene {scene.name!r}: the stored settings version {raw!r} is not a version number; "
             "the file is read as one from before versioning")
        return 0
    return raw


# ----------------------------------------------------------------------------- migrations

def _position_to_number(group, prop, owner, warn):
    """One preset menu: a stored position (version 0) → the entry at that position, stored by
    its stable number. True when the value was changed."""
    raw = group.get(prop)
    if raw is None:  # never set: the menu's first entry, as before
        return False
    if not _is_int(raw):
        warn(f"{owner}: {prop} holds {raw!r}, not a menu entry; left as it is")
        return False
    if raw >= FIRST_STABLE:  # already a stable number
        return False
    items = group.bl_rna.properties[prop].enum_items
    if not 0 <= raw < len(items):
        warn(f"{owner}: {prop} was entry {raw} of a menu that now has {len(items)} entries; left as it is")
        return False
    if items[raw].value == raw:  # an entry whose number is its position (a light's None, File)
        return False
    setattr(group, prop, items[raw].identifier)
    return True


def _to_1(warn):
    """Preset menus: positions → stable numbers (materials and lights)."""
    changed = 0
    for kind, collection, props in (("material", bpy.data.materials,
                                     ("reflectance_preset", "metal_preset", "glass_preset")),
                                    ("light", bpy.data.lights, ("profile",))):
        for datablock in _local(collection):
            group = _group(datablock)
            if group is None:
                continue
            owner = f"{kind} {datablock.name!r}"
            for prop in props:
                try:
                    changed += _position_to_number(group, prop, owner, warn)
                except Exception as exc:  # an unexpected datablock: say so, go on with the others
                    warn(f"{owner}: {prop} not updated ({type(exc).__name__}: {exc})")
    return changed


OLD_MAX_BOUNCES = 16  # the Max Bounces default of settings versions 0 and 1


def _to_2(warn):
    """Max Bounces: scenes of an older layout that never set it keep the old default."""
    changed = 0
    for scene in _local(bpy.data.scenes):
        group = _group(scene)
        if group is None or stored_version(scene, lambda text: None) >= 2:
            continue
        if not group.keys():  # nothing stored: a scene the add-on never touched (a new file), not an old one
            continue
        if group.get("max_bounces") is None:
            group.max_bounces = OLD_MAX_BOUNCES
            changed += 1
    return changed


# (version, what changed, function(warn) → number of values changed), in increasing version order
MIGRATIONS = (
    (1, "preset menus stored by stable numbers", _to_1),
    (2, "Max Bounces kept at the old default of 16 where it was never set", _to_2),
)


# ----------------------------------------------------------------------------- updating a file

def update_file():
    """Bring the open file's settings up to ``SCHEMA_VERSION`` (see the module docstring).

    Returns the messages printed on stderr (warnings, and what was updated); never raises.
    """
    messages = []

    def warn(text):
        messages.append(text)
        print(f"{PREFIX}: {text}", file=sys.stderr)

    try:
        scenes = [s for s in _local(bpy.data.scenes) if _group(s) is not None]
        versions = [stored_version(s, warn) for s in scenes]
        newest = max(versions, default=SCHEMA_VERSION)
        if newest > SCHEMA_VERSION:
            warn(f"warning: this file was saved by a newer version of the add-on (settings version {newest}; this "
                 f"version knows up to {SCHEMA_VERSION}). Its settings are used as they are, not updated; settings "
                 "this version does not know are ignored")
            return messages
        start = min(versions, default=SCHEMA_VERSION)
        for version, description, migrate in MIGRATIONS:
            if start >= version:
                continue
            try:
                changed = migrate(warn)
            except Exception as exc:
                warn(f"updating the settings to version {version} ({description}) stopped: "
                     f"{type(exc).__name__}: {exc}")
                continue
            if changed:
                warn(f"updated {changed} setting(s) of a file from settings version {start} to {version}: "
                     f"{description}")
        for scene, version in zip(scenes, versions):
            if version != SCHEMA_VERSION:
                group = scene.spectral_gi
                if not _is_int(group.get("schema_version", 0)):
                    del group["schema_version"]  # a value of another type cannot be overwritten
                group.schema_version = SCHEMA_VERSION
    except Exception as exc:  # never out of a handler
        warn(f"the file's settings could not be checked for updates ({type(exc).__name__}: {exc})")
    finally:
        LAST_MESSAGES[:] = messages
    return messages


@persistent
def load_post(*_args):
    update_file()


@persistent
def save_pre(*_args):
    update_file()


def _after_register():
    """The timer run once after registering (returning None ends a timer): the file open then."""
    update_file()


HANDLERS = (("load_post", load_post), ("save_pre", save_pre))


def _same(a, b):
    return getattr(a, "__module__", None) == b.__module__ and getattr(a, "__name__", None) == b.__name__


def register_extra():
    for name, func in HANDLERS:
        handlers = getattr(bpy.app.handlers, name)
        for h in [h for h in handlers if _same(h, func)]:  # a copy left by an earlier registration
            handlers.remove(h)
        handlers.append(func)
    if not bpy.app.timers.is_registered(_after_register):
        bpy.app.timers.register(_after_register, first_interval=0.0)


def unregister_extra():
    for name, func in HANDLERS:
        handlers = getattr(bpy.app.handlers, name)
        for h in [h for h in handlers if _same(h, func)]:
            handlers.remove(h)
    if bpy.app.timers.is_registered(_after_register):
        bpy.app.timers.unregister(_after_register)
