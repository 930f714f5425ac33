"""Shared setup for the add-on tests.

Blender-as-a-module keeps global state, so one session fixture builds the extension
zip with ``tools/build_extension.py``, installs it into a throw-away user folder
(``BLENDER_USER_RESOURCES``, set here before bpy is imported) and enables it. Set
``SPECTRAL_GI_EXTENSION_ZIP`` to test an already built zip instead. Tests
that need bpy are marked ``blender`` and are skipped only when ``import bpy`` fails.
"""
import atexit
import importlib.util
import math
import os
import shutil
import sys
import tempfile
from pathlib import Path
from types import SimpleNamespace

import pytest

REPO = Path(__file__).resolve().parents[2]
EXTENSION_MODULE = "bl_ext.user_default.spectral_gi"

if "bpy" not in sys.modules:
    # Before bpy is imported: keep Blender's user configuration out of the developer's home.
    _USER = tempfile.mkdtemp(prefix="spectral-gi-blender-user-")
    os.environ["BLENDER_USER_RESOURCES"] = _USER
    atexit.register(shutil.rmtree, _USER, True)


def _load_build_tool():
    spec = importlib.util.spec_from_file_location("spectral_gi_build_extension",
                                                  REPO / "tools" / "build_extension.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


@pytest.fixture(scope="session")
def bpy():
    try:
        import bpy as _bpy
    except ImportError as exc:
        pytest.skip(f"bpy (Blender as a Python module) is not importable: {exc}")
    return _bpy


@pytest.fixture(scope="session")
def extension(bpy, tmp_path_factory):
    """The installed and enabled extension's top-level module (``bl_ext.user_default.spectral_gi``)."""
    import addon_utils

    if not os.environ.get("BLENDER_USER_RESOURCES"):
        pytest.fail("bpy was imported before tests/addon/conftest.py could point BLENDER_USER_RESOURCES "
                    "at a temporary folder; refusing to install into the real user folder")
    prebuilt = os.environ.get("SPECTRAL_GI_EXTENSION_ZIP")  # test an already built artefact
    if prebuilt:
        zip_path = Path(prebuilt)
    else:
        zip_path = _load_build_tool().build(tmp_path_factory.mktemp("dist"), quiet=True)
    result = bpy.ops.extensions.package_install_files(filepath=str(zip_path), repo="user_default",
                                                      enable_on_install=True)
    assert result == {"FINISHED"}, result
    if EXTENSION_MODULE not in sys.modules:
        addon_utils.enable(EXTENSION_MODULE, default_set=True)
    assert EXTENSION_MODULE in sys.modules, "the extension did not load"
    bpy.ops.wm.read_homefile(use_empty=True)
    module = sys.modules[EXTENSION_MODULE]
    yield module
    addon_utils.disable(EXTENSION_MODULE, default_set=True)


@pytest.fixture()
def ext(extension, bpy):
    """The extension, with an empty scene (``read_homefile(use_empty=True)`` keeps add-ons enabled)."""
    bpy.ops.wm.read_homefile(use_empty=True)
    return SimpleNamespace(
        module=extension,
        core=sys.modules[EXTENSION_MODULE + ".core"] if EXTENSION_MODULE + ".core" in sys.modules
        else importlib.import_module(EXTENSION_MODULE + ".core"),
        export=importlib.import_module(EXTENSION_MODULE + ".addon.export"),
        render_job=importlib.import_module(EXTENSION_MODULE + ".addon.render_job"),
        registration=importlib.import_module(EXTENSION_MODULE + ".addon.registration"),
        scene=bpy.context.scene,
        build=Builder(bpy),
    )


class Builder:
    """Small helpers that build scenes with bpy.data (no operators, no context needed)."""

    def __init__(self, bpy):
        self.bpy = bpy

    @property
    def scene(self):
        return self.bpy.context.scene

    def link(self, obj):
        self.scene.collection.objects.link(obj)
        return obj

    def mesh(self, name, verts, faces, location=(0, 0, 0), material=None):
        me = self.bpy.data.meshes.new(name)
        me.from_pydata([tuple(v) for v in verts], [], [tuple(f) for f in faces])
        me.update()
        if material is not None:
            me.materials.append(material)
        obj = self.bpy.data.objects.new(name, me)
        obj.location = location
        return self.link(obj)

    def plane(self, name, size=2.0, location=(0, 0, 0), material=None):
        h = size / 2
        return self.mesh(name, [(-h, -h, 0), (h, -h, 0), (h, h, 0), (-h, h, 0)], [(0, 1, 2, 3)],
                         location, material)

    def cube(self, name, size=1.0, location=(0, 0, 0), material=None):
        h = size / 2
        v = [(x, y, z) for x in (-h, h) for y in (-h, h) for z in (-h, h)]
        f = [(0, 1, 3, 2), (4, 6, 7, 5), (0, 4, 5, 1), (2, 3, 7, 6), (0, 2, 6, 4), (1, 5, 7, 3)]
        return self.mesh(name, v, f, location, material)

    def camera(self, name="Camera", location=(0, -6, 2), rotation=(math.radians(75), 0, 0), lens=35.0,
               active=True):
        cam = self.bpy.data.cameras.new(name)
        cam.lens = lens
        obj = self.bpy.data.objects.new(name, cam)
        obj.location = location
        obj.rotation_euler = rotation
        self.link(obj)
        if active:
            self.scene.camera = obj
        return obj

    def light(self, name, kind="AREA", location=(0, 0, 3), energy=100.0, **props):
        data = self.bpy.data.lights.new(name, kind)
        data.energy = energy
        for k, v in props.items():
            setattr(data, k, v)
        obj = self.bpy.data.objects.new(name, data)
        obj.location = location
        return self.link(obj)

    def principled(self, name, rgb=(0.8, 0.8, 0.8), emission=None, strength=0.0):
        mat = self.bpy.data.materials.new(name)
        node = next(n for n in mat.node_tree.nodes if n.type == "BSDF_PRINCIPLED")
        node.inputs["Base Color"].default_value = (*rgb, 1.0)
        if emission is not None:
            node.inputs["Emission Color"].default_value = (*emission, 1.0)
            node.inputs["Emission Strength"].default_value = strength
        return mat

    def shader(self, name, idname, **inputs):
        """A material whose surface is one node of type ``idname`` with the given input values."""
        mat = self.bpy.data.materials.new(name)
        tree = mat.node_tree
        tree.nodes.clear()
        out = tree.nodes.new("ShaderNodeOutputMaterial")
        node = tree.nodes.new(idname)
        for k, v in inputs.items():
            node.inputs[k].default_value = v
        tree.links.new(node.outputs[0], out.inputs["Surface"])
        return mat

    def resolution(self, w, h, percentage=100):
        r = self.scene.render
        r.resolution_x, r.resolution_y, r.resolution_percentage = w, h, percentage

    def export(self, ext, **kw):
        return ext.export.export_scene(self.bpy.context.evaluated_depsgraph_get(), self.scene, **kw)

    def image_array(self, name="Spectral GI Result"):
        """The image's pixels as (H, W, 4) float32, rows top-to-bottom."""
        import numpy as np

        img = self.bpy.data.images[name]
        w, h = img.size
        a = np.empty(w * h * 4, dtype=np.float32)
        img.pixels.foreach_get(a)
        return a.reshape(h, w, 4)[::-1]
