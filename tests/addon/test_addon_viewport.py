"""The viewport: the view's camera, what a depsgraph update re-exports, the interactive render's restarts."""
import importlib
import math
import time

import numpy as np
import pytest

pytestmark = pytest.mark.blender

MODULE = "bl_ext.user_default.spectral_gi"


def modules():
    return tuple(importlib.import_module(MODULE + name)
                 for name in (".addon.viewport", ".addon.export.camera", ".core.camera.record", ".core"))


def camera_view(bpy, cam_obj, w, h):
    """The matrices of a viewport looking through ``cam_obj``: view = the camera's inverse, window = its projection."""
    dg = bpy.context.evaluated_depsgraph_get()
    ev = cam_obj.evaluated_get(dg)
    return (np.array(ev.matrix_world.inverted()), np.array(ev.calc_matrix_camera(dg, x=w, y=h)))


def viewport_camera(bpy, ext_camera, cam_obj, w, h, scale=1.0):
    view, window = camera_view(bpy, cam_obj, w, h)
    return ext_camera.view_camera(view, window, w, h, scale)


@pytest.mark.parametrize("setup", [
    dict(lens=35.0, w=64, h=40),
    dict(lens=50.0, w=40, h=64, shift_x=0.1, shift_y=-0.05),
    dict(lens=24.0, w=50, h=50, sensor_fit="VERTICAL", sensor_height=20.0),
    dict(ortho=3.5, w=64, h=32, shift_x=0.2),
])
def test_the_view_camera_matches_the_exported_camera(ext, bpy, setup):
    """A viewport looking through the scene camera renders what F12 renders: the core camera built
    from the view and projection matrices packs to the camera export's record."""
    _, cam_mod, record, core = modules()
    b = ext.build
    obj = b.camera(location=(1.0, -5.0, 2.0), rotation=(math.radians(70), math.radians(5), math.radians(20)))
    data = obj.data
    if "ortho" in setup:
        data.type, data.ortho_scale = "ORTHO", setup["ortho"]
    else:
        data.lens = setup["lens"]
    data.shift_x, data.shift_y = setup.get("shift_x", 0.0), setup.get("shift_y", 0.0)
    data.sensor_fit = setup.get("sensor_fit", "AUTO")
    if "sensor_height" in setup:
        data.sensor_height = setup["sensor_height"]
    b.resolution(setup["w"], setup["h"])
    b.plane("Floor")
    exported = b.export(ext).scene.camera
    view = viewport_camera(bpy, cam_mod, obj, setup["w"], setup["h"])
    a, v = record.camera_vector(exported), record.camera_vector(view)
    np.testing.assert_allclose(v, a, rtol=1e-5, atol=1e-6)
    assert (view.width, view.height) == (exported.width, exported.height)


def test_an_orthographic_view_starts_its_rays_at_the_near_plane(ext):
    _, cam_mod, _, core = modules()
    # Blender's orthographic viewport: clipping from -clip_end/2 to +clip_end/2 about the view point
    view = np.eye(4)
    half, near, far = 2.0, -50.0, 50.0
    window = np.diag([1 / half, 1 / half, -2.0 / (far - near), 1.0])
    window[2, 3] = -(far + near) / (far - near)
    cam = cam_mod.view_camera(view, window, 100, 100)
    assert cam.projection == core.constants.CAM_ORTHOGRAPHIC
    assert cam.ortho_scale == pytest.approx(2 * half)
    np.testing.assert_allclose(cam.to_world[:3, 3], [0.0, 0.0, 50.0])  # moved back along +Z (the view looks at -Z)


def changes_of(bpy, vp_mod, action):
    """The Changes of the depsgraph update ``action()`` causes (from a real update handler)."""
    seen = []

    def handler(scene, depsgraph):
        seen.append(vp_mod.classify(depsgraph))

    bpy.app.handlers.depsgraph_update_post.append(handler)
    try:
        action()
        bpy.context.view_layer.update()
    finally:
        bpy.app.handlers.depsgraph_update_post.remove(handler)
    out = vp_mod.Changes()
    for c in seen:
        out.kinds |= c.kinds
        out.objects |= c.objects
        out.meshes |= c.meshes
    return out


