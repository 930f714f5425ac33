"""Lighting analysis in Blender: calculation surfaces, Calculate Illuminance, the stored statistics."""
import importlib
import importlib.util
import math

import numpy as np
import pytest

from helpers import recording_layout

pytestmark = pytest.mark.blender

H = 2.0  # m, the light above the plane
I_CD = 100.0


def lux_ops(ext):
    return importlib.import_module(ext.module.__name__ + ".addon.operators.lux")


def open_floor(ext, bpy):
    b = ext.build
    b.camera()
    grey = b.shader("Grey", "ShaderNodeBsdfDiffuse", Color=(0.0, 0.0, 0.0, 1.0))
    plane = b.plane("Target", size=2.0, material=grey)
    plane.hide_render = True
    light = b.light("Bulb", "POINT", location=(0, 0, H), energy=10.0)
    light.data.shadow_soft_size = 0.0
    light.data.spectral_gi.unit = "CANDELA"
    light.data.spectral_gi.value = I_CD
    s = plane.spectral_gi_lux
    s.enabled, s.kind, s.spacing_mode, s.spacing, s.samples = True, "GRID", "USER", 0.5, 8
    return plane


def test_grid_surface_matches_the_closed_form(ext, bpy, tmp_path):
    ops = lux_ops(ext)
    plane = open_floor(ext, bpy)
    bpy.context.view_layer.objects.active = plane
    assert bpy.ops.spectral_gi.lux_calculate() == {"FINISHED"}
    s = plane.spectral_gi_lux
    assert s.valid and s.n_points == 16
    surface = ops.build_surface(plane)
    p = surface.points
    want = I_CD * H / ((p[:, 0] ** 2 + p[:, 1] ** 2 + H * H) ** 1.5)  # I cos θ / d²
    assert s.mean == pytest.approx(want.mean(), rel=1e-3)
    assert s.minimum == pytest.approx(want.min(), rel=1e-3)
    assert s.u0 == pytest.approx(want.min() / want.mean(), rel=3e-3)
    core_scene = ext.build.export(ext).scene
    e, _se, _n = ext.core.point_illuminance(core_scene, p, surface.normals, spp=8)
    assert s.mean == pytest.approx(float(e.mean()), rel=1e-5)  # the same integrator on the same points
    assert s.minimum == pytest.approx(float(e.min()), rel=1e-5)
    grid = bpy.data.objects[f"{plane.name} lux grid"]
    attr = grid.data.color_attributes[ops.ATTRIBUTE]
    assert len(grid.data.polygons) == 16 and attr.domain == "CORNER" and len(attr.data) == 64
    path = tmp_path / "lux.blend"
    bpy.ops.wm.save_as_mainfile(filepath=str(path))
    bpy.ops.wm.open_mainfile(filepath=str(path))
    s2 = bpy.data.objects["Target"].spectral_gi_lux
    assert s2.valid and s2.mean == pytest.approx(want.mean(), rel=1e-3) and s2.n_points == 16


def test_faces_kind_and_bad_input(ext, bpy):
    ops = lux_ops(ext)
    plane = open_floor(ext, bpy)
    plane.spectral_gi_lux.kind = "FACES"
    assert bpy.ops.spectral_gi.lux_calculate() == {"FINISHED"}
    attr = plane.data.color_attributes[ops.ATTRIBUTE]
    assert attr.domain == "CORNER" and plane.spectral_gi_lux.n_points == 2
    plane.spectral_gi_lux.enabled = False
    assert ops.marked_objects(bpy.context.scene) == []
    bent = ext.build.mesh("Bent", [(0, 0, 0), (1, 0, 0), (1, 1, 0.5), (0, 1, 0)], [(0, 1, 2, 3)])
    bent.spectral_gi_lux.enabled = True
    with pytest.raises(ops.LuxInputError, match="not planar"):
        ops.build_surface(bent)
    with pytest.raises(RuntimeError, match="not planar"):  # bpy.ops turns the operator's ERROR report into this
        bpy.ops.spectral_gi.lux_calculate()


