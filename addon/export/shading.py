"""Blender node trees → shader programs (core/shading): the graph description the core's
compiler reads, with node groups flattened, reroutes followed and muted nodes passed through
as Blender does (an output linked internally to an input gives that input, else its own
default value), and the corner attributes a program reads computed per mesh.

A material slot (base colour, roughness, emission) gets a program when its input is driven
by something other than a constant (Value, RGB), an Image Texture the texture path reads,
or, for an emitter's colour, a Blackbody node of constant temperature (Planck's spectrum).
"""
import numpy as np

from .nodes import linked_node

# node settings the compiler reads (core/shading/compiler.py), where the node has them
PROPS = ("operation", "use_clamp", "data_type", "blend_type", "clamp_factor", "clamp_result", "factor_mode",
         "clamp_type", "interpolation_type", "clamp", "mode", "vector_type", "uv_map", "attribute_name",
         "attribute_type", "layer_name", "projection", "noise_dimensions", "noise_type", "normalize",
         "voronoi_dimensions", "distance", "feature", "wave_type", "bands_direction", "rings_direction",
         "wave_profile", "turbulence_depth", "offset_frequency", "squash_frequency", "offset", "squash",
         "gradient_type", "invert", "space")
CURVE_TABLE_SIZE = 256
CONSTANT_SOURCES = ("VALUE", "RGB")


class GraphError(Exception):
    pass


def _default(sock):
    v = getattr(sock, "default_value", 0.0)
    try:
        return tuple(float(x) for x in v)[:3]
    except TypeError:
        return float(v)


def _group_output(tree):
    outs = [n for n in tree.nodes if n.bl_idname == "NodeGroupOutput"]
    for n in outs:
        if getattr(n, "is_active_output", False):
            return n
    return outs[0] if outs else None


class GraphBuilder:
    """The flat graph description of everything upstream of some sockets."""

    def __init__(self, ctx, owner, images=None):
        self.ctx = ctx
        self.owner = owner
        self.images = images  # (ctx, owner, node, usage) -> (texture index, mean): export/material.py
        self.nodes = {}
        self.depth = 0

    def source(self, sock, path="", stack=()):
        """A constant or ("link", node key, output identifier) for input socket ``sock``."""
        self.depth += 1
        try:
            if self.depth > 256:
                raise GraphError("node tree nested too deeply")
            if not sock.is_linked:
                return _default(sock)
            link = sock.links[0]
            if not link.is_valid or getattr(link, "is_muted", False):
                return _default(sock)
            return self.output(link.from_node, link.from_socket, path, stack)
        finally:
            self.depth -= 1

    def output(self, node, out, path, stack):
        if node.bl_idname == "NodeReroute":
            return self.source(node.inputs[0], path, stack)
        if node.mute:
            for il in node.internal_links:
                if il.to_socket.identifier == out.identifier:
                    return self.source(il.from_socket, path, stack)
            return _default(out)
        if node.type == "GROUP":
            tree = node.node_tree
            gout = _group_output(tree) if tree is not None else None
            if gout is None:
                return _default(out)
            for s in gout.inputs:
                if s.identifier == out.identifier:
                    return self.source(s, f"{path}{node.name}/", stack + ((node, path),))
            return _default(out)
        if node.type == "GROUP_INPUT":
            if not stack:
                return _default(out)
            gnode, gpath = stack[-1]
            for s in gnode.inputs:
                if s.identifier == out.identifier:
                    return self.source(s, gpath, stack[:-1])
            return _default(out)
        key = path + node.name
        if key not in self.nodes:
            self.nodes[key] = None  # a placeholder against cycles
            self.nodes[key] = self.describe(node, path, stack)
        return ("link", key, out.identifier)

    def describe(self, node, path, stack):
        props = {k: getattr(node, k) for k in PROPS if hasattr(node, k)}
        props = {k: (v if isinstance(v, (bool, int, float, str)) else str(v)) for k, v in props.items()}
        t = node.type
        if t == "VALUE":
            props["value"] = float(node.outputs[0].default_value)
        elif t == "RGB":
            props["color"] = tuple(float(x) for x in node.outputs[0].default_value)[:3]
        elif t == "VALTORGB":
            ramp = node.color_ramp
            props["interpolation"] = ramp.interpolation
            props["table"] = np.array([ramp.evaluate(i / (255.0)) for i in range(256)], np.float64)
            if ramp.color_mode != "RGB":
                self.ctx.note(f"{self.owner}: '{node.name}' {ramp.color_mode} ramp interpolation evaluated by "
                              "Blender into a table")
        elif t in ("CURVE_RGB", "CURVE_FLOAT"):
            props.update(_curve_table(node, t == "CURVE_RGB"))
        elif t == "TEX_IMAGE":
            index = -1
            if self.images is not None:
                index, _ = self.images(self.ctx, self.owner, node, "colour")
            props["texture"] = index
            props["uv_map"] = ""
        inputs = {}
        for s in node.inputs:
            if not getattr(s, "enabled", True) and not s.is_linked:
                continue
            if s.type == "SHADER":
                continue
            if not s.is_linked and getattr(s, "hide_value", False):
                continue  # an implicit input (coordinates, normal): the compiler's default
            inputs[s.identifier] = self.source(s, path, stack)
        return {"type": t, "props": props, "inputs": inputs, "label": f"{self.owner}/{path}{node.name}"}


