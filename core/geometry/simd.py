"""The traversal's 4-wide vector code: four ray/triangle edge tests or four slab tests at once.

A leaf's triangles are stored in blocks of four (``bvh.py``: one row of ``tris`` per
block, each corner coordinate as four consecutive float32, one per lane). ``hit4`` runs
the watertight test of ``bvh.intersect_triangle`` on the four lanes of a block as LLVM
``<4 x double>`` operations: the same IEEE operations in the same order as the scalar
test, so each lane's distance is bit for bit the scalar test's. numba does not vectorize
this itself (its SLP vectorizer is off and a four-trip loop is fully unrolled before the
loop vectorizer runs), so the vector code is written out here as an intrinsic, compiled
into each caller and kept by numba's on-disk cache like ``prefetch``. ``hit4_nearest``
also picks the nearest lane hit, so the closest-hit traversal needs no scalar test until
its final hit. ``slab4`` does the same for the four child boxes of a BVH record, and
``f32_below`` rounds their entry distances down to float32.
"""
from llvmlite import ir
from numba.core import cgutils, types
from numba.extending import intrinsic

BLOCK = 4  # triangles per block (lanes)
BLOCK_COLS = 40  # float32 slots per block row: 9 coordinates x 4 lanes, then 4 int32 lane indices
PRIM_COL = 36  # first of the four int32 slots: the lanes' leaf-order triangle index (-1: padding)

_F32 = ir.FloatType()
_F64 = ir.DoubleType()
_V4F = ir.VectorType(_F32, BLOCK)
_V4D = ir.VectorType(_F64, BLOCK)


def _splat(builder, x):
    v = ir.Constant(_V4D, ir.Undefined)
    for k in range(BLOCK):
        v = builder.insert_element(v, x, ir.Constant(ir.IntType(32), k))
    return v


def _hit4_args_ok(tris, ints, floats):
    """The typing rule of the triangle tests: float32 blocks, integer indices, float64 ray."""
    if not isinstance(tris, types.Array) or tris.ndim != 2 or tris.dtype != types.float32:
        return False
    return all(isinstance(a, types.Integer) for a in ints) and all(a == types.float64 for a in floats)


def _hit4_lanes(context, builder, sig, args):
    """The lanes' distances and the mask of lanes hit inside the interval (see ``hit4``)."""
    aryty = sig.args[0]
    ary = context.make_array(aryty)(context, builder, args[0])
    strides = cgutils.unpack_tuple(builder, ary.strides, 2)
    idx = [context.cast(builder, args[k], sig.args[k], types.intp) for k in range(1, 5)]
    base = builder.add(builder.ptrtoint(ary.data, cgutils.intp_t), builder.mul(idx[0], strides[0]))
    lane_bytes = ir.Constant(cgutils.intp_t, 4 * BLOCK)

    def load(corner, axis):
        col = builder.add(ir.Constant(cgutils.intp_t, 3 * corner), idx[1 + axis])
        addr = builder.add(base, builder.mul(col, lane_bytes))
        v = builder.load(builder.inttoptr(addr, _V4F.as_pointer()), align=4)
        return builder.fpext(v, _V4D)

    okx_, oky_, okz_, sx_, sy_, sz_, tmin_, tmax_ = (_splat(builder, a) for a in args[5:13])
    fsub, fmul, fadd = builder.fsub, builder.fmul, builder.fadd
    sheared = []
    for corner in range(3):
        pz = fsub(load(corner, 2), okz_)
        px = fsub(fsub(load(corner, 0), okx_), fmul(sx_, pz))
        py = fsub(fsub(load(corner, 1), oky_), fmul(sy_, pz))
        sheared.append((px, py, pz))
    (ax, ay, az), (bx, by, bz), (cx, cy, cz) = sheared
    u = fsub(fmul(cx, by), fmul(cy, bx))
    v = fsub(fmul(ax, cy), fmul(ay, cx))
    w = fsub(fmul(bx, ay), fmul(by, ax))
    det = fadd(fadd(u, v), w)
    zero = ir.Constant(_V4D, [0.0] * BLOCK)
    lt, gt = (lambda a: builder.fcmp_ordered("<", a, zero)), (lambda a: builder.fcmp_ordered(">", a, zero))
    neg = builder.or_(builder.or_(lt(u), lt(v)), lt(w))
    pos = builder.or_(builder.or_(gt(u), gt(v)), gt(w))
    hit = builder.and_(builder.not_(builder.and_(neg, pos)), builder.fcmp_unordered("!=", det, zero))
    # the scalar test's t, operation for operation: sz * ((u az + v bz) + w cz) / det
    t = builder.fdiv(fmul(sz_, fadd(fadd(fmul(u, az), fmul(v, bz)), fmul(w, cz))), det)
    inside = builder.and_(builder.fcmp_ordered(">", t, tmin_), builder.fcmp_ordered("<", t, tmax_))
    return t, builder.and_(hit, inside)