def test_add_work_plane(ext, bpy):
    room = ext.build.cube("Room", size=4.0, location=(0, 0, 2))
    bpy.context.view_layer.objects.active = room
    assert bpy.ops.spectral_gi.lux_add_workplane() == {"FINISHED"}
    wp = bpy.data.objects["Work Plane"]
    zs = [v.co.z for v in wp.data.vertices]
    assert all(math.isclose(z, 0.75, abs_tol=1e-6) for z in zs) and wp.spectral_gi_lux.enabled
    assert wp.hide_render


# ----------------------------------------------------------------------------- work planes over the floor outline

L_FLOOR = [(0, 0), (6, 0), (6, 2), (3, 2), (3, 4), (0, 4)]  # m, an L: 6 × 4 less the corner 3..6 × 2..4


def l_room(ext, height=2.8):
    """An L-shaped room: the floor as three quads (so its outline has points on straight edges), the
    ceiling as one n-gon, the walls as quads."""
    pts = [(0, 0), (3, 0), (6, 0), (6, 2), (3, 2), (3, 4), (0, 4), (0, 2)]
    verts = [(x, y, 0.0) for x, y in pts] + [(x, y, height) for x, y in pts]
    floor = [(0, 1, 4, 7), (1, 2, 3, 4), (7, 4, 5, 6)]
    ceiling = [tuple(range(15, 7, -1))]
    walls = [(k - 1 if k else 7, k, k + 8, (k - 1 if k else 7) + 8) for k in range(8)]
    return ext.build.mesh("L Room", verts, floor + ceiling + walls)


def test_work_plane_follows_an_l_shaped_floor(ext, bpy):
    ops = lux_ops(ext)
    room = l_room(ext)
    bpy.context.view_layer.objects.active = room
    poly = ops.floor_polygon(room)
    assert poly.shape == (6, 3) and np.allclose(poly[:, 2], 0.0)
    assert {tuple(p) for p in poly[:, :2].round(9).tolist()} == {tuple(map(float, p)) for p in L_FLOOR}
    assert ops._signed_area(poly[:, :2]) == pytest.approx(18.0)  # counter-clockwise, 24 − 6 m²
    assert bpy.ops.spectral_gi.lux_add_workplane() == {"FINISHED"}
    wp = bpy.data.objects["Work Plane"]
    assert len(wp.data.vertices) == 6 and len(wp.data.polygons) == 1
    assert all(math.isclose(v.co.z, 0.75, abs_tol=1e-9) for v in wp.data.vertices)
    assert wp.data.polygons[0].normal.z == pytest.approx(1.0)  # the points face up
    s = wp.spectral_gi_lux
    assert s.enabled and s.workplane and s.kind == "GRID" and s.band == pytest.approx(0.5)
    surface = ops.build_surface(wp)
    assert surface.kind == "workplane"
    want = ext.core.lux.workplane(L_FLOOR, height=0.75, band=0.5)  # core's own work plane over the polygon
    assert surface.grid_shape == want.grid_shape and surface.n_points == want.n_points
    np.testing.assert_allclose(np.sort(surface.points, axis=0), np.sort(want.points, axis=0), atol=1e-9)
    x, y = surface.points[:, 0], surface.points[:, 1]
    assert not ((x > 2.5) & (y > 1.5)).any()  # nothing in the missing corner nor its band
    assert (x >= 0.5).all() and (y >= 0.5).all() and (x <= 5.5).all() and (y <= 3.5).all()
    bpy.context.scene.spectral_gi_use_band = False
    bpy.context.view_layer.objects.active = room
    assert bpy.ops.spectral_gi.lux_add_workplane() == {"FINISHED"}
    assert bpy.data.objects["Work Plane.001"].spectral_gi_lux.band == 0.0


FLOOR_6X5 = [(0, 0), (6, 0), (6, 5), (0, 5)]  # m
COURTYARD = [(2, 2), (4, 2), (4, 3), (2, 3)]  # m, a hole in it