def _curve_table(node, rgb):
    """Blender's CurveMapping sampled as Cycles bakes it: over the curves' x range, each
    channel through the combined curve first (RGB Curves)."""
    mapping = node.mapping
    mapping.initialize()
    curves = mapping.curves
    lo = float(mapping.clip_min_x) if mapping.use_clip else 0.0
    hi = float(mapping.clip_max_x) if mapping.use_clip else 1.0
    pts = [p.location[0] for c in curves for p in c.points]
    if pts:
        lo, hi = min(lo, min(pts)), max(hi, max(pts))
    x = np.linspace(lo, hi, CURVE_TABLE_SIZE)
    ext = getattr(mapping, "extend", "EXTRAPOLATED") == "EXTRAPOLATED"
    if rgb:
        tab = np.array([[mapping.evaluate(curves[ch], mapping.evaluate(curves[3], v)) for ch in range(3)]
                        for v in x], np.float64)
    else:
        tab = np.array([mapping.evaluate(curves[0], v) for v in x], np.float64)
    return {"table": tab, "lo": lo, "hi": hi, "extrapolate": ext}


def needs_program(sock, kind):
    """True when input ``sock`` is driven by a node graph (not a constant or an image the
    texture path reads)."""
    if sock is None or not sock.is_linked:
        return False
    src = linked_node(sock)
    if src is None or src.type in CONSTANT_SOURCES:
        return False
    if src.type == "BLACKBODY" and kind == "emission":
        t = src.inputs.get("Temperature")
        return t is not None and t.is_linked and linked_node(t) is not None and linked_node(t).type != "VALUE"
    if src.type == "TEX_IMAGE" and kind in ("colour", "roughness"):
        vec = src.inputs.get("Vector")
        if vec is None or not vec.is_linked:
            return False
        v = linked_node(vec)
        return v is not None and not (v.type == "TEX_COORD" and vec.links[0].from_socket.name == "UV")
    return True


