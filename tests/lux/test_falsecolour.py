"""False colour: the shipped colour map, steps, scales, legends and iso-lux lines."""
import filecmp
import subprocess
import sys

import numpy as np
import pytest

from spectral_gi.core.io.presets import PRESETS_DIR
from spectral_gi.core.lux import falsecolour as fc
from spectral_gi.core.lux import LuxError
from spectral_gi.core.lux.grids import workplane

try:
    import matplotlib
except ImportError:  # a test dependency: its absence is a failure, not a skip
    matplotlib = None


def _need_matplotlib():
    assert matplotlib is not None, "matplotlib is a test dependency: pip install -e '.[test]'"


def test_viridis_matches_matplotlib_and_regenerates_identically(tmp_path):
    _need_matplotlib()
    cm = fc.colormap("viridis")
    assert cm.shape == (256, 3)
    np.testing.assert_array_equal(cm, np.asarray(matplotlib.colormaps["viridis"].colors))
    np.testing.assert_array_equal(cm, matplotlib.colormaps["viridis"](np.arange(256))[:, :3])
    written = fc.generate_colormap_tables(tmp_path)
    assert [p.relative_to(tmp_path).as_posix() for p in written] == ["colormaps/viridis.csv"]
    assert filecmp.cmp(written[0], PRESETS_DIR / "colormaps" / "viridis.csv", shallow=False)


def test_colormap_reader_rejects_bad_tables(tmp_path):
    f = tmp_path / "bad.csv"
    f.write_text("r,g,b\n0,0,0\n0.5,1.5,0\n")
    with pytest.raises(LuxError, match="line 3"):
        fc.read_colormap(f)
    f.write_text("red,green,blue\n0,0,0\n1,1,1\n")
    with pytest.raises(LuxError, match="header"):
        fc.read_colormap(f)
    with pytest.raises(LuxError, match="unknown colour map"):
        fc.colormap("jet")


def test_eight_steps_by_default():
    v = np.linspace(0.0, 800.0, 2001)
    rgb = fc.false_colour(v, 0.0, 800.0)
    colours = np.unique(rgb, axis=0)
    assert len(colours) == 8
    steps = fc.step_colours(8)
    cm = fc.colormap()
    np.testing.assert_array_equal(steps, cm[[16, 48, 80, 112, 143, 175, 207, 239]])  # band middles
    # band k holds [100 k, 100 (k + 1)): 99.9 is band 0, 100 band 1, 800 (the top) band 7
    np.testing.assert_array_equal(fc.false_colour([99.9, 100.0, 799.0, 800.0], 0, 800),
                                  steps[[0, 1, 7, 7]])
    # outside the range: the ends' colours; not finite: black
    np.testing.assert_array_equal(fc.false_colour([-5.0, 1e9, np.nan, np.inf], 0, 800),
                                  [steps[0], steps[7], [0, 0, 0], [0, 0, 0]])


def test_images_keep_their_shape():
    img = np.arange(12.0).reshape(3, 4)
    rgb = fc.false_colour(img, 0.0, 12.0)
    assert rgb.shape == (3, 4, 3)
    np.testing.assert_array_equal(rgb.reshape(-1, 3), fc.false_colour(img.ravel(), 0.0, 12.0))


def test_continuous_and_other_step_counts():
    v = np.linspace(0.0, 1.0, 256)
    np.testing.assert_array_equal(fc.false_colour(v, 0.0, 1.0, steps=0), fc.colormap())
    assert len(np.unique(fc.false_colour(np.linspace(0, 1, 999), 0, 1, steps=5), axis=0)) == 5
    with pytest.raises(LuxError, match="steps"):
        fc.false_colour(v, 0, 1, steps=2.5)


def test_log_scale():
    t = fc.scale_positions([1.0, 10.0, 100.0, 10000.0, 0.0], 1.0, 1e4, "log")
    np.testing.assert_allclose(t, [0.0, 0.25, 0.5, 1.0, 0.0])
    np.testing.assert_array_equal(fc.false_colour([100.0], 1.0, 1e4, steps=0, scale="log"), fc.colormap()[[128]])
    # 4 log steps over four decades: one colour per decade
    rgb = fc.false_colour([2.0, 20.0, 200.0, 2000.0], 1.0, 1e4, steps=4, scale="log")
    np.testing.assert_array_equal(rgb, fc.step_colours(4))
    with pytest.raises(LuxError, match="vmin > 0"):
        fc.false_colour([1.0], 0.0, 10.0, scale="log")
    with pytest.raises(LuxError, match="unknown scale"):
        fc.false_colour([1.0], 0.0, 10.0, scale="sqrt")


