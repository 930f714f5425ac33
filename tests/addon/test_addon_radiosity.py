"""Calculate Illuminance with Method Radiosity: one solve of the scene, the calculation
surfaces gathering from it, the per-vertex false-colour overlay on every surface, the
luminance overlay, the warning for non-diffuse materials, the report and cancel."""
import importlib
import json
import math
import warnings

import numpy as np
import pytest

pytestmark = pytest.mark.blender

H = 2.0  # m, the light above the floor
I_CD = 100.0
RHO = 0.5


def lux_ops(ext):
    return importlib.import_module(ext.module.__name__ + ".addon.operators.lux")


def lit_room(ext, bpy):
    """A grey diffuse floor (ρ = 0.5) and a glossy wall under a point light; a hidden
    calculation plane just above the floor."""
    b = ext.build
    b.camera()
    grey = b.shader("Grey", "ShaderNodeBsdfDiffuse", Color=(RHO, RHO, RHO, 1.0))
    shiny = b.shader("Shiny", "ShaderNodeBsdfGlossy", Color=(0.6, 0.6, 0.6, 1.0))
    b.plane("Floor", size=4.0, material=grey)
    b.mesh("Wall", [(2, -2, 0), (2, 2, 0), (2, 2, 2), (2, -2, 2)], [(0, 3, 2, 1)], material=shiny)
    target = b.plane("Target", size=2.0, location=(0, 0, 0.01))
    target.hide_render = True
    light = b.light("Bulb", "POINT", location=(0, 0, H), energy=10.0)
    light.data.shadow_soft_size = 0.0
    light.data.spectral_gi.unit = "CANDELA"
    light.data.spectral_gi.value = I_CD
    s = target.spectral_gi_lux
    s.enabled, s.kind, s.spacing_mode, s.spacing = True, "GRID", "USER", 0.5
    bpy.context.scene.spectral_gi_lux_method = "RADIOSITY"
    bpy.context.scene.spectral_gi_radiosity.max_edge = 0.5
    return target


def _colours(obj, ops):
    attr = obj.data.color_attributes[ops.ATTRIBUTE]
    a = np.empty(len(attr.data) * 4, np.float32)
    attr.data.foreach_get("color", a)
    return attr.domain, a.reshape(-1, 4)


def test_radiosity_method_overlay_and_report(ext, bpy, tmp_path):
    ops = lux_ops(ext)
    target = lit_room(ext, bpy)
    scene = bpy.context.scene
    bpy.context.view_layer.objects.active = target
    assert bpy.ops.spectral_gi.lux_calculate() == {"FINISHED"}
    s = target.spectral_gi_lux
    assert s.valid and s.n_points == 16 and s.max_rel_error == 0.0
    # the points gather from one solve of the exported scene: the same as core's
    core_scene = ext.build.export(ext).scene
    solve = importlib.import_module(ext.module.__name__ + ".core.integrators.radiosity.solve")
    opts = dict(solve.LUX_DEFAULTS, max_edge=0.5)
    with pytest.warns(UserWarning, match="Shiny"):
        sol = ext.core.radiosity(core_scene, **opts)
    p = ops.build_surface(target).points
    want = ext.core.radiosity_illuminance(sol, p, np.tile([0, 0, 1.0], (len(p), 1)))
    assert s.mean == pytest.approx(float(want.mean()), rel=1e-6)
    direct = I_CD * (H - 0.01) / ((p[:, 0] ** 2 + p[:, 1] ** 2 + (H - 0.01) ** 2) ** 1.5)
    assert np.all(want >= direct * (1 - 1e-6)) and want.mean() < 1.3 * direct.mean()
    # the non-diffuse material is named in the warning
    r = scene.spectral_gi_radiosity
    assert "Shiny" in r.warning and r.patches == sol.patches.n
    # an overlay on every exported surface, per vertex
    names = r.objects.splitlines()
    assert sorted(names) == ["Floor radiosity", "Wall radiosity"]
    floor = bpy.data.objects["Floor radiosity"]
    domain, rgba = _colours(floor, ops)
    assert domain == "POINT" and rgba.shape[0] == len(floor.data.vertices) and floor.hide_render
    lux_v = np.asarray(floor[ops.RADIOSITY_KEY]["lux"], np.float64)
    lum_v = np.asarray(floor[ops.RADIOSITY_KEY]["luminance"], np.float64)
    # diffuse grey floor: every vertex's luminance is ρ/π times its illuminance (means of one linear map;
    # ρ the V-weighted reflectance of the grey's spectrum, within 0.2 % of the colour's 0.5)
    np.testing.assert_allclose(lum_v, RHO / math.pi * lux_v, rtol=2e-3)
    fc = importlib.import_module(ext.module.__name__ + ".core.lux.falsecolour")
    rs = scene.spectral_gi_radiosity_scale
    opts_c = ops.overlay_options(rs, np.concatenate([lux_v, np.asarray(bpy.data.objects["Wall radiosity"]
                                                                        [ops.RADIOSITY_KEY]["lux"])]))
    np.testing.assert_allclose(rgba[:, :3], fc.srgb_to_linear(fc.false_colour(lux_v, **opts_c)), atol=1e-6)
    assert ops.radiosity_legend(scene)[-1][1].endswith("lx")
    # luminance, on a fixed range
    r.quantity = "LUMINANCE"
    rs.scale_auto, rs.scale_fixed_min, rs.scale_fixed_max, rs.scale_steps = False, 0.0, 20.0, 4
    assert bpy.ops.spectral_gi.radiosity_recolour() == {"FINISHED"}
    _, rgba2 = _colours(floor, ops)
    np.testing.assert_allclose(rgba2[:, :3], fc.srgb_to_linear(fc.false_colour(lum_v, 0.0, 20.0, 4)), atol=1e-6)
    legend = ops.radiosity_legend(scene)
    assert len(legend) == 4 and legend[-1][1].endswith("cd/m²")
    # reported like the path-traced analysis, saying how
    written, _img = ops.write_report(bpy.context, target, str(tmp_path))
    d = json.loads((tmp_path / "Target_lux.json").read_text())
    assert d["method"] == "radiosity" and "diffuse" in d["note"]
    # a second calculation replaces the overlay, it does not pile up
    assert bpy.ops.spectral_gi.lux_calculate() == {"FINISHED"}
    assert sorted(scene.spectral_gi_radiosity.objects.splitlines()) == ["Floor radiosity", "Wall radiosity"]
    assert sum(o.name.endswith(" radiosity") for o in bpy.data.objects) == 2


