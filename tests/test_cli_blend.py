"""``spectral-gi render-blend``: failures in one line, and a real .blend rendered headlessly."""
import json
import subprocess
import sys
import textwrap

import numpy as np
import pytest

from spectral_gi.core.cli import main


def test_missing_file(tmp_path, capsys):
    assert main(["render-blend", str(tmp_path / "nope.blend")]) == 1
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "nope.blend: no such file" in err


def test_not_a_blend_file(tmp_path, capsys):
    p = tmp_path / "scene.blend"
    p.write_text("not a blend file")
    assert main(["render-blend", str(p)]) == 1
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "not a .blend file" in err


def test_bpy_missing(tmp_path):
    p = tmp_path / "fake.blend"
    p.write_bytes(b"BLENDER-v500" + bytes(64))  # passes the header check; bpy is then needed
    code = ("import sys; sys.modules['bpy'] = None; from spectral_gi.core.cli import main; "
            f"sys.exit(main(['render-blend', {str(p)!r}]))")
    proc = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert proc.returncode == 1
    assert proc.stderr.count("\n") == 1 and "bpy module" in proc.stderr, proc.stderr


MAKE_BLEND = textwrap.dedent("""
    import math, sys
    import bpy
    from spectral_gi.addon import registration
    registration.register()
    bpy.ops.wm.read_homefile(use_empty=True)
    scene = bpy.context.scene
    def link(o):
        scene.collection.objects.link(o)
        return o
    m = bpy.data.materials.new("Grey")
    t = m.node_tree
    t.nodes.clear()
    out, d = t.nodes.new("ShaderNodeOutputMaterial"), t.nodes.new("ShaderNodeBsdfDiffuse")
    d.inputs["Color"].default_value = (0.5, 0.5, 0.5, 1.0)
    t.links.new(d.outputs[0], out.inputs["Surface"])
    me = bpy.data.meshes.new("Floor")
    me.from_pydata([(-3, -3, 0), (3, -3, 0), (3, 3, 0), (-3, 3, 0)], [], [(0, 1, 2, 3)])
    me.materials.append(m)
    link(bpy.data.objects.new("Floor", me))
    light = bpy.data.lights.new("Key", "AREA")
    light.energy, light.size = 200.0, 1.0
    link(bpy.data.objects.new("Key", light)).location = (0, 0, 3)
    cam = link(bpy.data.objects.new("Cam", bpy.data.cameras.new("Cam")))
    cam.location, cam.rotation_euler = (0, -6, 3), (math.radians(60), 0, 0)
    scene.camera = cam
    scene.render.resolution_x, scene.render.resolution_y, scene.render.resolution_percentage = 12, 8, 100
    scene.spectral_gi.samples = 2
    bpy.ops.wm.save_as_mainfile(filepath=sys.argv[1])
""")


@pytest.mark.blender
def test_render_blend_end_to_end(tmp_path):
    pytest.importorskip("bpy")
    blend = tmp_path / "scene.blend"
    made = subprocess.run([sys.executable, "-c", MAKE_BLEND, str(blend)], capture_output=True, text=True)
    assert made.returncode == 0 and blend.is_file(), made.stderr[-2000:]
    out, report = tmp_path / "out" / "render.exr", tmp_path / "report.json"
    proc = subprocess.run([sys.executable, "-m", "spectral_gi.core.cli", "render-blend", str(blend), "--out",
                           str(out), "--spp", "4", "--compare-cycles", "--json", str(report)],
                          capture_output=True, text=True, timeout=1200)
    assert proc.returncode == 0, proc.stderr[-3000:]
    from spectral_gi.core import read_exr

    chans, header = read_exr(out)
    assert chans["R"].shape == (8, 12)
    lum = chans["Luminance.Y"]
    assert lum.mean() > 0.0 and np.all(np.isfinite(lum))
    assert out.with_suffix(".png").is_file()
    doc = json.loads(report.read_text())
    assert doc["samples"] == 4 and (doc["width"], doc["height"]) == (12, 8)  # --spp overrides the file's 2
    assert doc["mean_luminance"] == pytest.approx(float(lum.mean()), rel=1e-5)
    cmp = doc["comparison"]
    assert cmp["samples"] == 4 and np.isfinite(cmp["luminance_ratio"]) and cmp["luminance_ratio"] > 0.5