def compile_input(ctx, owner, node, name, kind, scale=None, weight=1.0, images=None):
    """Index into ctx.programs of the program computing input ``name`` of ``node`` as ``kind``
    ("colour", "value", "vector"; ``scale``: the name of a second input multiplied in), or None when
    the graph holds something unsupported (listed in the warning, the caller uses constants).
    ``images``: how an Image Texture node becomes a core texture (export/material.py image_texture)."""
    from ...core import UnsupportedNode as Unsupported
    from ...core import compile_shader_output as compile_output

    b = GraphBuilder(ctx, owner, images)
    try:
        src = b.source(node.inputs[name])
        sc = b.source(node.inputs[scale]) if scale is not None else None
    except GraphError as e:
        ctx.skip("shader node graphs", f"{owner}/{node.name} input '{name}': {e}")
        return None
    graph = {"nodes": b.nodes}
    try:
        prog = compile_output(graph, src, kind, name=f"{owner}/{node.name}.{name}",
                              camera=getattr(ctx, "camera_from_world", None), scale=sc,
                              weight=weight, window=getattr(ctx, "camera_window", None))
    except Unsupported as e:
        ctx.skip("shader nodes (the input's own value instead)",
                 f"{owner}/{node.name} input '{name}': '{e.node}' {e.why}")
        return None
    ctx.programs.append(prog)
    return len(ctx.programs) - 1


def compile_mixed_emission(ctx, owner, node, rgb_a, rgb_b, weight=1.0, images=None):
    """Index into ctx.programs of the emission (1 − f)·rgb_a + f·rgb_b of a Mix Shader ``node``
    whose Factor f (clamped to [0, 1]) a node graph drives, times ``weight``; None when the
    graph holds something unsupported (listed in the warning)."""
    from ...core import UnsupportedNode as Unsupported
    from ...core import compile_shader_output as compile_output

    b = GraphBuilder(ctx, owner, images)
    try:
        fac = b.source(node.inputs["Factor"])
    except GraphError as e:
        ctx.skip("shader node graphs", f"{owner}/{node.name} input 'Factor': {e}")
        return None
    key = f"{owner}/{node.name} emission"
    b.nodes[key] = {"type": "MIX", "props": {"data_type": "RGBA", "blend_type": "MIX", "clamp_factor": True},
                    "inputs": {"Factor_Float": fac, "A_Color": tuple(rgb_a), "B_Color": tuple(rgb_b)}, "label": key}
    try:
        prog = compile_output({"nodes": b.nodes}, ("link", key, "Result_Color"), "colour", name=key,
                              camera=getattr(ctx, "camera_from_world", None), weight=weight,
                              window=getattr(ctx, "camera_window", None))
    except Unsupported as e:
        ctx.skip("shader nodes (the input's own value instead)",
                 f"{owner}/{node.name} input 'Factor': '{e.node}' {e.why}")
        return None
    ctx.programs.append(prog)
    return len(ctx.programs) - 1


# ----------------------------------------------------------------------------- mesh attributes

def program_attributes(ctx, material_indices):
    """The corner attribute names the programs of the core materials ``material_indices`` read."""
    from ...core import PROGRAM_FIELDS, reached_materials

    names = set()
    for i in reached_materials(ctx.materials, material_indices):
        m = ctx.materials[i]
        for key in PROGRAM_FIELDS:
            k = getattr(m, key, -1)
            if k >= 0:
                names.update(ctx.programs[k].attributes)
    return sorted(names)


def render_uv_layer(me):
    """The UV map Cycles renders with (the active render one, else the active one), or None."""
    layers = getattr(me, "uv_layers", None)
    if layers is None or len(layers) == 0:
        return None
    for layer in layers:
        if getattr(layer, "active_render", False):
            return layer
    return layers.active or layers[0]


def _corner_loops(me):
    n_t = len(me.loop_triangles)
    loops = np.empty(n_t * 3, dtype=np.int32)
    me.loop_triangles.foreach_get("loops", loops)
    return loops


