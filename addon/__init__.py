"""The Blender add-on. Everything that imports bpy lives under this package.

``register``/``unregister`` import bpy lazily, so ``import spectral_gi`` (and the
command line) work without Blender.
"""


def register():
    from . import registration
    registration.register()


def unregister():
    from . import registration
    registration.unregister()
