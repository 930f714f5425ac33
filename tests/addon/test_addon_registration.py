"""Installing, enabling, registering and unregistering the extension."""
from pathlib import Path

import pytest

pytestmark = pytest.mark.blender


def op_registered(bpy, name):
    try:
        getattr(bpy.ops.spectral_gi, name).get_rna_type()
        return True
    except KeyError:
        return False


def registered(bpy):
    return {
        "scene prop": hasattr(bpy.types.Scene, "spectral_gi"),
        "operator": op_registered(bpy, "render"),
        "cornell": op_registered(bpy, "add_cornell_box"),
        "panel": hasattr(bpy.types, "SPECTRALGI_PT_render"),
    }


def test_register_unregister_register(ext, bpy):
    assert all(registered(bpy).values())
    ext.module.unregister()
    assert not any(registered(bpy).values())
    ext.module.unregister()  # unregistering twice is harmless
    ext.module.register()
    assert all(registered(bpy).values())
    s = bpy.context.scene.spectral_gi
    assert (s.samples, s.max_bounces, s.seed, s.threads) == (64, 64, 0, 0)
    # the engine's own panels show again with the engine selected (their COMPAT_ENGINES
    # survive the cycle), and Blender's generic panels list the engine again
    engine = bpy.context.scene.render.engine
    try:
        bpy.context.scene.render.engine = "SPECTRAL_GI"
        for name in ("SPECTRALGI_PT_sampling", "SPECTRALGI_PT_film", "SPECTRALGI_PT_sensors"):
            panel = getattr(bpy.types, name)
            assert "SPECTRAL_GI" in panel.COMPAT_ENGINES and panel.poll(bpy.context), name
        assert "SPECTRAL_GI" in bpy.types.RENDER_PT_format.COMPAT_ENGINES
    finally:
        bpy.context.scene.render.engine = engine


def test_every_setting_states_its_unit_or_meaning(ext, bpy):
    props = bpy.types.Scene.bl_rna.properties["spectral_gi"].fixed_type.bl_rna.properties
    for name in ("samples", "max_bounces", "seed", "threads"):
        desc = props[name].description
        assert len(desc) > 20 and ("count" in desc or "integer" in desc), (name, desc)


def test_panel_is_in_render_properties_for_every_engine(ext, bpy):
    panel = bpy.types.SPECTRALGI_PT_render
    assert (panel.bl_space_type, panel.bl_region_type, panel.bl_context) == ("PROPERTIES", "WINDOW", "render")
    assert not getattr(panel, "COMPAT_ENGINES", None)
    assert not hasattr(panel, "poll") or panel.poll(bpy.context)


def test_the_extension_keeps_its_kernels_in_the_user_cache_folder(ext, bpy):
    """The installed extension (a copy of the package in Blender's user folder) keeps its
    compiled kernels in the user's cache folder beside the command line's, under a key of
    its own: the same sources imported under the extension's name (numba's cached code names
    its modules), so every reinstall of this version finds them."""
    import importlib

    from spectral_gi.core import jit

    assert ext.registration.extension_package() == "bl_ext.user_default.spectral_gi"
    theirs = importlib.import_module("bl_ext.user_default.spectral_gi.core.jit")
    assert Path(theirs.__file__).resolve() != Path(jit.__file__).resolve()
    assert theirs.CACHE_DIR.parent == jit.CACHE_DIR.parent
    assert theirs.CACHE_DIR != jit.CACHE_DIR  # another import name: numba's cached code names its modules


def test_panel_draws_idle_and_while_rendering(ext, bpy, monkeypatch):
    from unittest import mock

    panel = bpy.types.SPECTRALGI_PT_render
    labels = []
    layout = mock.MagicMock()
    for name in ("row", "column", "box"):
        getattr(layout, name).return_value = layout
    layout.label.side_effect = lambda text="", **kw: labels.append(text)
    fake = mock.MagicMock(layout=layout)
    panel.draw(fake, bpy.context)
    ops = [c.args[0] for c in layout.operator.call_args_list]
    assert "spectral_gi.render" in ops and "spectral_gi.add_cornell_box" in ops
    props = [c.args[1] for c in layout.prop.call_args_list]
    assert props == ["samples", "max_bounces", "seed", "threads"]

    state = ext.render_job.STATE
    monkeypatch.setattr(ext.render_job, "busy", lambda: True)
    monkeypatch.setattr(state, "phase", "Compiling kernels (first run only)")
    monkeypatch.setattr(state, "done", 3)
    monkeypatch.setattr(state, "total", 64)
    monkeypatch.setattr(state, "rate", 1.5e6)
    monkeypatch.setattr(state, "cancelling", False)
    labels.clear()
    panel.draw(fake, bpy.context)
    text = " ".join(labels)
    assert "Compiling kernels (first run only)" in text and "3 / 64" in text and "1.50 M samples/s" in text
    assert "Esc" in text and "Cancelling" not in text
    monkeypatch.setattr(state, "cancelling", True)
    labels.clear()
    panel.draw(fake, bpy.context)
    assert "Cancelling…" in " ".join(labels)