def _domain_values(me, attr, loops, width):
    """float32 (T*3, width) of a generic attribute per triangle corner, or None."""
    n = len(attr.data)
    key = {"FLOAT": "value", "FLOAT_VECTOR": "vector", "FLOAT_COLOR": "color", "BYTE_COLOR": "color",
           "FLOAT2": "vector", "INT": "value", "BOOLEAN": "value"}.get(attr.data_type)
    if key is None or n == 0:
        return None
    w = {"value": 1, "vector": 2 if attr.data_type == "FLOAT2" else 3, "color": 4}[key]
    buf = np.empty(n * w, np.float32) if attr.data_type not in ("INT", "BOOLEAN") else None
    if buf is None:
        raw = np.empty(n, np.int32 if attr.data_type == "INT" else bool)
        attr.data.foreach_get("value", raw)
        buf = raw.astype(np.float32)
    else:
        attr.data.foreach_get(key, buf)
    vals = buf.reshape(n, w)
    if attr.domain == "CORNER":
        idx = loops
    elif attr.domain == "POINT":
        vi = np.empty(len(me.loops), np.int32)
        me.loops.foreach_get("vertex_index", vi)
        idx = vi[loops]
    elif attr.domain == "FACE":
        pi = np.empty(len(me.loop_triangles), np.int32)
        me.loop_triangles.foreach_get("polygon_index", pi)
        idx = np.repeat(pi, 3)
    else:
        return None
    out = np.zeros((loops.shape[0], 3), np.float32)
    v = vals[idx]
    if w == 1:
        out[:] = v
    else:
        out[:, :min(w, 3)] = v[:, :3]
    return out


def corner_attributes(ctx, obj, name, names):
    """{attribute name: float32 (T*3, 3)} of evaluated object ``obj`` for ``names`` (the
    corners in the order of core Mesh triangles: its loop triangles)."""
    if not names:
        return None
    try:
        me = obj.to_mesh()
    except RuntimeError:
        return None
    try:
        if me is None:
            return None
        me.calc_loop_triangles()
        loops = _corner_loops(me)
        n = loops.shape[0]
        vi = np.empty(len(me.loops), np.int32)
        me.loops.foreach_get("vertex_index", vi)
        co = np.empty(len(me.vertices) * 3, np.float32)
        me.vertices.foreach_get("co", co)
        co = co.reshape(-1, 3)[vi[loops]]
        out = {}
        for key in names:
            v = None
            if key == "@object":
                v = co
            elif key == "@generated":
                loc = np.asarray(me.texspace_location, np.float32)
                size = np.asarray(me.texspace_size, np.float32)
                size = np.where(size == 0.0, 1.0, size)
                v = (co - (loc - size)) / (2.0 * size)
            elif key == "@normal":
                nrm = np.empty(len(me.corner_normals) * 3, np.float32)
                me.corner_normals.foreach_get("vector", nrm)
                v = nrm.reshape(-1, 3)[loops]
            elif key.startswith("uv:"):
                layer = me.uv_layers.get(key[3:]) if key[3:] else render_uv_layer(me)
                if layer is not None:
                    uv = np.empty(len(layer.data) * 2, np.float32)
                    layer.data.foreach_get("uv", uv)
                    v = np.zeros((n, 3), np.float32)
                    v[:, :2] = uv.reshape(-1, 2)[loops]
            elif key.startswith("col:"):
                v = _named_attribute(me, key[4:], loops)
            if v is None:
                ctx.note(f"{name}: attribute {key.split(':', 1)[-1] or '(render UV map)'!r} not found, read as 0")
                v = np.zeros((n, 3), np.float32)
            out[key] = np.ascontiguousarray(v, np.float32)
        return out
    finally:
        obj.to_mesh_clear()


def _named_attribute(me, attr_name, loops):
    """A colour attribute, UV map or generic attribute named ``attr_name`` ("" = the active
    render colour attribute) per corner, or None."""
    cols = getattr(me, "color_attributes", None)
    if not attr_name and cols is not None:
        i = getattr(cols, "render_color_index", -1)
        if 0 <= i < len(cols):
            attr_name = cols[i].name
        elif cols.active_color is not None:
            attr_name = cols.active_color.name
    if me.uv_layers.get(attr_name) is not None:
        layer = me.uv_layers[attr_name]
        uv = np.empty(len(layer.data) * 2, np.float32)
        layer.data.foreach_get("uv", uv)
        v = np.zeros((loops.shape[0], 3), np.float32)
        v[:, :2] = uv.reshape(-1, 2)[loops]
        return v
    attr = me.attributes.get(attr_name) if attr_name else None
    if attr is None:
        return None
    return _domain_values(me, attr, loops, 3)