def test_work_plane_over_a_floor_with_a_hole(ext, bpy):
    """A floor of four quads around a 2 × 1 m courtyard: the outline and the hole are found, the work
    plane is the floor less the courtyard (triangles facing up), and its grid is core's work plane with
    the hole: nothing in the courtyard, the 0.5 m band at its edges as at the walls."""
    ops = lux_ops(ext)
    verts = [(x, y, 0.0) for x, y in FLOOR_6X5 + COURTYARD]
    room = ext.build.mesh("Courtyard Floor", verts, [(0, 1, 5, 4), (1, 2, 6, 5), (2, 3, 7, 6), (3, 0, 4, 7)])
    outline, holes = ops.floor_outline(room)
    assert {tuple(p) for p in outline[:, :2].round(9).tolist()} == {tuple(map(float, p)) for p in FLOOR_6X5}
    assert len(holes) == 1 and {tuple(p) for p in holes[0][:, :2].round(9).tolist()} == \
        {tuple(map(float, p)) for p in COURTYARD}
    assert ops.floor_polygon(room).shape == (4, 3)
    bpy.context.view_layer.objects.active = room
    assert bpy.ops.spectral_gi.lux_add_workplane() == {"FINISHED"}
    wp = bpy.data.objects["Work Plane"]
    assert len(wp.data.vertices) == 8 and len(wp.data.polygons) == 8
    assert all(p.normal.z == pytest.approx(1.0) for p in wp.data.polygons)
    assert sum(p.area for p in wp.data.polygons) == pytest.approx(30.0 - 2.0)
    surface = ops.build_surface(wp)
    want = ext.core.lux.workplane(FLOOR_6X5, height=0.75, band=0.5, holes=[COURTYARD])
    assert surface.grid_shape == want.grid_shape and surface.n_points == want.n_points
    np.testing.assert_allclose(np.sort(surface.points, axis=0), np.sort(want.points, axis=0), atol=1e-9)
    x, y = surface.points[:, 0], surface.points[:, 1]
    gap = np.hypot(np.maximum.reduce([2 - x, x - 4, 0 * x]), np.maximum.reduce([2 - y, y - 3, 0 * y]))
    assert (gap >= 0.5 - 1e-9).all() and surface.n_points < ext.core.lux.workplane(FLOOR_6X5).n_points


def test_work_plane_needs_a_floor(ext, bpy):
    ops = lux_ops(ext)
    wall = ext.build.mesh("Wall", [(0, 0, 0), (1, 0, 0), (1, 0, 1), (0, 0, 1)], [(0, 1, 2, 3)])
    with pytest.raises(ops.LuxInputError, match="no floor"):
        ops.floor_polygon(wall)
    bpy.context.view_layer.objects.active = wall
    with pytest.raises(RuntimeError, match="no floor"):
        bpy.ops.spectral_gi.lux_add_workplane()


# ----------------------------------------------------------------------------- background job: cancel, errors


def _plan_pixels(img):
    a = np.empty(img.size[0] * img.size[1] * 4, np.float32)
    img.pixels.foreach_get(a)
    return a


def test_cancel_keeps_the_earlier_result(ext, bpy, monkeypatch):
    ops = lux_ops(ext)
    job_mod = importlib.import_module(ext.module.__name__ + ".addon.lux_job")
    plane = open_floor(ext, bpy)
    plane.spectral_gi_lux.samples = 64  # batches of 16, 16, 32 samples: a cancel after the first stops early
    bpy.context.view_layer.objects.active = plane
    assert bpy.ops.spectral_gi.lux_calculate() == {"FINISHED"}
    s = plane.spectral_gi_lux
    before = (s.mean, s.minimum, s.maximum, s.u0, s.samples_used)
    stored = list(plane[ops.RESULT_KEY]["lux"])
    pixels = _plan_pixels(s.plan_image)
    bpy.data.objects["Bulb"].data.spectral_gi.value = 4 * I_CD  # a different scene: a result would differ

    # the operator (on the calling thread in the background), cancelled after its first batch
    seen = []

    def cancel_after_first(job, done, total):
        seen.append((done, total))
        job.request_cancel()

    monkeypatch.setattr(job_mod.LuxJob, "on_progress", cancel_after_first)
    assert bpy.ops.spectral_gi.lux_calculate() == {"CANCELLED"}
    assert seen == [(16 * 16, 16 * 64)]  # 16 points × the first batch of 16, of 16 × 64 samples
    assert job_mod.STATE.phase == "Cancelled" and not job_mod.STATE.running and not job_mod.busy()
    assert (s.mean, s.minimum, s.maximum, s.u0, s.samples_used) == before
    assert list(plane[ops.RESULT_KEY]["lux"]) == stored
    np.testing.assert_array_equal(_plan_pixels(s.plan_image), pixels)

    # the worker thread, as the modal operator runs it
    job = ops.prepare_job(bpy.context, [plane])
    job.start()
    job.thread.join(timeout=600)
    assert job.poll() and job.cancelled and job.results == {} and ops.store_job(job) == []
    assert s.mean == before[0]

    # an integrator failure is reported, not raised into Blender; the result stays
    monkeypatch.setattr(job_mod.LuxJob, "on_progress", None)

    def boom(*args, **kw):
        raise RuntimeError("integrator exploded")

    monkeypatch.setattr(ext.core, "point_illuminance", boom, raising=False)
    with pytest.raises(RuntimeError, match="integrator exploded"):
        bpy.ops.spectral_gi.lux_calculate()
    assert job_mod.STATE.phase == "Failed" and s.mean == before[0]
    monkeypatch.delattr(ext.core, "point_illuminance")
    assert bpy.ops.spectral_gi.lux_calculate() == {"FINISHED"}
    assert s.mean == pytest.approx(4 * before[0], rel=1e-9)  # I × 4: every sample × 4


