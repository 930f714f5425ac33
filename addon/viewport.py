"""The viewport's renderer: depsgraph updates and the view → an interactive core render.

``RenderEngine.view_update`` hands each depsgraph to :meth:`ViewportRenderer.sync` and
``view_draw`` hands the region's view to :meth:`ViewportRenderer.view`; neither waits for a
render. :func:`classify` reads ``depsgraph.updates`` and says what changed, and the export
does only that again:

* the view (or, in camera view, the camera) moved: the camera is rebuilt from the region's
  matrices, nothing is exported;
* a material, light, world or render setting changed: the scene is walked again with every
  mesh's triangles taken from a :class:`~.export.MeshCache` (no ``to_mesh``); the core keeps
  its BVH, the corners being the same;
* an object moved: the same walk (its corners move, so the core builds a BVH again);
* an object's geometry changed (edit mode, modifiers): that object alone is read again.

The render itself (``core.InteractiveRender``) runs on a worker thread: coarse passes
first (pixel size 4, 2), then full resolution until the viewport's sample count. It pauses
while a final render of this add-on runs (``FINAL_RENDERS``): both share the CPU cores.
"""
import threading
from dataclasses import dataclass, field

from .export import MeshCache, export_scene
from .export.mesh import GEOMETRY_TYPES

VIEWPORT_SAMPLES_DEFAULT = 256


class _FinalRenders:
    """How many final (F12) renders of this engine are running; the viewports pause meanwhile."""

    def __init__(self):
        self._n = 0
        self._lock = threading.Lock()

    def __enter__(self):
        with self._lock:
            self._n += 1
        return self

    def __exit__(self, *exc):
        with self._lock:
            self._n -= 1
        return False

    def active(self):
        return self._n > 0


FINAL_RENDERS = _FinalRenders()


@dataclass
class Changes:
    """What a depsgraph update changed (see :func:`classify`)."""

    kinds: set = field(default_factory=set)  # of 'geometry', 'materials', 'lights', 'world', 'settings', 'camera'
    objects: set = field(default_factory=set)  # original names of objects whose mesh is read again
    meshes: set = field(default_factory=set)  # names of mesh data read again (for every object using them)

    @property
    def export(self):
        """True if the scene must be walked again (anything but the camera changed)."""
        return bool(self.kinds - {"camera"})


SETTINGS_TYPES = ("Scene", "Collection", "ViewLayer")


def classify(depsgraph):
    """The :class:`Changes` of ``depsgraph.updates`` (valid during ``view_update`` or an update handler)."""
    import bpy

    ch = Changes()
    trees = False
    for u in depsgraph.updates:
        idb = u.id
        orig = getattr(idb, "original", idb)
        name = getattr(orig, "name", "")
        if isinstance(idb, bpy.types.Object):
            kind = idb.type
            if kind == "LIGHT":
                ch.kinds.add("lights")
            elif kind == "CAMERA":
                ch.kinds.add("camera")
            elif kind in GEOMETRY_TYPES:
                if u.is_updated_geometry:
                    ch.objects.add(name)
                    ch.kinds.add("geometry")
                if u.is_updated_transform:
                    ch.kinds.add("geometry")
                if u.is_updated_shading and not (u.is_updated_geometry or u.is_updated_transform):
                    ch.kinds.add("materials")  # a material assigned or edited
            elif u.is_updated_transform or u.is_updated_geometry:
                ch.kinds.add("geometry")  # an empty that parents or instances geometry
        elif isinstance(idb, bpy.types.Light):
            ch.kinds.add("lights")
        elif isinstance(idb, bpy.types.World):
            ch.kinds.add("world")
        elif isinstance(idb, bpy.types.Camera):
            ch.kinds.add("camera")
        elif isinstance(idb, (bpy.types.Mesh, bpy.types.Curve, bpy.types.MetaBall)):
            if u.is_updated_geometry:
                ch.meshes.add(name)
                ch.kinds.add("geometry")
        elif type(idb).__name__ in SETTINGS_TYPES or isinstance(idb, (bpy.types.Scene, bpy.types.Collection)):
            ch.kinds.add("settings")
        elif isinstance(idb, bpy.types.NodeTree):
            trees = True  # a material's or the world's tree (reported with its owner), or a node group
        elif isinstance(idb, (bpy.types.Material, bpy.types.Image, bpy.types.Texture)):
            ch.kinds.add("materials")
        else:
            ch.kinds.add("settings")
    if trees and not ch.kinds & {"materials", "world"}:
        ch.kinds.add("materials")  # a node group the materials use
    return ch