def test_overlay_vertices_are_the_area_weighted_means_of_their_patches(ext, bpy):
    """The overlay's vertex values: the mean of the patches meeting at the vertex (same side and
    normal), weighted by area, against a brute-force sum over the patches."""
    ops = lux_ops(ext)
    lit_room(ext, bpy)
    core_scene = ext.build.export(ext).scene
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # the glossy wall's (tested above)
        sol = ext.core.radiosity(core_scene, max_edge=0.7, n_vis=1, method="jacobi")
    for m, idx in ops.mesh_patches(sol, core_scene).items():
        pos, faces, vals = ops.overlay_mesh(sol, idx, sol.vertex_illuminance)
        assert faces.shape == (idx.size, 3)
        for v in range(0, pos.shape[0], 3):
            rows, cols = np.nonzero(faces == v)
            pid = idx[rows]
            # every patch with a corner at this vertex on the same side and plane
            c = sol.patches.corners
            base = pos[v] - ops.RADIOSITY_OFFSET * sol.patches.normal[pid[0]]
            same = (np.abs(c - base).max(axis=2).min(axis=1) < 1e-6) & (sol.patches.side == sol.patches.side[pid[0]]) \
                & (sol.patches.normal @ sol.patches.normal[pid[0]] > 1 - 1e-6)
            a = sol.patches.area[same]
            assert vals[v] == pytest.approx(np.sum(a * sol.illuminance[same]) / a.sum(), rel=1e-9)


def test_radiosity_cancel_keeps_the_earlier_result(ext, bpy, monkeypatch):
    job_mod = importlib.import_module(ext.module.__name__ + ".addon.lux_job")
    target = lit_room(ext, bpy)
    scene = bpy.context.scene
    assert bpy.ops.spectral_gi.lux_calculate() == {"FINISHED"}
    before = (target.spectral_gi_lux.mean, scene.spectral_gi_radiosity.objects)
    bpy.data.objects["Bulb"].data.spectral_gi.value = 4 * I_CD

    def cancel(job, done, total):
        job.request_cancel()

    monkeypatch.setattr(job_mod.LuxJob, "on_progress", cancel)
    assert bpy.ops.spectral_gi.lux_calculate() == {"CANCELLED"}
    assert (target.spectral_gi_lux.mean, scene.spectral_gi_radiosity.objects) == before
    assert not job_mod.busy()
    monkeypatch.setattr(job_mod.LuxJob, "on_progress", None)
    assert bpy.ops.spectral_gi.lux_calculate() == {"FINISHED"}
    assert target.spectral_gi_lux.mean == pytest.approx(4 * before[0], rel=1e-6)


def test_radiosity_without_calculation_surfaces_gives_the_overlay_alone(ext, bpy):
    target = lit_room(ext, bpy)
    target.spectral_gi_lux.enabled = False
    assert bpy.ops.spectral_gi.lux_calculate() == {"FINISHED"}
    assert sorted(bpy.context.scene.spectral_gi_radiosity.objects.splitlines()) == ["Floor radiosity",
                                                                                    "Wall radiosity"]
    assert not target.spectral_gi_lux.valid
    bpy.context.scene.spectral_gi_lux_method = "PATH"
    with pytest.raises(RuntimeError, match="no calculation surface"):
        bpy.ops.spectral_gi.lux_calculate()
