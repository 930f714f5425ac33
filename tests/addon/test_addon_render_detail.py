"""Exports outside F12 (Render GI, Compare with Cycles, the lighting analysis) see the scene at
render detail: subdivision at its render levels, hair at its render amounts and steps, curves
at their render resolution, and the objects hidden in the viewport that render; every setting
is put back afterwards."""
import importlib

import pytest

from .test_addon_hair import hair_patch

pytestmark = pytest.mark.blender


def _scene(b, bpy):
    b.camera()
    b.resolution(8, 8)
    cube = b.mesh("Cube", [(x, y, z) for z in (0, 1) for y in (0, 1) for x in (0, 1)],
                  [(0, 2, 3, 1), (4, 5, 7, 6), (0, 1, 5, 4), (2, 6, 7, 3), (0, 4, 6, 2), (1, 3, 7, 5)])
    sub = cube.modifiers.new("Subdivision", "SUBSURF")
    sub.levels, sub.render_levels = 0, 2
    off = (b.mesh("Disabled", [(3, 0, 0), (4, 0, 0), (4, 1, 0)], [(0, 1, 2)]))
    off.hide_viewport = True
    eye = (b.mesh("Hidden", [(5, 0, 0), (6, 0, 0), (6, 1, 0)], [(0, 1, 2)]))
    eye.hide_set(True)
    skipped = (b.mesh("Not rendered", [(7, 0, 0), (8, 0, 0), (8, 1, 0)], [(0, 1, 2)]))
    skipped.hide_viewport, skipped.hide_render = True, True
    floor, ps = hair_patch(b, bpy, count=10, children=3)
    ps.rendered_child_count = 5
    ps.display_percentage = 30
    return cube, sub, off, eye, ps


def _triangles(scene, name):
    return sum(m.indices.shape[0] for m in scene.meshes if m.name == name)


def test_render_detail_exports_what_f12_renders_and_restores(ext, bpy, monkeypatch):
    curves = importlib.import_module(ext.module.__name__ + ".addon.export.curves")
    detail = importlib.import_module(ext.module.__name__ + ".addon.export.detail")
    seen = []
    strands = curves.particle_strands

    def spy(obj, psys, render):
        out = strands(obj, psys, render)
        seen.append((len(out[1]), int(out[1][0])))
        return out

    monkeypatch.setattr(curves, "particle_strands", spy)
    b = ext.build
    cube, sub, off, eye, ps = _scene(b, bpy)
    viewport = ext.export.export_scene(bpy.context.evaluated_depsgraph_get(), b.scene).scene
    assert _triangles(viewport, "Cube") == 12  # level 0: the cube's own six quads
    assert {"Disabled", "Hidden"}.isdisjoint(m.name for m in viewport.meshes)
    assert seen[-1] == (3 * 3, (1 << 2) + 1), seen  # 30 % of 10 parents, 3 children each, 2 viewport steps

    with detail.render_detail(b.scene, bpy.context.view_layer):
        full = ext.export.export_scene(bpy.context.evaluated_depsgraph_get(), b.scene).scene
    assert _triangles(full, "Cube") == 6 * 16 * 2  # render level 2: each quad into 16
    assert _triangles(full, "Disabled") == 1 and _triangles(full, "Hidden") == 1
    assert _triangles(full, "Not rendered") == 0
    assert seen[-1] == (10 * 5, (1 << 3) + 1), seen  # as F12: every parent, 5 children, 3 render steps

    assert (sub.levels, sub.render_levels, off.hide_viewport, eye.hide_get()) == (0, 2, True, True)
    assert (ps.display_percentage, ps.child_percent, ps.display_step) == (30, 3, 2)
    after = ext.export.export_scene(bpy.context.evaluated_depsgraph_get(), b.scene).scene
    assert _triangles(after, "Cube") == 12 and "Hidden" not in {m.name for m in after.meshes}


def test_render_detail_restores_on_an_error(ext, bpy):
    detail = importlib.import_module(ext.module.__name__ + ".addon.export.detail")
    b = ext.build
    cube, sub, off, eye, ps = _scene(b, bpy)
    with pytest.raises(RuntimeError, match="cancelled"):
        with detail.render_detail(b.scene, bpy.context.view_layer):
            assert sub.levels == 2 and not off.hide_viewport and not eye.hide_get()
            raise RuntimeError("cancelled")
    assert (sub.levels, off.hide_viewport, eye.hide_get(), ps.display_percentage) == (0, True, True, 30)


def test_render_gi_operator_exports_at_render_detail(ext, bpy):
    """The Render GI button's export (its main-thread half) sees the render levels."""
    op = importlib.import_module(ext.module.__name__ + ".addon.operators.render")
    b = ext.build
    _scene(b, bpy)
    reports = []
    fake = type("Op", (), {"report": lambda self, kind, text: reports.append((kind, text))})()
    job = op.SPECTRALGI_OT_render._prepare(fake, bpy.context)
    assert job is not None, reports
    assert _triangles(job.scene, "Cube") == 6 * 16 * 2