# ----------------------------------------------------------------------------- false-colour scale, points outside


def _corner_colours(obj, ops):
    attr = obj.data.color_attributes[ops.ATTRIBUTE]
    a = np.empty(len(attr.data) * 4, np.float32)
    attr.data.foreach_get("color", a)
    return a.reshape(-1, 4)


def test_fixed_logarithmic_range_and_steps_reach_every_overlay(ext, bpy, tmp_path):
    """The surface's scale settings (fixed range, logarithmic, steps) are the ones core draws the
    viewport colours, the plan and the report page with; Update False Colours redraws without
    calculating; a range core cannot draw is refused before a calculation."""
    ops = lux_ops(ext)
    lux = ext.core.lux
    plane = open_floor(ext, bpy)
    bpy.context.view_layer.objects.active = plane
    assert bpy.ops.spectral_gi.lux_calculate() == {"FINISHED"}
    s = plane.spectral_gi_lux
    surface, e, se, spp, _lum = ops.saved_result(plane)
    assert (s.scale_min, s.scale_max) == pytest.approx(lux.auto_range(e))
    s.scale_auto, s.scale_fixed_min, s.scale_fixed_max, s.scale_log, s.scale_steps = False, 5.0, 40.0, True, 3
    assert bpy.ops.spectral_gi.lux_recolour() == {"FINISHED"}
    assert (s.scale_min, s.scale_max) == pytest.approx((5.0, 40.0)) and s.valid
    options = {"vmin": 5.0, "vmax": 40.0, "steps": 3, "scale": "log"}
    want = lux.colour_attribute(surface, e, linear=True, **options)
    grid = bpy.data.objects[f"{plane.name} lux grid"]
    got = _corner_colours(grid, ops)
    np.testing.assert_allclose(got, np.repeat(want, 4, axis=0), atol=1e-6)
    assert len({tuple(c) for c in np.round(got, 6).tolist()}) <= 3
    assert not np.allclose(got, np.repeat(lux.colour_attribute(surface, e, linear=True), 4, axis=0))
    plan = _plan_pixels(s.plan_image).reshape(s.plan_image.size[1], s.plan_image.size[0], 4)[::-1]
    np.testing.assert_allclose(plan, lux.plan_image(surface, e, size=ops.PLAN_SIZE, **options), atol=1 / 255)
    if ops.has_matplotlib():
        written, _img = ops.write_report(bpy.context, plane, str(tmp_path))
        assert any(p.endswith(".pdf") for p in written)
    s.scale_fixed_min = 0.0  # a logarithmic scale from 0 lx
    with pytest.raises(RuntimeError, match="Range Minimum above 0"):
        bpy.ops.spectral_gi.lux_recolour()
    with pytest.raises(RuntimeError, match="Range Minimum above 0"):
        bpy.ops.spectral_gi.lux_calculate()
    s.scale_log, s.scale_fixed_max = False, 0.0
    with pytest.raises(RuntimeError, match="Range Maximum"):
        bpy.ops.spectral_gi.lux_calculate()
    s.scale_auto, s.scale_steps = True, 0  # automatic and continuous again
    assert bpy.ops.spectral_gi.lux_recolour() == {"FINISHED"}
    np.testing.assert_allclose(_corner_colours(bpy.data.objects[f"{plane.name} lux grid"], ops),
                               np.repeat(lux.colour_attribute(surface, e, linear=True, steps=0), 4, axis=0),
                               atol=1e-6)