def small_scene(b):
    grey = b.principled("Grey", rgb=(0.6, 0.6, 0.6))
    red = b.principled("Red", rgb=(0.7, 0.1, 0.1))
    b.plane("Floor", size=6.0, material=grey)
    cube = b.cube("Cube", size=1.0, location=(0, 0, 0.5), material=red)
    key = b.light("Key", "AREA", location=(0, 0, 3), energy=200.0, size=1.0)
    cam = b.camera(location=(0, -6, 2), rotation=(math.radians(75), 0, 0), lens=30.0)
    b.scene.world = b.bpy.data.worlds.new("World")
    b.scene.spectral_gi.max_bounces = 4
    return cube, red, key, cam


def test_depsgraph_updates_are_classified(ext, bpy):
    vp_mod = modules()[0]
    cube, red, key, cam = small_scene(ext.build)
    bpy.context.view_layer.update()
    bsdf = next(n for n in red.node_tree.nodes if n.type == "BSDF_PRINCIPLED")

    def edit():
        cube.data.vertices[0].co.z += 0.1
        cube.data.update()

    ch = changes_of(bpy, vp_mod, lambda: setattr(cube, "location", (0.2, 0, 0.5)))
    assert ch.kinds == {"geometry"} and not ch.objects and not ch.meshes  # moved: no mesh read again
    ch = changes_of(bpy, vp_mod, lambda: setattr(bsdf.inputs["Base Color"], "default_value", (0.1, 0.7, 0.1, 1)))
    assert ch.kinds == {"materials"}
    ch = changes_of(bpy, vp_mod, lambda: setattr(key.data, "energy", 50.0))
    assert ch.kinds == {"lights"}
    ch = changes_of(bpy, vp_mod, edit)
    assert ch.kinds == {"geometry"} and ("Cube" in ch.objects or cube.data.name in ch.meshes)
    ch = changes_of(bpy, vp_mod, lambda: setattr(bpy.context.scene.world, "color", (0.2, 0.3, 0.4)))
    assert ch.kinds == {"world"}
    ch = changes_of(bpy, vp_mod, lambda: setattr(cam, "location", (0, -7, 2)))
    assert ch.kinds == {"camera"} and not ch.export