@intrinsic
def hit4(typingctx, tris, blk, ukx, uky, ukz, okx, oky, okz, sx, sy, sz, tmin, tmax):
    """Which of the four triangles of block ``blk`` the ray hits in (``tmin``, ``tmax``):
    a 4-bit mask, bit k for lane k.

    ``ukx, uky, ukz`` are the ray's axes (``bvh.ray_setup``) as unsigned integers,
    ``okx ... sz`` its origin on those axes and its shear. A lane is set when its three
    edge functions do not have mixed signs, its determinant is not 0 and its distance
    t = sz (u az + v bz + w cz) / det lies in the interval: exactly the lanes for which
    the scalar test returns a hit (padding lanes are degenerate triangles, so never set).
    The distance is computed for all four lanes with one vector division (in a closed
    room a ray's line passes through the walls behind it and beyond its hit as well).
    """
    if not _hit4_args_ok(tris, (blk, ukx, uky, ukz), (okx, oky, okz, sx, sy, sz, tmin, tmax)):
        return None

    def codegen(context, builder, sig, args):
        _, mask = _hit4_lanes(context, builder, sig, args)
        return builder.zext(builder.bitcast(mask, ir.IntType(BLOCK)), ir.IntType(64))

    return types.int64(tris, blk, ukx, uky, ukz, okx, oky, okz, sx, sy, sz, tmin, tmax), codegen


@intrinsic
def hit4_nearest(typingctx, tris, blk, ukx, uky, ukz, okx, oky, okz, sx, sy, sz, tmin, tmax):
    """The nearest of the lanes ``hit4`` reports and its distance: (lane, t), the lowest
    such lane on a tie (as testing the lanes one by one in order, keeping a strictly
    nearer hit), or (-1, tmax) when no lane is hit in (``tmin``, ``tmax``). Each lane's
    distance is bit for bit the scalar test's (``bvh.intersect_lane``)."""
    if not _hit4_args_ok(tris, (blk, ukx, uky, ukz), (okx, oky, okz, sx, sy, sz, tmin, tmax)):
        return None
    ret = types.Tuple((types.int64, types.float64))

    def codegen(context, builder, sig, args):
        t, mask = _hit4_lanes(context, builder, sig, args)
        i32 = ir.IntType(32)
        tm = builder.select(mask, t, _splat(builder, args[12]))
        best = builder.extract_element(tm, ir.Constant(i32, 0))
        for k in range(1, BLOCK):
            e = builder.extract_element(tm, ir.Constant(i32, k))
            best = builder.select(builder.fcmp_ordered("<", e, best), e, best)
        first = builder.and_(mask, builder.fcmp_ordered("==", tm, _splat(builder, best)))
        bits = builder.zext(builder.bitcast(first, ir.IntType(BLOCK)), ir.IntType(64))
        i64 = ir.IntType(64)
        cttz = builder.module.declare_intrinsic("llvm.cttz", [i64, ir.IntType(1)])
        lane = builder.call(cttz, [builder.or_(bits, ir.Constant(i64, 1 << BLOCK)), ir.Constant(ir.IntType(1), 0)])
        lane = builder.select(builder.icmp_unsigned("==", bits, ir.Constant(i64, 0)), ir.Constant(i64, -1), lane)
        return context.make_tuple(builder, ret, [lane, best])

    return ret(tris, blk, ukx, uky, ukz, okx, oky, okz, sx, sy, sz, tmin, tmax), codegen