def test_points_outside_the_lit_geometry_are_warned_and_kept(ext, bpy, tmp_path):
    """A surface facing away from the only light, with nothing to reflect: every point reads 0 lx;
    the job names them in one warning line, the count is kept with the result and in the report's JSON."""
    import json

    ops = lux_ops(ext)
    plane = open_floor(ext, bpy)
    under = ext.build.plane("Under", size=1.0, location=(0, 0, -0.5))
    under.rotation_euler = (math.pi, 0.0, 0.0)  # facing down, away from the lamp
    under.hide_render = True
    bpy.context.view_layer.update()
    su = under.spectral_gi_lux
    su.enabled, su.kind, su.samples = True, "FACES", 8
    job = ops.prepare_job(bpy.context, [plane, under])
    job.run_sync()
    lines = ops.store_job(job)
    warnings = ops.unlit_warnings(job)
    assert len(lines) == 2 and len(warnings) == 1
    assert warnings[0].startswith("2 of 2 points of 'Under' look outside the lit geometry (2 read 0 lx")
    assert "0 (in open space" in warnings[0] and "1 (in open space" in warnings[0]
    assert su.unlit_points == 2 and plane.spectral_gi_lux.unlit_points == 0
    assert ops.saved_unlit(under)["indices"] == [0, 1] and ops.saved_unlit(plane)["count"] == 0
    ops.write_report(bpy.context, under, str(tmp_path))
    assert json.loads((tmp_path / "Under_lux.json").read_text())["unlit_points"]["count"] == 2


# ----------------------------------------------------------------------------- the office, one click to the report


