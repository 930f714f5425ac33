"""Reading Blender shader node trees: the active output, what feeds a socket, input values."""

RENDER_TARGETS = ("ALL", "CYCLES")


def active_output(tree, idname):
    """The output node Cycles would use (active, targeting All or Cycles), or None."""
    if tree is None:
        return None
    outputs = [n for n in tree.nodes if n.bl_idname == idname]
    for n in outputs:
        if getattr(n, "is_active_output", False) and getattr(n, "target", "ALL") in RENDER_TARGETS:
            return n
    for n in outputs:
        if getattr(n, "target", "ALL") in RENDER_TARGETS:
            return n
    return outputs[0] if outputs else None


def linked_node(socket):
    """The node feeding ``socket`` (through reroutes), or None when it is not linked."""
    seen = 0
    while socket is not None and socket.is_linked and seen < 64:
        link = socket.links[0]
        if not link.is_valid or getattr(link, "is_muted", False):
            return None
        node = link.from_node
        if node.bl_idname == "NodeReroute":
            socket = node.inputs[0]
            seen += 1
            continue
        return node
    return None


def surface_node(output, input_name="Surface"):
    sock = output.inputs.get(input_name) if output is not None else None
    return linked_node(sock) if sock is not None else None


def input_value(ctx, owner, node, names, kind):
    """The value of the first input of ``node`` named in ``names``.

    ``kind`` is "colour" (returns an RGB tuple) or "value" (returns a float). A linked
    input is replaced by the value of a constant RGB/Value node feeding it, or else by
    the socket's own unlinked value; the substitution is noted in the export warning.
    Returns None when the node has no such input.
    """
    from .convert import rgb_of

    sock = None
    for name in names:
        sock = node.inputs.get(name)
        if sock is not None:
            break
    if sock is None:
        return None
    value = sock.default_value
    src = linked_node(sock) if sock.is_linked else None
    if src is not None:
        if kind == "colour" and src.type == "RGB":
            value = src.outputs[0].default_value
        elif kind == "value" and src.type == "VALUE":
            value = src.outputs[0].default_value
        elif kind == "colour" and src.type == "BLACKBODY":
            return blackbody_colour(ctx, owner, src)
        else:
            ctx.note(f"{owner}: '{node.name}' input '{sock.name}' is driven by '{src.name}', "
                     f"used its unlinked value")
    if kind == "colour":
        return rgb_of(value)
    return float(value)


BLACKBODY_FIT_K = (800.0, 12000.0)  # Cycles' Blackbody node holds its colour outside this range


class BlackbodyColour(tuple):
    """A Blackbody node's colour (an RGB tuple) that remembers its ``temperature`` (K), so that an
    emitter it feeds gets Planck's spectrum instead of the colour's uplift."""

    temperature = None


def blackbody_colour(ctx, owner, node):
    """The Blackbody node's output as Cycles gives it: Planck's spectrum as linear Rec.709 with
    luminance 1 (out-of-gamut channels clipped), the temperature held to [800, 12000] K."""
    from ...core import emission_to_rgb, light_emission_coeffs

    t = constant_input(ctx, owner, node, "Temperature", 1500.0)
    lo, hi = BLACKBODY_FIT_K
    if not lo <= t <= hi:
        ctx.note(f"{owner}: '{node.name}' temperature {t:g} K held to [{lo:g}, {hi:g}] K, as Cycles does")
        t = min(max(t, lo), hi)
    rgb = emission_to_rgb(light_emission_coeffs("blackbody", temperature=t, n_coeffs=ctx.n_coeffs), 0.0)[0]
    colour = BlackbodyColour(float(c) for c in rgb)
    colour.temperature = float(t)
    return colour


def shader_inputs(node):
    """The nodes feeding a Mix/Add Shader's two shader inputs, in order (None for an unlinked one)."""
    socks = [s for s in node.inputs if s.type == "SHADER"]
    return [linked_node(s) for s in socks[:2]] + [None] * (2 - len(socks[:2]))


def constant_input(ctx, owner, node, name, fallback):
    """A value input used only as a constant: its own value, or a Value node's; anything else
    driving it is noted in the warning and ``fallback`` is used. None if there is no such input."""
    sock = node.inputs.get(name)
    if sock is None:
        return None
    if not sock.is_linked:
        return float(sock.default_value)
    src = linked_node(sock)
    if src is None:  # a muted or invalid link: Blender uses the socket's value
        return float(sock.default_value)
    if src.type == "VALUE":
        return float(src.outputs[0].default_value)
    ctx.note(f"{owner}: '{node.name}' input '{sock.name}' is driven by '{src.name}', used {fallback:g}")
    return float(fallback)


def ignored_links(ctx, owner, node, names):
    """Note the inputs among ``names`` that are linked (e.g. Normal, Tangent): they are ignored."""
    for name in names:
        sock = node.inputs.get(name)
        if sock is not None and sock.is_linked and linked_node(sock) is not None:
            ctx.note(f"{owner}: '{node.name}' input '{name}' ignored")