@intrinsic
def slab4(typingctx, nodes, rec, cnx, cny, cnz, cfx, cfy, cfz, ox, oy, oz, ix, iy, iz, tmax):
    """Entry distances of a ray into the four child boxes of BVH record ``rec`` (inf where
    it misses a box or enters it beyond ``tmax``), as one ``<4 x double>`` slab test.

    A record stores each box plane for its four children as four consecutive float32
    (``bvh.py``); ``cnx ... cfz`` are the first columns of the near and far planes along
    each axis, chosen once per ray from its direction's signs (``bvh._planes4``), and
    ``ix, iy, iz`` the inverse direction. Per lane: tn = max((near - o) * i over the axes,
    0), tf = min((far - o) * i over the axes, tmax), the box is entered at tn if tn <= tf.
    An absent child's box is min +inf, max -inf, which no ray enters.
    """
    if not isinstance(nodes, types.Array) or nodes.ndim != 2 or nodes.dtype != types.float32:
        return None
    ints = (rec, cnx, cny, cnz, cfx, cfy, cfz)
    if not all(isinstance(a, types.Integer) for a in ints):
        return None
    floats = (ox, oy, oz, ix, iy, iz, tmax)
    if not all(a == types.float64 for a in floats):
        return None
    ret = types.UniTuple(types.float64, BLOCK)

    def codegen(context, builder, sig, args):
        ary = context.make_array(sig.args[0])(context, builder, args[0])
        strides = cgutils.unpack_tuple(builder, ary.strides, 2)
        idx = [context.cast(builder, args[k], sig.args[k], types.intp) for k in range(1, 8)]
        base = builder.add(builder.ptrtoint(ary.data, cgutils.intp_t), builder.mul(idx[0], strides[0]))
        four = ir.Constant(cgutils.intp_t, 4)

        def load(col):
            addr = builder.add(base, builder.mul(col, four))
            return builder.fpext(builder.load(builder.inttoptr(addr, _V4F.as_pointer()), align=4), _V4D)

        o = [_splat(builder, a) for a in args[8:11]]
        inv = [_splat(builder, a) for a in args[11:14]]
        tmax_ = _splat(builder, args[14])

        def vmax(a, b):
            return builder.select(builder.fcmp_ordered(">", a, b), a, b)

        def vmin(a, b):
            return builder.select(builder.fcmp_ordered("<", a, b), a, b)

        near = [builder.fmul(builder.fsub(load(idx[1 + k]), o[k]), inv[k]) for k in range(3)]
        far = [builder.fmul(builder.fsub(load(idx[4 + k]), o[k]), inv[k]) for k in range(3)]
        zero = ir.Constant(_V4D, [0.0] * BLOCK)
        tn = vmax(vmax(near[0], near[1]), vmax(near[2], zero))
        tf = vmin(vmin(far[0], far[1]), vmin(far[2], tmax_))
        t = builder.select(builder.fcmp_ordered("<=", tn, tf), tn, ir.Constant(_V4D, [float("inf")] * BLOCK))
        vals = [builder.extract_element(t, ir.Constant(ir.IntType(32), k)) for k in range(BLOCK)]
        return context.make_tuple(builder, ret, vals)

    return ret(nodes, rec, cnx, cny, cnz, cfx, cfy, cfz, ox, oy, oz, ix, iy, iz, tmax), codegen


@intrinsic
def f32_below(typingctx, t):
    """The largest float32 not above the float64 ``t`` (t ≥ 0, or NaN): ``t`` rounded to
    float32, and when that rounded up, the float32 just below it, found by decrementing its
    bit pattern (a positive float's predecessor; +inf's is the largest finite float32).
    What ``np.nextafter`` gives, without its library call."""
    if not isinstance(t, types.Float):
        return None

    def codegen(context, builder, sig, args):
        i32 = ir.IntType(32)
        x = context.cast(builder, args[0], sig.args[0], types.float64)
        f = builder.fptrunc(x, _F32)
        up = builder.fcmp_ordered(">", builder.fpext(f, _F64), x)
        bits = builder.bitcast(f, i32)
        down = builder.bitcast(builder.sub(bits, ir.Constant(i32, 1)), _F32)
        return builder.select(up, down, f)

    return types.float32(t), codegen
