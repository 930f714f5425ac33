"""Schema versioning of the stored settings: a file in an older layout is updated when it is
loaded, a file saved by this version reloads unchanged, a file from a newer version is read
as it is with a warning, and values of the wrong type are skipped with a warning."""
import contextlib
import importlib

import pytest

pytestmark = pytest.mark.blender

MODULE = "bl_ext.user_default.spectral_gi"


@pytest.fixture()
def versioning(ext):
    return importlib.import_module(MODULE + ".addon.versioning")


@pytest.fixture()
def schema(ext):
    return importlib.import_module(MODULE + ".addon.properties.scene").SCHEMA_VERSION


@contextlib.contextmanager
def without_handlers(bpy, versioning, names=("save_pre",)):
    """The add-on's handlers taken out for the block: saving as an add-on without versioning did."""
    removed = []
    for name in names:
        handlers = getattr(bpy.app.handlers, name)
        for h in list(handlers):
            if getattr(h, "__module__", "") == versioning.__name__:
                handlers.remove(h)
                removed.append((handlers, h))
    try:
        yield
    finally:
        for handlers, h in removed:
            handlers.append(h)


def version_0_positions(ext):
    """Positions in the preset menus as files from before versioning stored them (the menus'
    order: the core's preset lists; a light's profile: None, File, then the sorted samples)."""
    core = ext.core
    return {
        "glass_preset": core.glass_preset_names().index("N-SF11"),
        "metal_preset": core.metal_preset_names().index("Au"),
        "reflectance_preset": core.reflectance_preset_names().index("red"),
        "profile": 2 + sorted(core.photometric_presets()).index("quadrant"),
    }


def build_old_layout(bpy, ext, raw_material=None, raw_light=None, stamp=None):
    """A scene, a glass material and a profiled spot light written as the given raw values
    (default: the version 0 positions); no stored settings version unless ``stamp``."""
    pos = version_0_positions(ext)
    scene = bpy.context.scene
    s = scene.spectral_gi
    s.samples, s.sampler, s.colour_space = 7, "HALTON", "ACESCG"
    if s.get("schema_version") is not None:
        del s["schema_version"]  # the empty file was stamped when it was read
    if stamp is not None:
        s["schema_version"] = stamp
    mat = bpy.data.materials.new("Old glass")
    mat.use_fake_user = True
    mat.spectral_gi.model, mat.spectral_gi.spectrum, mat.spectral_gi.exponent = "GLASS", "PRESET", 123.0
    raw_material = raw_material if raw_material is not None else {
        k: pos[k] for k in ("glass_preset", "metal_preset", "reflectance_preset")}
    for key, value in raw_material.items():
        mat.spectral_gi[key] = value
    light = bpy.data.lights.new("Old spot", "SPOT")
    light.use_fake_user = True
    light.spectral_gi.unit, light.spectral_gi.value = "LUMEN", 1200.0
    for key, value in (raw_light if raw_light is not None else {"profile": pos["profile"]}).items():
        light.spectral_gi[key] = value
    return pos


def save_and_open(bpy, path, versioning=None):
    """Save (without the add-on's save handler when ``versioning`` is given), then open the file."""
    with without_handlers(bpy, versioning) if versioning is not None else contextlib.nullcontext():
        assert bpy.ops.wm.save_as_mainfile(filepath=str(path), check_existing=False) == {"FINISHED"}
    bpy.ops.wm.read_homefile(use_empty=True)
    assert "Old glass" not in bpy.data.materials
    assert bpy.ops.wm.open_mainfile(filepath=str(path)) == {"FINISHED"}
    return bpy.data.materials.get("Old glass"), bpy.data.lights.get("Old spot")


def test_a_file_from_before_versioning_is_updated_on_load(ext, bpy, versioning, schema, tmp_path, capsys):
    build_old_layout(bpy, ext)
    mat, light = save_and_open(bpy, tmp_path / "old.blend", versioning)
    m = mat.spectral_gi
    assert (m.glass_preset, m.metal_preset, m.reflectance_preset) == ("N-SF11", "Au", "red")
    items = m.bl_rna.properties["glass_preset"].enum_items
    assert m.get("glass_preset") == items["N-SF11"].value >= ext.module.addon.properties.enums.FIRST_STABLE
    assert light.spectral_gi.profile == "PRESET_quadrant"
    # every other value is carried over as it was
    assert (m.model, m.spectrum, m.exponent) == ("GLASS", "PRESET", 123.0)
    assert (light.spectral_gi.unit, light.spectral_gi.value) == ("LUMEN", 1200.0)
    s = bpy.context.scene.spectral_gi
    assert (s.samples, s.sampler, s.colour_space) == (7, "HALTON", "ACESCG")
    assert s.get("schema_version") == schema == s.schema_version
    out = capsys.readouterr().err
    assert "updated 4 setting(s)" in out and "from settings version 0 to 1" in out


