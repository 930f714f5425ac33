"""Property groups, one per datablock, composed under the ``spectral_gi`` namespace."""
from . import material, scene

classes = scene.classes + material.classes


def register_extra():
    scene.register_properties()
    material.register_properties()


def unregister_extra():
    material.unregister_properties()
    scene.unregister_properties()