def test_legend_levels_and_automatic_range():
    np.testing.assert_allclose(fc.legend_levels(0, 800), np.arange(0, 801, 100))
    np.testing.assert_allclose(fc.legend_levels(1, 1e4, 4, "log"), [1, 10, 100, 1000, 1e4])
    assert fc.auto_range([20.0, 350.0, 500.0]) == (0.0, 500.0)
    assert fc.auto_range([-2.0, 3.0]) == (-2.0, 3.0)
    assert fc.auto_range([0.0, 5.0, 50.0], "log") == (5.0, 50.0)
    assert fc.auto_range([7.0, 7.0]) == (0.0, 7.0)
    with pytest.raises(LuxError, match="positive"):
        fc.auto_range([0.0, -1.0], "log")
    # automatic range in false_colour: the largest value is the top band
    np.testing.assert_array_equal(fc.false_colour([0.0, 500.0]), fc.step_colours(8)[[0, 7]])


def test_colour_attribute_per_point_rgba():
    w = workplane([(0, 0), (4, 0), (4, 4), (0, 4)])
    lux = np.linspace(0.0, 500.0, w.n_points)
    rgba = fc.colour_attribute(w, lux, 0.0, 500.0)
    assert rgba.shape == (w.n_points, 4) and rgba.dtype == np.float32
    np.testing.assert_array_equal(rgba[:, 3], 1.0)
    np.testing.assert_allclose(rgba[:, :3], fc.false_colour(lux, 0.0, 500.0), atol=1e-7)
    lin = fc.colour_attribute(w, lux, 0.0, 500.0, linear=True)
    np.testing.assert_allclose(fc.srgb_to_linear([0.0, 0.04045, 0.5, 1.0]), [0.0, 0.04045 / 12.92, 0.21404114, 1.0],
                               rtol=1e-7)
    np.testing.assert_allclose(lin[:, :3], fc.srgb_to_linear(rgba[:, :3]), rtol=1e-6)
    with pytest.raises(LuxError, match="expected"):
        fc.colour_attribute(w, lux[:-1])


def test_legend_ticks_are_the_band_boundaries():
    _need_matplotlib()
    fig = fc.new_figure(2, 4)
    cax = fig.add_axes((0.3, 0.1, 0.2, 0.8))
    cb = fc.draw_legend(fig, cax, 0.0, 400.0, steps=8, unit="lx")
    np.testing.assert_allclose(cb.get_ticks(), np.arange(0, 401, 50))
    assert [t.get_text() for t in cb.ax.get_yticklabels()] == ["0", "50.0", "100", "150", "200", "250", "300",
                                                               "350", "400"]
    assert cb.ax.get_ylabel() == "lx"
    cb = fc.draw_legend(fig, cax, 1.0, 1000.0, steps=3, scale="log", unit="cd/m²")
    np.testing.assert_allclose(cb.get_ticks(), [1, 10, 100, 1000])
    # the legend's colours are the lookup's
    cmap, norm = fc.mpl_colormap_and_norm(0.0, 400.0, 8)
    np.testing.assert_allclose(cmap(norm(np.array([25.0, 375.0])))[:, :3], fc.false_colour([25.0, 375.0], 0, 400))


def test_isolux_levels_and_positions():
    """A ramp E = 100 x (x the column index): the line of level L lies at x = L / 100."""
    _need_matplotlib()
    img = np.tile(100.0 * np.arange(9), (5, 1))
    fig = fc.new_figure(4, 3)
    ax = fig.add_subplot()
    levels = fc.legend_levels(0.0, 800.0)[1:-1]
    cs = fc.draw_isolux(ax, img, levels)
    np.testing.assert_allclose(cs.levels, [100, 200, 300, 400, 500, 600, 700])
    for level, segs in zip(cs.levels, cs.allsegs):
        xy = np.concatenate(segs)
        np.testing.assert_allclose(xy[:, 0], level / 100.0, atol=1e-9)
        assert xy[:, 1].min() == pytest.approx(0.0) and xy[:, 1].max() == pytest.approx(4.0)
    assert len(cs.labelTexts) >= 7 and {t.get_text() for t in cs.labelTexts} >= {"100", "400", "700"}
    # levels outside the data draw nothing; NaN cells are left out
    assert fc.draw_isolux(ax, img, [900.0, 1000.0]) is None
    img[:, 4] = np.nan
    cs = fc.draw_isolux(ax, img, [200.0])
    assert np.concatenate(cs.allsegs[0])[:, 0] == pytest.approx(2.0)