def test_without_the_update_the_old_positions_match_no_entry(ext, bpy, versioning, tmp_path):
    """What the update prevents: without the load handler the stored positions mean nothing."""
    build_old_layout(bpy, ext)
    path = tmp_path / "old.blend"
    with without_handlers(bpy, versioning, ("save_pre",)):
        bpy.ops.wm.save_as_mainfile(filepath=str(path), check_existing=False)
    with without_handlers(bpy, versioning, ("load_post",)):
        bpy.ops.wm.open_mainfile(filepath=str(path))
    m = bpy.data.materials["Old glass"].spectral_gi
    assert m.glass_preset != "N-SF11" and bpy.data.lights["Old spot"].spectral_gi.profile != "PRESET_quadrant"
    assert bpy.context.scene.spectral_gi.get("schema_version") is None


def snapshot(bpy):
    """Every Spectral GI setting of the file's scenes, materials and lights, and their raw stored values."""
    def plain(v):
        return tuple(v) if hasattr(v, "__len__") and not isinstance(v, str) else v

    out = {}
    for kind in ("scenes", "materials", "lights"):
        for d in getattr(bpy.data, kind):
            g = d.spectral_gi
            rna = {p.identifier: plain(getattr(g, p.identifier)) for p in g.bl_rna.properties
                   if p.identifier not in ("rna_type", "name")}
            raw = {k: plain(g[k]) for k in g.keys()}
            out[(kind, d.name)] = (rna, raw)
    return out


def test_a_file_saved_by_this_version_reloads_unchanged(ext, bpy, versioning, schema, tmp_path, capsys):
    s = bpy.context.scene.spectral_gi
    s.samples, s.observer = 9, "CIE1964"
    second = bpy.data.scenes.new("Second")  # a new scene stores its version when the file is saved
    assert second.spectral_gi.schema_version == schema and second.spectral_gi.get("schema_version") is None
    mat = bpy.data.materials.new("Glass")
    mat.use_fake_user = True
    m = mat.spectral_gi
    m.model, m.glass_preset, m.metal_preset, m.reflectance_preset = "GLASS", "N-SF6", "Cu", "blue sky"
    light = bpy.data.lights.new("Spot", "SPOT")
    light.use_fake_user = True
    light.spectral_gi.profile = "PRESET_wallwasher"
    path = tmp_path / "current.blend"
    bpy.ops.wm.save_as_mainfile(filepath=str(path), check_existing=False)
    assert all(sc.spectral_gi.get("schema_version") == schema for sc in bpy.data.scenes)
    before = snapshot(bpy)
    capsys.readouterr()
    for _ in range(2):  # loading twice changes nothing either
        bpy.ops.wm.open_mainfile(filepath=str(path))
        assert snapshot(bpy) == before
        assert versioning.LAST_MESSAGES == []
    assert bpy.data.materials["Glass"].spectral_gi.glass_preset == "N-SF6"
    assert bpy.data.lights["Spot"].spectral_gi.profile == "PRESET_wallwasher"
    assert "Spectral GI" not in capsys.readouterr().err


def test_a_file_from_a_newer_version_is_read_as_it_is_with_a_warning(ext, bpy, versioning, schema, tmp_path,
                                                                     capsys):
    newer = schema + 1
    build_old_layout(bpy, ext, raw_material={"glass_preset": 3}, raw_light={"profile": 4}, stamp=newer)
    path = tmp_path / "newer.blend"
    bpy.ops.wm.save_as_mainfile(filepath=str(path), check_existing=False)  # the save handler leaves it alone
    assert "newer version of the add-on" in capsys.readouterr().err
    bpy.ops.wm.read_homefile(use_empty=True)
    capsys.readouterr()
    bpy.ops.wm.open_mainfile(filepath=str(path))
    mat, light = bpy.data.materials["Old glass"], bpy.data.lights["Old spot"]
    out = capsys.readouterr().err
    assert "newer version of the add-on" in out and f"settings version {newer}" in out
    assert mat.spectral_gi.get("glass_preset") == 3 and light.spectral_gi.get("profile") == 4  # not "migrated"
    assert bpy.context.scene.spectral_gi.get("schema_version") == newer  # not lowered
    assert (mat.spectral_gi.model, light.spectral_gi.unit) == ("GLASS", "LUMEN")


def test_values_of_the_wrong_type_are_skipped_with_a_warning(ext, bpy, versioning, schema, tmp_path, capsys):
    pos = version_0_positions(ext)
    build_old_layout(bpy, ext, raw_material={"glass_preset": "N-SF11", "metal_preset": 2.5,
                                             "reflectance_preset": pos["reflectance_preset"]},
                     raw_light={"profile": 999})
    mat, light = save_and_open(bpy, tmp_path / "bad.blend", versioning)
    out = capsys.readouterr().err
    assert "glass_preset holds 'N-SF11'" in out and "metal_preset holds 2.5" in out
    assert "profile was entry 999" in out
    assert mat.spectral_gi.get("glass_preset") == "N-SF11" and light.spectral_gi.get("profile") == 999  # left
    assert mat.spectral_gi.reflectance_preset == "red"  # the good value is still updated
    assert bpy.context.scene.spectral_gi.get("schema_version") == schema


