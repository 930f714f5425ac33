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
        else:
            ctx.note(f"{owner}: '{node.name}' input '{sock.name}' is driven by '{src.name}', "
                     f"used its unlinked value")
    if kind == "colour":
        return rgb_of(value)
    return float(value)
