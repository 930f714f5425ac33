"""Register the add-on's classes in a fixed order; unregister in reverse.

Each module in ``MODULES`` has a ``classes`` tuple and may have ``register_extra()``
/ ``unregister_extra()`` (for properties attached to Blender types). Registering
twice, or unregistering what is not registered, does nothing, so
register → unregister → register is safe. ``core`` (and so numba) is never imported
here: operators import it lazily, and the background compile (``background.py``, started
by ``preferences``) on a thread of its own. Compiled kernels go to the user's cache folder that
the command line uses too (``core/jit.py``), under a key of the sources and the
extension's import name, so reinstalling the same version does not compile again.
"""

import bpy

from . import engine, operators, preferences, properties, ui, versioning

MODULES = (properties, versioning, engine, operators, ui, preferences)


def extension_package(package=__package__):
    """The extension's top-level package (``bl_ext.<repo>.<id>``), or None outside an extension."""
    if not package or not package.startswith("bl_ext."):
        return None
    top = package.rpartition(".")[0]  # drop ".addon"
    return top or None


def register():
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