@pytest.mark.slow
def test_viewport_restarts_and_re_exports_only_what_changed(ext, bpy):
    vp_mod, cam_mod, _, _ = modules()
    b = ext.build
    cube, red, key, cam = small_scene(b)
    w, h = 48, 36
    bsdf = next(n for n in red.node_tree.nodes if n.type == "BSDF_PRINCIPLED")
    published = []  # (generation, pixel size, spp) of every frame, in order (a poll may miss one)
    vp = vp_mod.ViewportRenderer(threads=2, should_pause=lambda: False,
                                 on_frame=lambda fr: published.append((fr.generation, fr.pixel_size, fr.spp)))
    s = vp.session
    latencies, core_part = {}, {}

    def first_of(generation):  # the first frame published for a generation (its callback may lag its poll)
        for _ in range(5000):
            hit = next((fr for fr in published if fr[0] == generation), None)
            if hit is not None:
                return hit
            time.sleep(0.002)
        raise AssertionError(f"no frame of generation {generation} was published")

    def handler(scene, depsgraph):
        vp.sync(depsgraph, viewport_camera(bpy, cam_mod, cam, w, h))

    def change(label, action):
        reads, builds, prepares = vp.meshes.reads, s.counters.bvh_builds, s.counters.prepares
        t0 = time.perf_counter()
        bpy.app.handlers.depsgraph_update_post.append(handler)
        try:
            action()
            bpy.context.view_layer.update()
        finally:
            bpy.app.handlers.depsgraph_update_post.remove(handler)
        f = s.wait_frame(s.generation, timeout=60)
        assert f is not None and f.generation == s.generation, (vp.error, s.error)
        latencies[label] = time.perf_counter() - t0
        core_part[label] = f.restart_seconds
        assert first_of(f.generation)[1:] == (4, 1)  # the restart's first frame is the coarsest
        return vp.meshes.reads - reads, s.counters.bvh_builds - builds, s.counters.prepares - prepares

    try:
        bpy.context.scene.spectral_gi.viewport_samples = 1000000
        dg = bpy.context.evaluated_depsgraph_get()
        changes = vp.sync(dg, viewport_camera(bpy, cam_mod, cam, w, h))
        assert changes.export and vp.exports == 1 and vp.meshes.reads == 2
        f = s.wait_frame(spp=4, timeout=900)
        assert f is not None and f.pixel_size == 1 and f.rgba.shape == (h, w, 4), (vp.error, s.error)
        assert np.isfinite(f.rgba).all() and f.rgba[..., :3].max() > 0.0

        # a material's colour: materials exported again, no mesh read, the BVH kept
        assert change("material", lambda: setattr(bsdf.inputs["Base Color"], "default_value",
                                                   (0.1, 0.7, 0.1, 1))) == (0, 0, 1)
        assert vp.last.kinds == {"materials"}
        # a light: the same
        assert change("light", lambda: setattr(key.data, "energy", 400.0)) == (0, 0, 1)
        # an object moved: its cached triangles placed again, the BVH rebuilt
        assert change("move", lambda: setattr(cube, "location", (0.3, 0.0, 0.5))) == (0, 1, 1)

        # its mesh edited: that one mesh read again
        def edit():
            cube.data.vertices[0].co.z += 0.2
            cube.data.update()

        assert change("edit", edit) == (1, 1, 1)

        # the view: the camera only, nothing exported
        exports, prepares = vp.exports, s.counters.prepares
        t0 = time.perf_counter()
        view, window = camera_view(bpy, cam, w, h)
        view[0, 3] += 0.1
        assert vp.view(cam_mod.view_camera(view, window, w, h))
        f = s.wait_frame(s.generation, timeout=60)
        latencies["view"] = time.perf_counter() - t0
        core_part["view"] = f.restart_seconds
        assert f is not None and first_of(f.generation)[1] == 4
        assert vp.exports == exports and s.counters.prepares == prepares and s.counters.camera_updates == 1
        assert not vp.view(cam_mod.view_camera(view, window, w, h))  # the same view: no restart
        print("\nviewport restart latency (change → first frame), s: "
              + ", ".join(f"{k} {v:.3f}" for k, v in latencies.items())
              + "; of which the core's restart (update → first frame): "
              + ", ".join(f"{k} {v:.3f}" for k, v in core_part.items()))
        for v in latencies.values():
            assert v < 10.0  # a restart never waits for the render it interrupts
    finally:
        assert vp.stop(wait=10.0)


def test_the_engine_reads_the_region_it_draws(ext, bpy):
    """view_update and view_draw build the camera from the region's matrices (no GPU needed for that part)."""
    from types import SimpleNamespace

    engine = importlib.import_module(MODULE + ".addon.engine")
    _, cam_mod, record, _ = modules()
    cls = engine.SpectralGIRenderEngine
    assert callable(getattr(cls, "view_update", None)) and callable(getattr(cls, "view_draw", None))
    obj = ext.build.camera(location=(0.5, -4.0, 1.5), rotation=(math.radians(80), 0, math.radians(10)))
    view, window = camera_view(bpy, obj, 80, 50)
    import mathutils

    ctx = SimpleNamespace(region=SimpleNamespace(width=80, height=50),
                          region_data=SimpleNamespace(view_matrix=mathutils.Matrix(view.tolist()),
                                                      window_matrix=mathutils.Matrix(window.tolist())))
    bpy.context.scene.unit_settings.scale_length = 0.5
    cam = engine.region_camera(ctx, bpy.context.scene)
    expected = cam_mod.view_camera(view, window, 80, 50, 0.5)
    np.testing.assert_allclose(record.camera_vector(cam), record.camera_vector(expected))
    np.testing.assert_allclose(cam.to_world[:3, 3], 0.5 * np.array([0.5, -4.0, 1.5]), atol=1e-6)  # metres