def test_false_colour_image_file(tmp_path):
    _need_matplotlib()
    y, x = np.mgrid[0:40, 0:60]
    lum = 1000.0 / (1.0 + ((x - 20) ** 2 + (y - 15) ** 2) / 50.0)
    out = tmp_path / "fc.png"
    fc.false_colour_image(lum, out, unit="cd/m²", scale="log", title="luminance")
    assert out.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n" and out.stat().st_size > 10_000
    with pytest.raises(LuxError, match=".png, .pdf or .svg"):
        fc.false_colour_image(lum, tmp_path / "fc.bmp")


def test_missing_matplotlib_names_the_extra(monkeypatch):
    monkeypatch.setitem(sys.modules, "matplotlib", None)
    with pytest.raises(ImportError, match=r"'analysis' extra"):
        fc.new_figure(1, 1)


def test_core_import_does_not_import_matplotlib():
    code = ("import sys; import spectral_gi.core.lux; "
            "from spectral_gi.core.lux import false_colour; false_colour([1.0, 2.0]); "
            "print('matplotlib' in sys.modules)")
    import os
    from pathlib import Path

    import spectral_gi

    root = str(Path(spectral_gi.__file__).parent.parent)  # the folder that holds this spectral_gi
    env = {**os.environ, "PYTHONPATH": os.pathsep.join([root, os.environ.get("PYTHONPATH", "")])}
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=300, env=env)
    assert out.returncode == 0, out.stderr[-2000:]
    assert out.stdout.strip() == "False"


def test_plan_image_of_an_l_shaped_work_plane():
    # an L: 6 × 4 m less the 3 × 2 m corner at (3..6, 2..4); a 1 m grid, no band
    floor = [(0, 0), (6, 0), (6, 2), (3, 2), (3, 4), (0, 4)]
    s = workplane(floor, band=0.0, spacing=1.0)
    assert s.grid_shape == (4, 6) and s.n_points == 18
    e = s.points[:, 0] * 100.0 + s.points[:, 1]  # lx, distinct per cell
    img = fc.plan_image(s, e, size=120, legend=False)
    assert img.shape == (80, 120, 4) and img.dtype == np.float32
    ppm = 20.0  # px per metre
    want = fc.false_colour(e)
    for (x, y, _z), c in zip(s.points, want):
        px = img[int(80 - y * ppm), int(x * ppm)]  # the cell centre (rows top-to-bottom)
        assert px[3] == 1.0
        np.testing.assert_array_equal(px[:3], c.astype(np.float32))
    assert img[10, 100, 3] == 0.0  # (5, 3.5) m: outside the L, transparent
    assert np.allclose(img[0, 30, :3], 0.2)  # the outline along y = 4 m
    with_bar = fc.plan_image(s, e, size=120)
    bar = with_bar[:, -1, :3]
    bands = fc.step_colours(fc.DEFAULT_STEPS)
    np.testing.assert_array_equal(bar[-1], bands[0].astype(np.float32))  # lowest band at the bottom
    np.testing.assert_array_equal(bar[0], bands[-1].astype(np.float32))
    np.testing.assert_array_equal(with_bar[:, :120], img)
    with pytest.raises(LuxError, match="18 lux values"):
        fc.plan_image(s, e[:-1])
    # with a 0.5 m band the plan still spans the room: the band transparent, the walls drawn
    b = workplane(floor, band=0.5, spacing=1.0)
    img = fc.plan_image(b, np.full(b.n_points, 100.0), size=120, legend=False)
    assert img.shape == (80, 120, 4)
    assert img[75, 5, 3] == 0.0 and img[40, 40, 3] == 1.0  # (0.25, 0.25) m in the band; (2, 2) m on the grid
    assert np.allclose(img[40, 0, :3], 0.2) and img[40, 0, 3] == 1.0  # the wall x = 0


def test_plan_image_of_mesh_face_points():
    from spectral_gi.core.lux.grids import mesh_face_points

    pos = np.array([[0, 0, 0], [2, 0, 0], [2, 1, 0], [0, 1, 0]], float)
    s = mesh_face_points(pos, [[0, 1, 2], [0, 2, 3]])
    img = fc.plan_image(s, [10.0, 20.0], size=64, legend=False)
    want = fc.false_colour(np.array([10.0, 20.0]))
    assert img[..., 3].max() == 1.0
    colours = {tuple(p) for p in img[img[..., 3] > 0][:, :3].tolist()}
    assert colours == {tuple(c) for c in want.astype(np.float32).tolist()}
