"""The interactive (viewport) renderer: coarse-to-fine frames, restarts, what an update rebuilds."""
import dataclasses

import numpy as np
import pytest

from spectral_gi.core import InteractiveRender, cornell_box, render
from spectral_gi.core.camera.record import camera_vector
from spectral_gi.core.camera import kernel as K
from spectral_gi.core.integrators.interactive import preview_rgba, scaled_camera


def test_scaled_camera_keeps_the_field_of_view():
    cam = cornell_box(width=64, height=48).camera
    for p in (2, 4):
        small = scaled_camera(cam, p)
        assert (small.width, small.height) == (64 // p, 48 // p)
        a, b = camera_vector(cam), camera_vector(small)
        assert a[K.CAM_HALF_W] == pytest.approx(b[K.CAM_HALF_W])
        assert a[K.CAM_HALF_H] == pytest.approx(b[K.CAM_HALF_H])
    odd = scaled_camera(dataclasses.replace(cam, width=65, height=47), 4)
    assert (odd.width, odd.height) == (17, 12)  # rounded up: the coarse image covers the whole view
    assert scaled_camera(cam, 1) is cam


def _session(**kw):
    return InteractiveRender(threads=2, **kw).start()


@pytest.mark.slow
def test_frames_go_coarse_to_fine_and_converge_to_the_final_render():
    scene = cornell_box(width=32, height=24, spp=6, max_depth=4)
    published = []  # every frame the worker publishes, in order (polling may miss one under load)
    s = _session(on_frame=lambda fr: published.append((fr.generation, fr.pixel_size, fr.spp)))
    try:
        gen = s.update(scene=scene)
        while True:
            f = s.wait_frame(gen, timeout=600)
            assert f is not None, s.error
            if f.pixel_size == 1 and f.spp >= 6:
                break
        sizes = [size for g, size, _spp in published if g == gen]
        assert sizes[:3] == [4, 2, 1]
        assert s.converged
        assert s.counters.bvh_builds == 1
        film, _ = render(scene, threads=1)
        # the same samples of the same pixels (counter-based RNG): the final render's image
        np.testing.assert_allclose(f.rgba, preview_rgba(film), rtol=1e-5, atol=1e-7)
        np.testing.assert_allclose(f.rgba[..., :3], film.develop().rgb, rtol=1e-5, atol=1e-7)
        assert f.rgba.shape == (24, 32, 4)
    finally:
        assert s.stop()


@pytest.mark.slow
def test_updates_rebuild_only_what_changed():
    scene = cornell_box(width=24, height=24, spp=2, max_depth=3)
    s = _session(pixel_sizes=())
    try:
        gen = s.update(scene=scene)
        assert s.wait_frame(gen, spp=2, timeout=600) is not None, s.error
        assert (s.counters.prepares, s.counters.bvh_builds) == (1, 1)

        # a material's colour: the scene is prepared again, the BVH kept
        materials = list(scene.materials)
        spectra = dataclasses.replace(scene.spectra, coeffs=scene.spectra.coeffs.copy())
        red = next(m for m in materials if m.name == "red")
        spectra.coeffs[red.reflectance] *= 0.5
        recoloured = dataclasses.replace(scene, spectra=spectra)
        gen = s.update(scene=recoloured)
        f = s.wait_frame(gen, spp=2, timeout=60)
        assert f is not None and f.generation == gen, s.error
        assert (s.counters.prepares, s.counters.bvh_builds) == (2, 1)
        film, _ = render(recoloured, threads=1)
        np.testing.assert_allclose(f.rgba[..., :3], film.develop().rgb, rtol=1e-5, atol=1e-7)

        # the camera: only its record is repacked; the image is the render from there
        cam = recoloured.camera
        to_world = np.array(cam.to_world, dtype=np.float64)
        to_world[0, 3] += 0.05
        moved_cam = dataclasses.replace(cam, to_world=to_world)
        gen = s.update(camera=moved_cam)
        f = s.wait_frame(gen, spp=2, timeout=60)
        assert f is not None, s.error
        assert s.counters.prepares == 2 and s.counters.camera_updates == 1
        film, _ = render(dataclasses.replace(recoloured, camera=moved_cam), threads=1)
        np.testing.assert_allclose(f.rgba[..., :3], film.develop().rgb, rtol=1e-5, atol=1e-7)

        # geometry: a mesh moved, the BVH is built again
        meshes = list(recoloured.meshes)
        m0 = meshes[-1]
        meshes[-1] = dataclasses.replace(m0, positions=m0.positions + np.float32(0.01))
        gen = s.update(scene=dataclasses.replace(recoloured, meshes=meshes))
        assert s.wait_frame(gen, spp=1, timeout=60) is not None, s.error
        assert s.counters.bvh_builds == 2
    finally:
        assert s.stop()


@pytest.mark.slow
def test_an_update_restarts_a_long_render_and_pause_holds_it():
    scene = cornell_box(width=48, height=48, spp=100000, max_depth=6)
    paused = {"on": False}
    s = _session(should_pause=lambda: paused["on"])
    try:
        gen = s.update(scene=scene)
        assert s.wait_frame(gen, spp=4, timeout=600) is not None, s.error
        cam = scene.camera
        to_world = np.array(cam.to_world, dtype=np.float64)
        to_world[1, 3] += 0.02
        gen2 = s.update(camera=dataclasses.replace(cam, to_world=to_world))
        f = s.wait_frame(gen2, timeout=30)
        assert f is not None and f.generation == gen2 and f.pixel_size == 4 and f.spp == 1
        assert 0.0 < f.restart_seconds < 30.0
        paused["on"] = True
        held = s.wait_frame(gen2, spp=3, timeout=2.0)  # at most the pass in flight completes
        spp = (held or s.frame()).spp
        import time
        time.sleep(0.5)
        assert s.frame().spp == spp
        paused["on"] = False
        assert s.wait_frame(gen2, spp=spp + 1, timeout=30) is not None
        assert s.counters.aborted >= 0
    finally:
        assert s.stop()
