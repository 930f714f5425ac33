"""Property groups, one per datablock, composed under the ``spectral_gi`` namespace."""
from . import light, scene

classes = scene.classes + light.classes


def register_extra():
    scene.register_properties()
    light.register_properties()


def unregister_extra():
    light.unregister_properties()
    scene.unregister_properties()
