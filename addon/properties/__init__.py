"""Property groups, one per datablock, composed under the ``spectral_gi`` namespace."""
from . import light, lux, material, scene

classes = scene.classes + light.classes + material.classes + lux.classes


def register_extra():
    scene.register_properties()
    light.register_properties()
    material.register_properties()
    lux.register_properties()


def unregister_extra():
    lux.unregister_properties()
    material.unregister_properties()
    light.unregister_properties()
    scene.unregister_properties()