def camera_key(camera):
    """A comparable summary of a core Camera (a new key: a new view)."""
    return (tuple(float(x) for x in camera.to_world.ravel()), camera.width, camera.height, camera.lens_mm,
            camera.sensor_width_mm, camera.sensor_height_mm, camera.sensor_fit, camera.shift_x, camera.shift_y,
            camera.projection, camera.ortho_scale, camera.fstop, camera.focus_distance, camera.latitude_min,
            camera.latitude_max, camera.longitude_min, camera.longitude_max, camera.fisheye_fov,
            camera.fisheye_lens_mm)


def viewport_samples(scene):
    """Samples per pixel the viewport refines to (the scene's Viewport Samples)."""
    s = getattr(scene, "spectral_gi", None)
    return max(1, int(getattr(s, "viewport_samples", VIEWPORT_SAMPLES_DEFAULT)))


class ViewportRenderer:
    """One viewport's interactive render, driven by :meth:`sync` (depsgraph) and :meth:`view` (the region).

    on_frame(frame): called on the worker thread after each image (the engine tags a redraw);
    threads: kernel threads (None: one per core); pixel_sizes: the coarse passes' pixel sizes.
    """

    def __init__(self, threads=None, on_frame=None, pixel_sizes=None, should_pause=None):
        from ..core import InteractiveRender

        kw = {} if pixel_sizes is None else {"pixel_sizes": pixel_sizes}
        pause = should_pause if should_pause is not None else FINAL_RENDERS.active
        self.session = InteractiveRender(threads=threads, on_frame=on_frame, should_pause=pause, **kw)
        self.meshes = MeshCache()
        self.exported = None  # the last core scene sent
        self.camera = None
        self._camera_key = None
        self.exports = 0  # scene walks
        self.camera_updates = 0
        self.last = None  # Changes of the last sync
        self.error = None  # the last export error (shown in the viewport's status)
        self.warning = None
        self._started = False

    # ------------------------------------------------------------------ main thread

    def sync(self, depsgraph, camera, changes=None):
        """A depsgraph update: export what changed and restart. ``camera``: the view's core Camera.

        Returns the :class:`Changes` acted on (all of them on the first call)."""
        if changes is None:
            changes = classify(depsgraph) if self.exported is not None else None
        failed = self.error is not None or self.session.error is not None
        if changes is None or (failed and not changes.export):
            changes = Changes(kinds={"geometry", "materials", "lights", "world", "settings"})
            self.meshes.forget()
            self.session.error = None  # a failed render tries again with the whole scene
        else:
            self.meshes.forget(changes.objects, changes.meshes)
        self.last = changes
        self.session.max_spp = viewport_samples(depsgraph.scene)
        if changes.export:
            try:
                result = export_scene(depsgraph, depsgraph.scene, mesh_cache=self.meshes, camera=camera)
            except Exception as exc:  # noqa: BLE001 - shown in the viewport, never raised into Blender
                self.error = f"cannot export the scene: {exc}"
                return changes
            self.error = None
            self.warning = result.warning
            self.exported = result.scene
            self.exports += 1
            self.camera, self._camera_key = camera, camera_key(camera)
            self._start()
            self.session.update(scene=result.scene)
        else:
            self.view(camera)
        return changes

    def view(self, camera):
        """The region's view: restart with ``camera`` if it differs from the last. True if it did."""
        key = camera_key(camera)
        if key == self._camera_key or self.exported is None:
            return False
        self.camera, self._camera_key = camera, key
        self.camera_updates += 1
        self._start()
        self.session.update(camera=camera)
        return True

    def frame(self):
        """The latest core Frame (or None)."""
        return self.session.frame()

    @property
    def converged(self):
        return self.session.converged

    @property
    def status(self):
        """One line for the viewport's header: samples, or the error."""
        if self.error is not None:
            return f"Spectral GI: {self.error}"
        if self.session.error is not None:
            return f"Spectral GI: render failed: {self.session.error}"
        f = self.frame()
        if f is None:
            return "Spectral GI: preparing"
        if f.pixel_size > 1:
            return f"Spectral GI: preview (pixel size {f.pixel_size})"
        return f"Spectral GI: sample {f.spp}/{self.session.max_spp}"

    def _start(self):
        if not self._started:
            self.session.start()
            self._started = True

    def stop(self, wait=0.0):
        return self.session.stop(wait=wait)
