"""Register the add-on's classes in a fixed order; unregister in reverse.

Each module in ``MODULES`` has a ``classes`` tuple and may have ``register_extra()``
/ ``unregister_extra()`` (for properties attached to Blender types). Registering
twice, or unregistering what is not registered, does nothing, so
register → unregister → register is safe. ``core`` (and so numba) is never imported
here: operators import it lazily, after ``NUMBA_CACHE_DIR`` has been set.
"""
import os

import bpy

from . import engine, operators, properties, ui, versioning

MODULES = (properties, versioning, engine, operators, ui)

NUMBA_CACHE_SUBDIR = "numba_cache"


def extension_package(package=__package__):
    """The extension's top-level package (``bl_ext.<repo>.<id>``), or None outside an extension."""
    if not package or not package.startswith("bl_ext."):
        return None
    top = package.rpartition(".")[0]  # drop ".addon"
    return top or None


def set_numba_cache_dir():
    """Point numba's cache at the extension's user folder (unless the environment already says where)."""
    top = extension_package()
    if top is None or "NUMBA_CACHE_DIR" in os.environ:
        return os.environ.get("NUMBA_CACHE_DIR")
    try:
        path = bpy.utils.extension_path_user(top, path=NUMBA_CACHE_SUBDIR, create=True)
    except (ValueError, RuntimeError, OSError, AttributeError):
        return None
    os.environ.setdefault("NUMBA_CACHE_DIR", path)
    return path


def register():
    set_numba_cache_dir()
    done = []
    try:
        for module in MODULES:
            for cls in module.classes:
                if not getattr(cls, "is_registered", False):
                    bpy.utils.register_class(cls)
                done.append(cls)
            extra = getattr(module, "register_extra", None)
            if extra is not None:
                extra()
    except Exception:
        # leave nothing half-registered
        for module in reversed(MODULES):
            extra = getattr(module, "unregister_extra", None)
            if extra is not None:
                try:
                    extra()
                except Exception:
                    pass
        for cls in reversed(done):
            if getattr(cls, "is_registered", False):
                bpy.utils.unregister_class(cls)
        raise


def unregister():
    from . import lux_job, render_job

    render_job.cancel_current(wait=5.0)
    lux_job.cancel_current(wait=5.0)
    for module in reversed(MODULES):
        extra = getattr(module, "unregister_extra", None)
        if extra is not None:
            extra()
        for cls in reversed(module.classes):
            if getattr(cls, "is_registered", False):
                bpy.utils.unregister_class(cls)