def office_module():
    from pathlib import Path

    path = Path(__file__).resolve().parents[2] / "benchmarks" / "office_report.py"
    spec = importlib.util.spec_from_file_location("spectral_gi_office_report", path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def _png_size(path):
    import struct

    data = path.read_bytes()
    assert data[:8] == b"\x89PNG\r\n\x1a\n"
    return struct.unpack(">II", data[16:24])


@pytest.mark.slow
def test_office_one_click_report(ext, bpy, tmp_path, monkeypatch):
    import json

    ops = lux_ops(ext)
    office = office_module()
    office.build_office(bpy)
    scene = bpy.context.scene
    scene.spectral_gi_report_dir = str(tmp_path / "report")
    assert ops.marked_objects(scene) == []
    assert bpy.ops.spectral_gi.lux_report() == {"FINISHED"}

    # the work plane it added: the floor at 0.75 m, a 0.5 m band, the EN 12464-1 grid (5 × 3 m inside the band:
    # d = 5 m, p = 0.2 · 5^log10(5) = 0.617 m, 9 × 5 points)
    wp = bpy.data.objects["Work Plane"]
    s = wp.spectral_gi_lux
    assert s.valid and s.workplane and (s.grid_cols, s.grid_rows) == (9, 5) and s.n_points == 45
    assert s.band_used == pytest.approx(0.5) and s.samples_used == 64
    stem = tmp_path / "report" / "Work_Plane_lux"
    for suffix in (".csv", ".json", ".png", ".pdf", "_plan.png"):
        assert stem.with_name(stem.name + suffix).is_file(), suffix
    assert _png_size(stem.with_suffix(".png")) == (1754, 1240)  # A4 landscape at 150 dpi
    summary = json.loads(stem.with_suffix(".json").read_text())

    # the same numbers as core on the exported scene: the same points, seed and samples
    surface = ops.build_surface(wp)
    assert surface.kind == "workplane"
    exported = ext.build.export(ext)
    e, se, used = ext.core.point_illuminance(exported.scene, surface.points, surface.normals, spp=64)
    st = ext.core.lux.statistics(surface, e, se, samples=64)
    got = summary["statistics"]
    for key in ("mean", "minimum", "maximum", "u0", "ud", "max_rel_std_error"):
        assert got[key] == pytest.approx(getattr(st, key), rel=1e-12), key
    assert (s.mean, s.minimum, s.maximum) == pytest.approx((st.mean, st.minimum, st.maximum), rel=1e-6)
    assert s.u0 == pytest.approx(st.u0, rel=1e-6) and s.ud == pytest.approx(st.ud, rel=1e-6)
    csv = np.loadtxt(stem.with_suffix(".csv"), delimiter=",", skiprows=1)
    np.testing.assert_allclose(csv[:, 6], e, rtol=1e-12)
    # the luminaire schedule: four profiled point lights of 1000π lm (the profile I = 1000 cd cos θ)
    (row,) = summary["luminaires"]
    assert row["count"] == 4 and row["type"] == "point" and "cosine_downlight" in row["profile"]
    assert row["lumens"] == pytest.approx(office.I0 * math.pi, rel=2e-3)
    # a lit office: the inter-reflections add to the direct light everywhere on average
    direct = np.array([office.direct_illuminance(*p) for p in surface.points])
    assert st.mean > 1.1 * direct.mean()

    # the images in Blender, packed into the .blend, and the false colours on the grid
    plan, page = s.plan_image, s.report_image
    assert plan is not None and plan.packed_file is not None
    assert tuple(plan.size) == (512 + 12 + 32, 341)  # the 6 × 4 m room at 512 px, then the legend bar
    assert page is not None and page.packed_file is not None and tuple(page.size) == (1754, 1240)
    grid = bpy.data.objects[s.result_object]
    assert ops.ATTRIBUTE in grid.data.color_attributes and grid.data.materials[0].name == ops.MATERIAL

    # the direct component by hand: a black room, maintenance factor 0.8
    for name in ("Floor", "Walls", "Ceiling"):
        bpy.data.materials[name].node_tree.nodes["Diffuse BSDF"].inputs["Color"].default_value = (0, 0, 0, 1)
    s.maintenance_factor = 0.8
    bpy.context.view_layer.objects.active = wp
    assert bpy.ops.spectral_gi.lux_calculate() == {"FINISHED"}
    surface2, e2, se2, spp2, _ = ops.saved_result(wp)
    np.testing.assert_array_equal(surface2.points, surface.points)
    tol = 5.0 * se2 + 2e-3 * direct  # Monte Carlo (the light picked per sample) and the profile's 5° table
    assert (np.abs(e2 - direct) <= tol).all(), np.abs(e2 - direct) / tol
    k = int(np.argmax(direct))
    assert e2[k] == pytest.approx(direct[k], rel=0.02)
    assert s.mean == pytest.approx(0.8 * direct.mean(), rel=0.02) and s.mf_used == pytest.approx(0.8)

    # kept in the .blend: the numbers, the images and the values a report is written from
    path = tmp_path / "office.blend"
    bpy.ops.wm.save_as_mainfile(filepath=str(path))
    mean = s.mean
    bpy.ops.wm.open_mainfile(filepath=str(path))
    wp = bpy.data.objects["Work Plane"]
    s = wp.spectral_gi_lux
    assert s.valid and s.mean == pytest.approx(mean, rel=1e-6) and s.n_points == 45
    assert s.plan_image.packed_file is not None and s.report_image.packed_file is not None
    assert _plan_pixels(s.plan_image)[3::4].max() == 1.0
    bpy.context.view_layer.objects.active = wp
    bpy.context.scene.spectral_gi_report_dir = str(tmp_path / "again")
    monkeypatch.setattr(ops, "has_matplotlib", lambda: False)  # Blender's own Python: no matplotlib
    assert bpy.ops.spectral_gi.lux_export_report() == {"FINISHED"}
    again = tmp_path / "again" / "Work_Plane_lux"
    assert sorted(p.name for p in again.parent.iterdir()) == ["Work_Plane_lux.csv", "Work_Plane_lux.json",
                                                             "Work_Plane_lux_plan.png"]
    assert json.loads(again.with_suffix(".json").read_text())["statistics"]["mean"] == pytest.approx(mean, rel=1e-6)
    assert _png_size(again.with_name("Work_Plane_lux_plan.png")) == tuple(s.plan_image.size)


def test_panels_show_the_result_and_the_progress(ext, bpy):
    from unittest import mock

    job_mod = importlib.import_module(ext.module.__name__ + ".addon.lux_job")
    plane = open_floor(ext, bpy)
    bpy.context.view_layer.objects.active = plane
    assert bpy.ops.spectral_gi.lux_calculate() == {"FINISHED"}
    labels, props, ops_used = [], [], []

    def layout():
        return recording_layout(props, labels, ops_used)

    ctx = mock.MagicMock(object=plane, scene=bpy.context.scene)
    bpy.types.SPECTRALGI_PT_lux.draw(mock.MagicMock(layout=layout()), ctx)
    s = plane.spectral_gi_lux
    assert f"{s.mean:.4g} lx" in labels and "4 × 4" in labels and "U0 = Emin/Ē" in labels
    assert {"enabled", "samples", "maintenance_factor", "spectral_gi_workplane_height", "spectral_gi_use_band",
            "spectral_gi_report_dir"} <= set(props)
    assert {"spectral_gi.lux_calculate", "spectral_gi.lux_report", "spectral_gi.lux_show_image"} <= set(ops_used)
    labels.clear()
    bpy.types.SPECTRALGI_PT_lux_view3d.draw(mock.MagicMock(layout=layout()), bpy.context)
    assert "Target" in labels and any(t.startswith(f"Ē {s.mean:.4g} lx") for t in labels)
    job_mod.STATE.begin(100)  # as while a calculation runs
    job_mod.STATE.done = 25
    try:
        labels.clear()
        bpy.types.SPECTRALGI_PT_lux_view3d.draw(mock.MagicMock(layout=layout()), bpy.context)
        assert any("25/100 samples" in t and "Esc to cancel" in t for t in labels)
    finally:
        job_mod.STATE.running = False


def test_the_modal_operator_polls_the_worker_and_esc_cancels(ext, bpy, monkeypatch):
    """The operator's modal steps (timer events while the worker thread runs, Esc), driven by hand: Blender
    in the background sends no events."""
    import threading
    import time
    from types import SimpleNamespace

    ops = lux_ops(ext)
    job_mod = importlib.import_module(ext.module.__name__ + ".addon.lux_job")
    plane = open_floor(ext, bpy)
    plane.spectral_gi_lux.samples = 64
    bpy.context.view_layer.objects.active = plane
    cls = ops.SPECTRALGI_OT_lux_calculate
    reports = []

    class Modal(ops._LuxJobOperator):  # the operator's own methods on a stand-in instance
        _finish = cls._finish

        def __init__(self, job):
            self._job, self._timer = job, None

        def report(self, kind, text):
            reports.append((set(kind), text))

    timer = SimpleNamespace(type="TIMER", value="NOTHING")
    esc = SimpleNamespace(type="ESC", value="PRESS")

    def drive(op, before_each=None):
        for _ in range(60000):
            if before_each is not None:
                before_each()
            r = op.modal(bpy.context, timer)
            if r != {"PASS_THROUGH"}:
                return r
            time.sleep(0.01)
        raise AssertionError("the calculation did not finish")

    # the worker is held after its first batch, so that it is seen running however fast it is
    release = threading.Event()
    monkeypatch.setattr(job_mod.LuxJob, "on_progress",
                        lambda self, done, total: release.wait(60))
    job = ops.prepare_job(bpy.context, [plane])
    job.start()
    assert job.thread is not None and job_mod.busy() and not bpy.ops.spectral_gi.lux_report.poll()
    release.set()
    assert drive(Modal(job)) == {"FINISHED"}
    s = plane.spectral_gi_lux
    assert s.valid and not job_mod.busy() and any("Ē" in text for _k, text in reports)
    first = s.mean

    # Esc while the worker waits after its first batch: nothing is stored
    bpy.data.objects["Bulb"].data.spectral_gi.value = 2 * I_CD
    go = threading.Event()
    monkeypatch.setattr(job_mod.LuxJob, "on_progress", lambda self, done, total: go.wait(60))
    job = ops.prepare_job(bpy.context, [plane])
    job.start()
    op = Modal(job)
    assert op.modal(bpy.context, esc) == {"RUNNING_MODAL"} and job.cancel_requested
    go.set()
    assert drive(op) == {"CANCELLED"}
    assert job.results == {} and s.mean == first and job_mod.STATE.phase == "Cancelled"
    assert reports[-1][0] == {"WARNING"} and "earlier results are kept" in reports[-1][1]
