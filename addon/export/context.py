"""State shared by the exporters: units, cancel checks, spectra, materials, warnings."""
from .convert import rgb_of

DEFAULT_GREY = (0.8, 0.8, 0.8)


class ExportCancelled(Exception):
    """The user cancelled while the scene was being exported."""


class ExportError(Exception):
    """The scene cannot be exported (for example: no active camera)."""


class ExportContext:
    """Collects what the exporters produce and what they could not export.

    ``should_cancel`` is a callable checked between objects. Unsupported objects,
    lights and shader nodes are gathered by category and reported once, as one
    warning (see :meth:`warning`).
    """

    def __init__(self, scale_length=1.0, should_cancel=None, n_coeffs=None, uplift_cache=None):
        from ...core import IORTable, SpectrumTable, constants

        if not scale_length > 0.0:
            raise ExportError(f"the scene's unit scale must be positive, got {scale_length}")
        self.scale_length = float(scale_length)
        self.physical_layering = False  # the material being built asks for the reciprocal coated plastic
        self._should_cancel = should_cancel
        # Fourier order: coefficients per spectrum (the scene's Spectral GI setting)
        self.n_coeffs = constants.N_COEFFS_DEFAULT if n_coeffs is None else int(n_coeffs)
        if not constants.N_COEFFS_MIN <= self.n_coeffs <= constants.N_COEFFS_MAX:
            raise ExportError(f"Fourier order {self.n_coeffs}: must be in [{constants.N_COEFFS_MIN}, "
                              f"{constants.N_COEFFS_MAX}]")
        self.spectra = SpectrumTable.empty(self.n_coeffs)
        self.ior_tables = IORTable.empty()  # η(λ), κ(λ) curves of metals and glasses
        self._ior_index = {}
        self.materials = []
        self._material_index = {}
        self.media = []  # core Medium records (homogeneous volumes), see :meth:`medium`
        self._medium_index = {}
        self.textures = []  # core Texture records (image textures), see material.image_texture
        self.texture_index = {}  # (image, usage, interpolation, extension) -> (index or -1, mean)
        self.programs = []  # core shader programs (node graphs), see export/shading.py
        self._spectrum_index = {}
        # (kind, rgb, coefficients) → the fitted spectrum, kept across exports by the viewport
        self._uplift = uplift_cache if uplift_cache is not None else {}
        self.unsupported = {}  # category -> list of names
        self.notes = []  # substitutions made (linked inputs, ignored settings)
        self.material_users = {}  # material name -> names of the objects rendered with it (for the warning)

    # ----------------------------------------------------------------- cancel / warnings

    def check_cancel(self):
        if self._should_cancel is not None and self._should_cancel():
            raise ExportCancelled("export cancelled")

    def skip(self, category, name):
        """Record something that was not exported (reported once, grouped by category)."""
        names = self.unsupported.setdefault(category, [])
        if name not in names:
            names.append(name)

    def note(self, text):
        if text not in self.notes:
            self.notes.append(text)

    def material_user(self, material_name, object_name):
        """Record that object ``object_name`` renders with material ``material_name``."""
        users = self.material_users.setdefault(material_name, [])
        if object_name not in users:
            users.append(object_name)

    def warning(self):
        """One message listing everything not exported or substituted, or None; the materials it
        names are followed by the objects that use them."""
        parts = [f"{cat}: {', '.join(repr(n) for n in names)}" for cat, names in self.unsupported.items()]
        text = ""
        if parts:
            text = "Not exported — " + "; ".join(parts)
        if self.notes:
            text = (text + ". " if text else "") + "Approximated — " + "; ".join(self.notes)
        items = [n for names in self.unsupported.values() for n in names] + self.notes
        named = [(m, users) for m, users in self.material_users.items()
                 if any(str(i).startswith((f"{m}/", f"{m}:")) for i in items)]
        if named:
            text += ". Materials on objects — " + "; ".join(
                f"{m!r}: {', '.join(repr(u) for u in users)}" for m, users in named)
        return text or None

    # ----------------------------------------------------------------- spectra

    def reflectance(self, name, rgb):
        from ...core import constants, reflectance_from_rgb

        key = ("R", tuple(rgb_of(rgb)))
        if key not in self._spectrum_index:
            fit = self._uplift.get(key + (self.n_coeffs,))
            if fit is None:
                fit = self._uplift[key + (self.n_coeffs,)] = reflectance_from_rgb(key[1], self.n_coeffs)
            self._spectrum_index[key] = self.spectra.add(name, fit, constants.SPECTRUM_BOUNDED)
        return self._spectrum_index[key]

    def emission(self, name, rgb):
        from ...core import constants, emission_from_rgb

        key = ("E", tuple(rgb_of(rgb)))
        if key not in self._spectrum_index:
            fit = self._uplift.get(key + (self.n_coeffs,))
            if fit is None:
                fit = self._uplift[key + (self.n_coeffs,)] = emission_from_rgb(key[1], self.n_coeffs)
            self._spectrum_index[key] = self.spectra.add(name, fit, constants.SPECTRUM_UNBOUNDED)
        return self._spectrum_index[key]

    def spectrum_file(self, path, kind, owner):
        """Index of the spectrum read from file ``path`` ('reflectance' or 'emission'; Blender's '//'
        is relative to the .blend file), added once; None (with the problem reported under ``owner``,
        an object or material name) if the file cannot be used, so the caller substitutes its colour."""
        import os

        from ...core import SpectrumFileError, load_spectrum_file

        path = str(path or "")
        if path.startswith("//"):
            try:
                import bpy

                path = bpy.path.abspath(path)
            except ImportError:
                pass
        if not path.strip():
            self.skip("spectrum files (the colour is used instead)", f"{owner}: no file chosen")
            return None
        full = os.path.abspath(path)
        key = ("F", kind, full)
        if key not in self._spectrum_index:
            try:
                sf = load_spectrum_file(full, kind)
                coeffs = sf.coeffs(self.n_coeffs)
            except (SpectrumFileError, ValueError, OSError) as e:
                self.skip("spectrum files (the colour is used instead)", f"{owner}: {e}")
                return None
            for text in sf.notes:
                self.note(f"{owner}: {text}")
            self._spectrum_index[key] = self.spectra.add(os.path.basename(full), coeffs, sf.spectrum_kind)
        return self._spectrum_index[key]

    def emission_spectrum(self, key, name, build):
        """Index of the emission spectrum for ``key``; ``build()`` returns its coefficients the first time."""
        from ...core import constants

        key = ("E*",) + tuple(key)
        if key not in self._spectrum_index:
            self._spectrum_index[key] = self.spectra.add(name, build(), constants.SPECTRUM_UNBOUNDED)
        return self._spectrum_index[key]

    def _medium_shape(self, name, rgb):
        """(spectrum index, density) with density · shape = the coefficient colour ``rgb`` (1/m):
        -1 (flat 1) for a grey, else the bounded spectrum of rgb / max(rgb)."""
        rgb = tuple(max(float(c), 0.0) for c in rgb)
        density = max(rgb)
        if not density > 0.0:
            return -1, 0.0
        if max(rgb) - min(rgb) <= 1e-9 * density:
            return -1, density
        return self.reflectance(name, tuple(c / density for c in rgb)), density

    def medium(self, name, absorption_rgb, scattering_rgb, anisotropy=0.0):
        """Index into ``media`` of the homogeneous medium with these coefficients, added once.

        ``absorption_rgb`` and ``scattering_rgb`` are σa and σs as linear Rec.709 colours in
        1/m (any non-negative values); each becomes a density (its largest channel) times a
        bounded spectrum (the colour over that density), or a flat spectrum for a grey.
        """
        from ...core import Medium

        sa = tuple(max(float(c), 0.0) for c in rgb_of(absorption_rgb))
        ss = tuple(max(float(c), 0.0) for c in rgb_of(scattering_rgb))
        key = (sa, ss, float(anisotropy))
        if key not in self._medium_index:
            a_idx, a_den = self._medium_shape(f"{name} absorption", sa)
            s_idx, s_den = self._medium_shape(f"{name} scattering", ss)
            self._medium_index[key] = len(self.media)
            self.media.append(Medium(name=name, absorption=a_idx, absorption_density=a_den, scattering=s_idx,
                                     scattering_density=s_den, anisotropy=float(anisotropy)))
        return self._medium_index[key]

    def ior_table(self, name, values):
        """Index into ``ior_tables`` of the curve ``name`` (N_LAMBDA values on the 1 nm grid), added once."""
        if name not in self._ior_index:
            self._ior_index[name] = self.ior_tables.add(name, values)
        return self._ior_index[name]

    # ----------------------------------------------------------------- materials

    def material_index(self, key, build):
        """Index of the material for ``key``; ``build()`` returns a core Material the first time.

        ``build`` may add other materials (the components of a mix) before returning.
        """
        if key not in self._material_index:
            material = build()
            self._material_index[key] = len(self.materials)
            self.materials.append(material)
        return self._material_index[key]

    def add_material(self, material):
        """Append a component material (of a mix) and return its index."""
        self.materials.append(material)
        return len(self.materials) - 1

    def default_material(self):
        from ...core import Material

        return self.material_index(None, lambda: Material(
            name="Spectral GI default", reflectance=self.reflectance("default grey", DEFAULT_GREY)))
