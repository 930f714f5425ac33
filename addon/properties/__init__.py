"""Property groups, one per datablock, composed under the ``spectral_gi`` namespace."""
from . import scene

classes = scene.classes


def register_extra():
    scene.register_properties()


def unregister_extra():
    scene.unregister_properties()
