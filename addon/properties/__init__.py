"""Property groups, one per datablock, composed under the ``spectral_gi`` namespace."""
from . import light, material, scene

classes = scene.classes + light.classes + material.classes


def register_extra():
    scene.register_properties()
    light.register_properties()
    material.register_properties()


def unregister_extra():
    material.unregister_properties()
    light.unregister_properties()
    scene.unregister_properties()
