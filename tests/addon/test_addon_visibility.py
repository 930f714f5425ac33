"""Objects' and lights' ray visibility, Cast Shadow, light linking and shadow linking carry
over from Blender: the exported flags and link lists, and renders beside Cycles of a
scene where each flag changes the image (a card over a floor under a sun at 45°: the flag
removes the card's shadow, hides the card, or leaves the floor unlit)."""
import math

import pytest

pytestmark = pytest.mark.blender


def card_over_floor(b, bpy):
    """Floor (4 m, grey), a card (1 m, grey) 0.5 m above it, a sun at 45°, an orthographic
    camera looking straight down over 3 m. Returns (floor, card, sun)."""
    grey = b.shader("Grey", "ShaderNodeBsdfDiffuse", Color=(0.5, 0.5, 0.5, 1.0))
    floor = b.plane("Floor", size=4.0, material=grey)
    card = b.plane("Card", size=1.0, location=(-0.3, 0.0, 0.5), material=grey)
    sun = b.light("Sun", "SUN", location=(0, 0, 5), energy=3.0, angle=math.radians(0.5))
    sun.rotation_euler = (math.radians(45.0), 0.0, 0.0)  # travels along (0, sin 45°, −cos 45°)
    cam = b.camera(location=(0.0, 0.0, 6.0), rotation=(0.0, 0.0, 0.0))
    cam.data.type = "ORTHO"
    cam.data.ortho_scale = 3.0
    b.resolution(16, 16)
    s = b.scene.spectral_gi
    s.samples, s.max_bounces, s.seed = 32, 0, 1
    return floor, card, sun


def collection(bpy, name, members):
    """A light-linking collection of (object, "INCLUDE" or "EXCLUDE")."""
    coll = bpy.data.collections.new(name)
    for ob, state in members:
        coll.objects.link(ob)
    for (ob, state), entry in zip(members, coll.collection_objects):
        entry.light_linking.link_state = state
    return coll


def test_flags_and_links_are_exported(ext, bpy):
    b = ext.build
    floor, card, sun = card_over_floor(b, bpy)
    card.visible_shadow = False
    card.visible_glossy = False
    floor.visible_camera = False
    sun.visible_diffuse = False
    sun.data.use_shadow = False
    sun.light_linking.receiver_collection = collection(bpy, "Lit", [(card, "INCLUDE")])
    sun.light_linking.blocker_collection = collection(bpy, "Blockers", [(floor, "EXCLUDE")])
    res = b.export(ext)
    sc = res.scene
    names = [m.name for m in sc.meshes]
    f, c = sc.meshes[names.index("Floor")], sc.meshes[names.index("Card")]
    assert (f.visible_camera, f.visible_shadow, f.visible_glossy) == (False, True, True)
    assert (c.visible_camera, c.visible_shadow, c.visible_glossy, c.visible_diffuse) == (True, False, False, True)
    li = next(li for li in sc.lights if li.name == "Sun")
    assert (li.visible_diffuse, li.visible_glossy, li.cast_shadow) == (False, True, False)
    assert li.receivers == [names.index("Card")]  # an Include: the objects outside are not linked
    assert li.blockers == [names.index("Card")]  # only Excludes: every other object is linked
    assert f.receivers is None and f.blockers is None
    w = res.warning or ""
    assert "ray visibility" not in w and "linking" not in w, w


def _compare(bpy, s, tmp_path):
    s.compare_output_dir = str(tmp_path)
    assert bpy.ops.spectral_gi.compare_cycles() == {"FINISHED"}
    assert s.compare_valid
    return s.compare_luminance_ratio


CASES = ("plain", "card casts no shadow", "card hidden from the camera", "sun casts no shadow",
         "sun lights the card only", "only the floor blocks the sun")


@pytest.mark.slow
@pytest.mark.parametrize("case", CASES)
def test_visibility_matches_cycles(ext, bpy, tmp_path, case):
    b = ext.build
    floor, card, sun = card_over_floor(b, bpy)
    if case == "card casts no shadow":
        card.visible_shadow = False
    elif case == "card hidden from the camera":
        card.visible_camera = False
    elif case == "sun casts no shadow":
        sun.data.use_shadow = False
    elif case == "sun lights the card only":
        sun.light_linking.receiver_collection = collection(bpy, "Lit", [(card, "INCLUDE")])
    elif case == "only the floor blocks the sun":
        sun.light_linking.blocker_collection = collection(bpy, "Blockers", [(floor, "INCLUDE")])
    ratio = _compare(bpy, b.scene.spectral_gi, tmp_path)
    print(f"{case}: luminance ratio to Cycles {ratio:.4f}")
    assert ratio == pytest.approx(1.0, abs=0.03)


def test_panels_show_the_flags(ext, bpy):
    """With the engine the object panel shows the ray visibility (Cycles' own panel is
    Cycles-only) and the light panel Cast Shadow; light linking is Blender's Object >
    Shading panel, which the engine is compatible with."""
    from unittest import mock

    from helpers import recording_layout

    b = ext.build
    floor, card, sun = card_over_floor(b, bpy)
    b.scene.render.engine = "SPECTRAL_GI"
    drawn = []
    panel = bpy.types.SPECTRALGI_PT_object
    panel.draw(mock.MagicMock(layout=recording_layout(drawn)), mock.MagicMock(object=card))
    assert {"visible_camera", "visible_diffuse", "visible_glossy", "visible_transmission", "visible_volume_scatter",
            "visible_shadow", "is_holdout"} <= set(drawn)
    drawn.clear()
    panel.draw(mock.MagicMock(layout=recording_layout(drawn)), mock.MagicMock(object=sun))
    assert {"visible_camera", "visible_diffuse", "visible_glossy"} <= set(drawn) and "visible_shadow" not in drawn
    drawn.clear()
    bpy.types.SPECTRALGI_PT_light.draw(mock.MagicMock(layout=recording_layout(drawn)), mock.MagicMock(light=sun.data))
    assert "use_shadow" in drawn
    assert "SPECTRAL_GI" in bpy.types.OBJECT_PT_shading.COMPAT_ENGINES