def test_an_unreadable_stored_version_counts_as_before_versioning(ext, bpy, versioning, schema, tmp_path, capsys):
    build_old_layout(bpy, ext, stamp="one")
    mat, _light = save_and_open(bpy, tmp_path / "stamp.blend", versioning)
    assert "stored settings version 'one' is not a version number" in capsys.readouterr().err
    assert mat.spectral_gi.glass_preset == "N-SF11"
    assert bpy.context.scene.spectral_gi.get("schema_version") == schema


def test_migrations_end_at_the_current_version(ext, versioning, schema):
    versions = [v for v, _what, _fn in versioning.MIGRATIONS]
    assert versions == sorted(set(versions)) and versions[-1] == schema


def test_preset_menus_store_distinct_numbers_independent_of_their_position(ext, bpy):
    enums = ext.module.addon.properties.enums
    props = bpy.types.Material.bl_rna.properties["spectral_gi"].fixed_type.bl_rna.properties
    light = bpy.types.Light.bl_rna.properties["spectral_gi"].fixed_type.bl_rna.properties
    for items in (props["glass_preset"].enum_items, props["metal_preset"].enum_items,
                  props["reflectance_preset"].enum_items, light["profile"].enum_items):
        numbers = {i.identifier: i.value for i in items}
        assert len(set(numbers.values())) == len(numbers)
        for identifier, number in numbers.items():
            if identifier in ("NONE", "FILE"):
                assert number == ("NONE", "FILE").index(identifier)
            else:
                assert number == enums.stable_number(identifier) >= enums.FIRST_STABLE
    # the number comes from the identifier alone: a menu with an entry added in front keeps the others
    shifted = enums.numbered_items([("NEW", "New", ""), ("N-BK7", "N-BK7", "")])
    assert shifted[1][3] == enums.stable_number("N-BK7")


def test_a_file_open_when_the_add_on_was_enabled_is_updated_when_saved(ext, bpy, versioning, schema, tmp_path):
    build_old_layout(bpy, ext)  # as if the old-layout file had been open before the add-on registered
    path = tmp_path / "saved.blend"
    bpy.ops.wm.save_as_mainfile(filepath=str(path), check_existing=False)
    bpy.ops.wm.read_homefile(use_empty=True)
    with without_handlers(bpy, versioning, ("load_post",)):  # what was saved, not what loading would fix
        bpy.ops.wm.open_mainfile(filepath=str(path))
    assert bpy.data.materials["Old glass"].spectral_gi.glass_preset == "N-SF11"
    assert bpy.data.lights["Old spot"].spectral_gi.profile == "PRESET_quadrant"
    assert bpy.context.scene.spectral_gi.get("schema_version") == schema


def test_the_handlers_come_and_go_with_the_add_on(ext, bpy, versioning):
    def ours():
        return [(name, h.__name__) for name in ("load_post", "save_pre") for h in getattr(bpy.app.handlers, name)
                if getattr(h, "__module__", "") == versioning.__name__]

    assert ours() == [("load_post", "load_post"), ("save_pre", "save_pre")]
    ext.module.unregister()
    try:
        assert ours() == []
    finally:
        ext.module.register()
    assert ours() == [("load_post", "load_post"), ("save_pre", "save_pre")]  # once each, not twice


def test_max_bounces_of_an_older_file_keeps_the_old_default(ext, bpy, versioning, schema, tmp_path, capsys):
    """A version 1 scene that never set Max Bounces rendered with 16; after the update it still
    does, while a scene that set it and a new scene keep theirs (the new default, 64)."""
    build_old_layout(bpy, ext, stamp=1)
    s = bpy.context.scene.spectral_gi
    assert s.get("max_bounces") is None and s.max_bounces == 64  # the new default, read from an unset value
    other = bpy.data.scenes.new("Set by hand")
    other.spectral_gi.max_bounces = 40
    other.spectral_gi["schema_version"] = 1
    save_and_open(bpy, tmp_path / "v1.blend", versioning)
    assert bpy.data.scenes["Scene"].spectral_gi.max_bounces == versioning.OLD_MAX_BOUNCES == 16
    assert bpy.data.scenes["Set by hand"].spectral_gi.max_bounces == 40
    assert "from settings version 1 to 2" in capsys.readouterr().err
    assert bpy.data.scenes.new("Fresh").spectral_gi.max_bounces == 64
    bpy.ops.wm.save_as_mainfile(filepath=str(tmp_path / "v2.blend"), check_existing=False)
    bpy.ops.wm.open_mainfile(filepath=str(tmp_path / "v2.blend"))
    assert bpy.data.scenes["Fresh"].spectral_gi.max_bounces == 64  # a current scene is not migrated
    assert bpy.data.scenes["Scene"].spectral_gi.max_bounces == 16
