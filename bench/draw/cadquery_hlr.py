"""`drafter draw` against OpenCascade's hidden-line removal (CadQuery's SVG export).

For each CAD model built here with CadQuery (plate, bushing, bracket, gear, six assemblies):

1. The solid is built z-up as CadQuery does, then turned so that its up is +y (drafter's world is
   y-up, as glTF's), and everything below uses these turned coordinates.
2. It is tessellated (``--tol`` mm linear deflection, ``--ang`` rad angular) and written as STL,
   baked (``drafter bake``) and drawn (``drafter draw --ortho --view AZ,EL --hidden dashed
   --json``); the time is the ``ms`` of its JSON.
3. The same direction goes to CadQuery's exporter: ``cq.exporters.export(shape, 'x.svg',
   opt={'projectionDir': d, 'showHidden': True, ...})``, timed as a whole. drafter's camera looks
   from ``d = (cos el sin az, sin el, cos el cos az)`` (``crates/drafter-scene/src/camera.rs``
   ``view_rotation``) and OpenCascade's projector's axis points to the viewer, so
   ``projectionDir = d``.
   The exporter's algorithm is run once more here (the same HLRBRep_Algo, projector, edge
   compounds and 1e-3 GCPnts_QuasiUniformDeflection) to keep the kinds of edges apart: sharp,
   smooth (Rg1, visible only, as the exporter draws) and outlines; its polylines are checked to be
   the exporter's, and its HLR alone (Update + Hide) is timed too (the best of ``--repeat`` runs,
   as every time here).
4. The two drawings are registered by a similarity: the in-plane rotation is known exactly from
   the two frames (OpenCascade's gp_Ax2(O, d) X/Y directions against drafter's right/up; each of
   the 8 rotations/flips on top of it is tried, the best kept), scale and translation from the
   bounding boxes of the visible lines, refined by trimmed least squares on nearest points.
5. Every polyline is cut into pieces of at most 0.1 px; a piece counts as near when its midpoint
   is within 0.5 px of the other set (measured against the other set resampled every 0.02 px, so
   distances are overestimated by at most 0.01 px). Reported: the share of the reference's
   visible length near ours and of ours near theirs, the same for hidden lines; and "common kinds",
   where OpenCascade's smooth (Rg1) edges, which drafter does not draw by definition (a fillet's
   tangent edges), are left out of the reference.

Usage (see bench/draw/README.md):
    bench/draw/setup.sh
    nice -n 10 target/cq-env/bin/python bench/draw/cadquery_hlr.py --out target/draw-bench
"""

import argparse
import json
import math
import os
import re
import subprocess
import sys
import time
import xml.etree.ElementTree as ET

import numpy as np
from scipy.spatial import cKDTree

import cadquery as cq
from cadquery.occ_impl.exporters import svg as cq_svg
from OCP.BRepLib import BRepLib
from OCP.HLRAlgo import HLRAlgo_Projector
from OCP.HLRBRep import HLRBRep_Algo, HLRBRep_HLRToShape
from OCP.gp import gp_Ax2, gp_Dir, gp_Pnt

# ---------------------------------------------------------------------------------------------
# Models (built z-up in CadQuery, millimetres)


def plate():
    """A plate with four holes, a boss with a bore and a chamfer, and a slot."""
    w = (
        cq.Workplane("XY")
        .box(120, 80, 10)
        .faces(">Z")
        .workplane()
        .rect(96, 56, forConstruction=True)
        .vertices()
        .hole(10)
        .faces(">Z")
        .workplane()
        .circle(18)
        .extrude(25)
        .faces(">Z")
        .edges()
        .chamfer(2)
        .faces(">Z")
        .workplane()
        .hole(16)
        .faces("<Z")
        .workplane()
        .center(-40, 0)
        .slot2D(30, 8, 90)
        .cutThruAll()
    )
    return w.val()


def bushing():
    """A flanged bushing: flange with six bolt holes, sleeve, bore, chamfers."""
    w = (
        cq.Workplane("XY")
        .circle(40)
        .extrude(10)
        .faces(">Z")
        .workplane()
        .circle(22)
        .extrude(40)
        .faces(">Z")
        .edges()
        .chamfer(2)
        .faces(">Z")
        .workplane()
        .hole(28)
        .faces("<Z")
        .workplane()
        .polarArray(31, 0, 360, 6)
        .hole(7)
    )
    return w.val()


def bracket():
    """An L bracket with an inner bend fillet, rounded corners, two holes in each leg."""
    w = (
        cq.Workplane("XZ")
        .polyline([(0, 0), (80, 0), (80, 10), (10, 10), (10, 60), (0, 60)])
        .close()
        .extrude(50)
        .edges("|Y")
        .edges(cq.selectors.NearestToPointSelector((10, 0, 10)))
        .fillet(8)
    )
    w = w.faces("<Z").workplane(centerOption="CenterOfBoundBox").pushPoints([(15, 12), (15, -12)]).hole(8)
    w = w.faces("<X").workplane(centerOption="CenterOfBoundBox").pushPoints([(12, 8), (-12, 8)]).hole(8)
    w = w.edges("|Z").edges(">X").fillet(6)
    return w.val()


def gear():
    """A spur gear with trapezoid teeth (one flat between teeth: every edge of the profile turns by
    more than 30°), a hub, a bore and a keyway."""
    teeth, r_root, r_tip = 18, 40.0, 48.0
    pts = []
    for k in range(teeth):
        a0 = 2 * math.pi * k / teeth
        step = 2 * math.pi / teeth
        for frac, r in ((0.2, r_root), (0.36, r_tip), (0.64, r_tip), (0.8, r_root)):
            a = a0 + frac * step
            pts.append((r * math.cos(a), r * math.sin(a)))
    w = cq.Workplane("XY").polyline(pts).close().extrude(12)
    w = w.faces(">Z").workplane().circle(16).extrude(10)
    w = w.faces(">Z").workplane().hole(14)
    key = cq.Workplane("XY").center(8, 0).rect(6, 4).extrude(30).translate((0, 0, -2))
    w = w.cut(key)
    return w.val()


def pillow_assembly():
    """Three parts: a base plate, a bearing block standing on it, a shaft through the block."""
    base = cq.Workplane("XY").box(140, 70, 8).translate((0, 0, 4))
    block = (
        cq.Workplane("XY")
        .box(50, 40, 45)
        .translate((0, 0, 8 + 22.5))
        .faces(">Y")
        .workplane(centerOption="CenterOfBoundBox")
        .center(0, 5)
        .hole(24)
    )
    # One extrusion (extrude(..., both=True) would leave a circular edge between two cylindrical
    # faces in the middle, which OpenCascade draws and a mesh cannot show).
    shaft = cq.Workplane("XZ").circle(10).extrude(120).translate((0, 60, 35.5))
    return cq.Compound.makeCompound([base.val(), block.val(), shaft.val()])


def tower_assembly():
    """Three stacked parts: a square base, a cylinder post with a chamfer, a cap plate with a hole."""
    base = cq.Workplane("XY").box(80, 80, 12).translate((0, 0, 6)).edges("|Z").fillet(6)
    post = cq.Workplane("XY").circle(15).extrude(60).translate((0, 0, 12))
    cap = (
        cq.Workplane("XY")
        .box(50, 30, 8)
        .translate((10, 0, 76))
        .faces(">Z")
        .workplane(centerOption="CenterOfBoundBox")
        .center(14, 0)
        .hole(10)
    )
    return cq.Compound.makeCompound([base.val(), post.val(), cap.val()])


def flange_assembly():
    """Five parts: a square flange plate with four holes and a centre bore, and four hexagon-head
    bolts through the holes (shank 8 in a 10 hole, so the shanks touch nothing; heads on the plate)."""
    plate = (
        cq.Workplane("XY")
        .box(90, 90, 12)
        .translate((0, 0, 6))
        .faces(">Z")
        .workplane()
        .rarray(60, 60, 2, 2)
        .hole(10)
        .faces(">Z")
        .workplane()
        .hole(30)
    )
    parts = [plate.val()]
    for x in (-30, 30):
        for y in (-30, 30):
            head = cq.Workplane("XY").polygon(6, 16).extrude(6).translate((x, y, 12))
            shank = cq.Workplane("XY").circle(4).extrude(24).translate((x, y, -12))
            parts.append(head.union(shank).val())
    return cq.Compound.makeCompound(parts)


def gear_pair_assembly():
    """Five parts: a base plate, two spur gears apart from each other (teeth not in mesh), each on
    its own shaft standing in a hole of the plate (shaft 12 in the gears' 14 bores)."""
    base = cq.Workplane("XY").box(150, 80, 10).translate((20, 0, 5))
    parts = [base.val()]
    for x in (-15, 55):
        g = gear()
        parts.append(g.translate(cq.Vector(x, 0, 30)))
        parts.append(cq.Workplane("XY").circle(6).extrude(50).translate((x, 0, 10)).val())
    return cq.Compound.makeCompound(parts)


def clevis_assembly():
    """Three parts: a clevis (a block with a slot and a cross hole), a link plate in the slot (thinner
    than the slot) and a pin through both (pin 8 in 10 holes)."""
    clevis = (
        cq.Workplane("XY")
        .box(40, 30, 40)
        .translate((0, 0, 20))
        .cut(cq.Workplane("XY").box(40, 14, 30).translate((0, 0, 25)))
        .faces(">Y")
        .workplane(centerOption="CenterOfBoundBox")
        .center(0, 5)
        .hole(10)
    )
    link = (
        cq.Workplane("XZ")
        .center(20, 25)
        .rect(70, 16)
        .extrude(5)
        .translate((0, 2.5, 0))
        .faces(">Y")
        .workplane(centerOption="CenterOfBoundBox")
        .center(-15, 0)
        .hole(10)
    )
    pin = cq.Workplane("XZ").circle(4).extrude(50).translate((0, 25, 25))
    return cq.Compound.makeCompound([clevis.val(), link.val(), pin.val()])


def bushing_assembly():
    """Three parts: a mounting plate with a bore, the flanged bushing on it (its sleeve up, the
    flange on the plate, centred over the bore) and a shaft through both (shaft 24 in the
    bushing's 28 bore and the plate's 30 bore: no contact)."""
    plate = (
        cq.Workplane("XY")
        .box(120, 100, 10)
        .translate((0, 0, -5))
        .faces(">Z")
        .workplane()
        .hole(30)
    )
    shaft = cq.Workplane("XY").circle(12).extrude(90).translate((0, 0, -25))
    return cq.Compound.makeCompound([plate.val(), bushing(), shaft.val()])


MODELS = {
    "plate": (plate, (35, 30)),
    "bushing": (bushing, (20, 35)),
    "bracket": (bracket, (-40, 25)),
    "gear": (gear, (30, 50)),
    "pillow-assembly": (pillow_assembly, (35, 25)),
    "tower-assembly": (tower_assembly, (25, 20)),
    "flange-assembly": (flange_assembly, (35, 40)),
    "gear-pair-assembly": (gear_pair_assembly, (25, 35)),
    "clevis-assembly": (clevis_assembly, (40, 25)),
    "bushing-assembly": (bushing_assembly, (25, 30)),
}

# ---------------------------------------------------------------------------------------------
# Geometry helpers

# The steepest elevation drafter's camera accepts (f32, below 90): a "top" view.
STEEPEST = 89.99999


def y_up(shape):
    """CadQuery's z-up turned to y-up: (x, y, z) -> (x, z, -y), a rotation about x by -90°."""
    return shape.rotate((0, 0, 0), (1, 0, 0), -90)


def towards_eye(az, el):
    az, el = math.radians(az), math.radians(el)
    return np.array([math.cos(el) * math.sin(az), math.sin(el), math.cos(el) * math.cos(az)])


def drafter_axes(az, el):
    """drafter's screen right and up in world space (glam look_to_rh with up +y)."""
    f = -towards_eye(az, el)
    right = np.cross(f, [0.0, 1.0, 0.0])
    right /= np.linalg.norm(right)
    up = np.cross(right, f)
    return right, up


def occ_axes(d):
    ax = gp_Ax2(gp_Pnt(), gp_Dir(*d))
    x, y = ax.XDirection(), ax.YDirection()
    return np.array([x.X(), x.Y(), x.Z()]), np.array([y.X(), y.Y(), y.Z()])


# ---------------------------------------------------------------------------------------------
# OpenCascade's HLR, as CadQuery's exporter runs it, kinds kept apart


def occ_hlr(shape, d):
    t0 = time.perf_counter()
    hlr = HLRBRep_Algo()
    hlr.Add(shape.wrapped)
    hlr.Projector(HLRAlgo_Projector(gp_Ax2(gp_Pnt(), gp_Dir(*d))))
    hlr.Update()
    hlr.Hide()
    hlr_s = time.perf_counter() - t0
    h = HLRBRep_HLRToShape(hlr)
    kinds = {
        ("visible", "sharp"): h.VCompound(),
        ("visible", "smooth"): h.Rg1LineVCompound(),
        ("visible", "outline"): h.OutLineVCompound(),
        ("hidden", "sharp"): h.HCompound(),
        ("hidden", "outline"): h.OutLineHCompound(),
    }
    out = {}
    for key, comp in kinds.items():
        lines = []
        if not comp.IsNull():
            BRepLib.BuildCurves3d_s(comp, cq_svg.TOLERANCE)
            for e in cq.Shape(comp).Edges():
                text = cq_svg.makeSVGedge(e)
                pts = [tuple(map(float, m.split(","))) for m in re.findall(r"[-0-9.e+]+,[-0-9.e+]+", text)]
                if len(pts) >= 2:
                    lines.append(np.array(pts))
        out[key] = lines
    return out, hlr_s


def exporter_paths(path):
    """The exporter's own polylines (model units, before its transform): hidden, visible."""
    root = ET.parse(path).getroot()
    ns = "{http://www.w3.org/2000/svg}"
    groups = [g for g in root.iter(ns + "g") if g.get("stroke", "").startswith("rgb")]
    res = []
    for g in groups[:2]:
        lines = []
        for p in g.iter(ns + "path"):
            pts = [tuple(map(float, m.split(","))) for m in re.findall(r"[-0-9.e+]+,[-0-9.e+]+", p.get("d"))]
            if len(pts) >= 2:
                lines.append(np.array(pts))
        res.append(lines)
    return res  # [hidden, visible]


# ---------------------------------------------------------------------------------------------
# drafter's drawing


def drafter_paths(path):
    root = ET.parse(path).getroot()
    ns = "{http://www.w3.org/2000/svg}"
    out = {"visible": {}, "hidden": {}}
    for top in root.findall(ns + "g"):
        vis = top.get("id")
        for cls in top.findall(ns + "g"):
            for p in cls.findall(ns + "path"):
                nums = [float(v) for v in re.findall(r"-?[0-9.]+(?:e-?[0-9]+)?", p.get("d"))]
                pts = np.array(nums).reshape(-1, 2)
                out[vis].setdefault(cls.get("class"), []).append(pts)
    return out


# ---------------------------------------------------------------------------------------------
# Comparison


def _cut(pl, step, offset):
    """Points at `offset` (0: start, 0.5: middle) of each piece of a polyline cut into pieces of at
    most `step`, and the pieces' lengths."""
    a, b = pl[:-1], pl[1:]
    seg = np.linalg.norm(b - a, axis=1)
    n = np.maximum(1, np.ceil(seg / step)).astype(int)
    idx = np.repeat(np.arange(len(seg)), n)
    k = np.concatenate([np.arange(m) for m in n]) if len(n) else np.zeros(0)
    t = (k + offset) / n[idx]
    return a[idx] + (b[idx] - a[idx]) * t[:, None], seg[idx] / n[idx]


def pieces(lines, step):
    """Midpoints and lengths of every polyline cut into pieces of at most `step`."""
    cut = [_cut(pl, step, 0.5) for pl in lines]
    if not cut:
        return np.zeros((0, 2)), np.zeros(0)
    return np.concatenate([m for m, _ in cut]), np.concatenate([l for _, l in cut])


def samples(lines, step):
    """Every polyline's points at most `step` apart, its last point included."""
    pts = []
    for pl in lines:
        pts.append(_cut(pl, step, 0.0)[0])
        pts.append(pl[-1:])
    return np.concatenate(pts) if pts else np.zeros((0, 2))


class Target:
    """A line set resampled every 0.02 px, for nearest-distance queries."""

    def __init__(self, lines):
        pts = samples(lines, 0.02)
        self.tree = cKDTree(pts) if len(pts) else None

    def dist(self, q):
        if self.tree is None:
            return np.full(len(q), np.inf)
        return self.tree.query(q, k=1, distance_upper_bound=50.0)[0]


def share_near(src_lines, target, tol=0.5):
    """Share of the length of `src_lines` within `tol` of `target` (pieces of <= 0.1 px)."""
    mids, lens = pieces(src_lines, 0.1)
    total = lens.sum()
    if total == 0:
        return None, 0.0
    d = target.dist(mids)
    return float(lens[d <= tol].sum() / total), float(total)


def transform(lines, m, s, t):
    return [(pl @ m.T) * s + t for pl in lines]


def bbox(lines):
    allp = np.concatenate(lines)
    return allp.min(axis=0), allp.max(axis=0)


def register(ref_vis, ours_vis, m0):
    """Similarity taking the reference's (model units) into drafter's pixels: rotation/flip `m`,
    scale `s`, translation `t`. Tries the 8 rotations/flips on top of the analytic `m0`."""
    ours_target = Target(ours_vis)
    lo_o, hi_o = bbox(ours_vis)
    best = None
    for rot in range(4):
        c, sn = [(1, 0), (0, 1), (-1, 0), (0, -1)][rot]
        r = np.array([[c, -sn], [sn, c]], float)
        for flip in (1, -1):
            m = r @ np.diag([1, flip]) @ m0
            pts = [pl @ m.T for pl in ref_vis]
            lo_r, hi_r = bbox(pts)
            s = float(np.mean((hi_o - lo_o) / (hi_r - lo_r)))
            t = (lo_o + hi_o) / 2 - s * (lo_r + hi_r) / 2
            # Trimmed least squares on nearest points: scale and translation.
            mids, _ = pieces(pts, 0.5 / s)
            for _ in range(8):
                q = mids * s + t
                dist, idx = ours_target.tree.query(q, k=1)
                keep = dist < 2.0
                if keep.sum() < 10:
                    break
                target_pts = ours_target.tree.data[idx[keep]]
                src = mids[keep]
                a = np.c_[src.reshape(-1), np.tile([[1, 0], [0, 1]], (len(src), 1))]
                sol = np.linalg.lstsq(a, target_pts.reshape(-1), rcond=None)[0]
                s, t = float(sol[0]), sol[1:3]
            score, _ = share_near(transform(ref_vis, m, s, t), ours_target)
            if best is None or score > best[0]:
                best = (score, m, s, t, (rot * 90, flip))
    return best


# ---------------------------------------------------------------------------------------------


def run(cmd, **kw):
    return subprocess.run(cmd, check=True, capture_output=True, text=True, **kw)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--drafter", default="target/release/drafter")
    ap.add_argument("--out", default="target/draw-bench")
    ap.add_argument("--size", default="1200x900")
    ap.add_argument("--tol", type=float, default=0.002, help="tessellation linear deflection, mm")
    ap.add_argument("--ang", type=float, default=0.05, help="tessellation angular deflection, rad")
    ap.add_argument("--repeat", type=int, default=3, help="timed runs of each side (the best kept)")
    ap.add_argument("--models", default=",".join(MODELS))
    ap.add_argument("--view", action="append", default=[], metavar="MODEL=AZ,EL",
                    help="draw MODEL from this view instead of its own (repeatable)")
    ap.add_argument("--views", default="own",
                    help="own (each model's view), or a list of iso,front,top: iso is the model's own view, "
                         "front elevation exactly 0, top the steepest elevation the camera accepts (89.99999)")
    ap.add_argument("--input", choices=("gltf", "stl"), default="gltf",
                    help="what drafter bakes: OpenCascade's glTF (one primitive per B-rep face, so the bake "
                         "knows the face borders) or an STL of the same tessellation (no faces)")
    ap.add_argument("--draw-arg", action="append", default=[], metavar="ARG",
                    help="one more argument for drafter draw (repeatable), e.g. --draw-arg=--smooth=thin")
    ap.add_argument("--json", default=None, help="write the figures as JSON here")
    args = ap.parse_args()
    os.makedirs(args.out, exist_ok=True)
    width, height = map(int, args.size.split("x"))
    views = {k: tuple(map(float, v.split(","))) for k, v in (o.split("=") for o in args.view)}
    rows = []
    jobs = []
    for name in args.models.split(","):
        build, own = MODELS[name]
        if args.views == "own":
            jobs.append((name, build, "own", views.get(name, own)))
        else:
            named = {"iso": own, "front": (0.0, 0.0), "top": (0.0, STEEPEST)}
            jobs.extend((name, build, v, named[v]) for v in args.views.split(","))
    baked = {}
    for name, build, view_name, (az, el) in jobs:
        raw = build()
        shape = y_up(raw)
        label = name if view_name == "own" and name not in views else f"{name}@{az:.10g},{el:.10g}"
        base = os.path.join(args.out, label)
        model = os.path.join(args.out, name)
        d = towards_eye(az, el)
        # Tessellate and bake (once per model). OpenCascade's glTF writer turns its z-up into glTF's
        # y-up with a root node rotation, so the raw shape gives the y-up world drawn here.
        if name not in baked:
            if args.input == "gltf":
                cq.Assembly().add(raw, name=name).save(model + ".in.glb", "GLTF", tolerance=args.tol,
                                                       angularTolerance=args.ang)
                run([args.drafter, "bake", "-q", model + ".in.glb", "-o", model + ".glb"])
            else:
                cq.exporters.export(shape, model + ".stl", tolerance=args.tol, angularTolerance=args.ang)
                run([args.drafter, "bake", "-q", model + ".stl", "-o", model + ".glb"])
            baked[name] = model + ".glb"
        # drafter draw, timed as its JSON says (the drawing) and as a process (load, draw, write).
        ms, wall = [], []
        for _ in range(args.repeat):
            t0 = time.perf_counter()
            r = run([args.drafter, "draw", baked[name], "-o", base + ".drafter.svg", "--ortho",
                     "--view", f"{az:.10g},{el:.10g}", "--size", args.size, "--hidden", "dashed", "--json", "-q",
                     *args.draw_arg])
            wall.append(time.perf_counter() - t0)
            info = json.loads(r.stdout)
            ms.append(info["ms"])
        # CadQuery's exporter, timed as a whole.
        ex = []
        for _ in range(args.repeat):
            t0 = time.perf_counter()
            cq.exporters.export(shape, base + ".occ.svg",
                                opt={"projectionDir": tuple(d), "showHidden": True, "showAxes": False,
                                     "width": width, "height": height})
            ex.append(time.perf_counter() - t0)
        kinds, hlr_s = occ_hlr(shape, d)
        for _ in range(args.repeat - 1):
            hlr_s = min(hlr_s, occ_hlr(shape, d)[1])
        # The replica's polylines are the exporter's.
        ex_hidden, ex_visible = exporter_paths(base + ".occ.svg")
        rep_visible = sum((kinds[("visible", k)] for k in ("sharp", "smooth", "outline")), [])
        rep_hidden = sum((kinds[("hidden", k)] for k in ("sharp", "outline")), [])
        same = (len(ex_visible) == len(rep_visible) and len(ex_hidden) == len(rep_hidden)
                and all(np.allclose(a, b, atol=1e-9) for a, b in zip(ex_visible + ex_hidden, rep_visible + rep_hidden)))
        # drafter's lines.
        ours = drafter_paths(base + ".drafter.svg")
        ours_vis = sum(ours["visible"].values(), [])
        ours_hid = sum(ours["hidden"].values(), [])
        # Register.
        right, up = drafter_axes(az, el)
        ox, oy = occ_axes(d)
        m0 = np.array([[ox @ right, oy @ right], [-(ox @ up), -(oy @ up)]])
        score, m, s, t, dihedral = register(rep_visible, ours_vis, m0)
        tr = lambda lines: transform(lines, m, s, t)
        ref_vis_all = tr(rep_visible)
        ref_vis_common = tr(kinds[("visible", "sharp")] + kinds[("visible", "outline")])
        ref_hid = tr(rep_hidden)
        t_ours_vis, t_ours_hid = Target(ours_vis), Target(ours_hid)
        t_ref_vis, t_ref_hid = Target(ref_vis_all), Target(ref_hid)
        row = {"model": os.path.basename(base), "view": [az, el], "projectionDir": [round(v, 6) for v in d],
               "triangles": info["triangles"], "scale_px_per_mm": s, "sag_px": args.tol * s,
               "dihedral": dihedral, "exporter_polylines_match": bool(same),
               "drafter_ms": min(ms), "drafter_process_ms": 1e3 * min(wall),
               "occ_export_ms": 1e3 * min(ex), "occ_hlr_ms": 1e3 * hlr_s, "view_name": view_name}
        for label, tol in (("", 0.5), ("_1px", 1.0), ("_0.25px", 0.25)):
            row["vis_ref_in_ours" + label], row["ref_vis_px"] = share_near(ref_vis_all, t_ours_vis, tol)
            row["vis_common_ref_in_ours" + label], row["ref_vis_common_px"] = share_near(ref_vis_common, t_ours_vis, tol)
            row["vis_ours_in_ref" + label], row["ours_vis_px"] = share_near(ours_vis, t_ref_vis, tol)
            row["hid_ref_in_ours" + label], row["ref_hid_px"] = share_near(ref_hid, t_ours_hid, tol)
            row["hid_ours_in_ref" + label], row["ours_hid_px"] = share_near(ours_hid, t_ref_hid, tol)
        # Hidden lines of the reference that lie under a visible line of ours are drawn as that
        # visible line (a visible piece wins over a hidden one on the same pixels): left out here.
        for label, tol in (("", 0.5), ("_1px", 1.0)):
            mids, lens = pieces(ref_hid, 0.1)
            if len(mids):
                keep = t_ours_vis.dist(mids) > tol
                near = t_ours_hid.dist(mids[keep]) <= tol
                total = float(np.sum(lens[keep]))
                row["hid_ref_in_ours_unmasked" + label] = float(np.sum(lens[keep][near])) / total if total else None
            else:
                row["hid_ref_in_ours_unmasked" + label] = None
        row["ref_smooth_px"] = share_near(tr(kinds[("visible", "smooth")]), t_ours_vis)[1] if kinds[("visible", "smooth")] else 0.0
        # Per kind of the reference: share near ours (visible and hidden), and its length.
        row["ref_by_kind"] = {f"{vis}/{kind}": share_near(tr(lines), t_ours_vis if vis == "visible" else t_ours_hid)
                              for (vis, kind), lines in kinds.items() if lines}
        # Per class of ours: share near the reference (visible and hidden).
        row["ours_by_class"] = {f"{vis}/{cls}": share_near(lines, t_ref_vis if vis == "visible" else t_ref_hid)
                                for vis in ("visible", "hidden") for cls, lines in ours[vis].items()}
        # Keep the registered reference as an SVG in drafter's pixels (red over black) to look at.
        with open(base + ".overlay.svg", "w") as f:
            f.write(f'<svg xmlns="http://www.w3.org/2000/svg" width="{width}" height="{height}" fill="none">\n')
            for lines, colour, dash in ((ours_hid, "#999", ' stroke-dasharray="3 2"'), (ours_vis, "#000", ""),
                                        (ref_hid, "#f80", ' stroke-dasharray="3 2"'), (ref_vis_all, "#e00", "")):
                f.write(f'<g stroke="{colour}" stroke-width="0.5"{dash}>\n')
                for pl in lines:
                    f.write('<path d="M' + " L".join(f"{x:.2f} {y:.2f}" for x, y in pl) + '"/>\n')
                f.write("</g>\n")
            # Pieces farther than 0.5 px from the other set, thick: reference's in blue, ours in green.
            for src, target, colour in ((ref_vis_all, t_ours_vis, "#00f"), (ref_hid, t_ours_hid, "#08f"),
                                        (ours_vis, t_ref_vis, "#0a0"), (ours_hid, t_ref_hid, "#6c6")):
                mids, _ = pieces(src, 0.1)
                far = mids[target.dist(mids) > 0.5] if len(mids) else mids
                f.write(f'<g fill="{colour}" stroke="none">\n')
                for x, y in far[::3]:
                    f.write(f'<circle cx="{x:.2f}" cy="{y:.2f}" r="1.5"/>\n')
                f.write("</g>\n")
            f.write("</svg>\n")
        rows.append(row)
        print(json.dumps(row), flush=True)
    if args.json:
        with open(args.json, "w") as f:
            json.dump(rows, f, indent=1)
    pct = lambda v: "—" if v is None else f"{100 * v:.1f}"
    print("\n| model | triangles | px/mm | visible: ref in ours (all / common) | visible: ours in ref | hidden: ref in ours | hidden: ours in ref | drafter draw ms | OCC export ms (HLR) |")
    print("|---|---:|---:|---:|---:|---:|---:|---:|---:|")
    for r in rows:
        print(f"| {r['model']} ({r['view'][0]},{r['view'][1]}) | {r['triangles']} | {r['scale_px_per_mm']:.2f} | "
              f"{pct(r['vis_ref_in_ours'])} / {pct(r['vis_common_ref_in_ours'])} | {pct(r['vis_ours_in_ref'])} | "
              f"{pct(r['hid_ref_in_ours'])} | {pct(r['hid_ours_in_ref'])} | {r['drafter_ms']:.0f} | "
              f"{r['occ_export_ms']:.0f} ({r['occ_hlr_ms']:.0f}) |")
    # The figures the drawing is held to: within 1 px, both ways, every view; speed as the median ratio of
    # OpenCascade's export (in this process) to drafter draw as a process (load, draw, write).
    def worst(key):
        values = [(r[key], r["model"]) for r in rows if r.get(key) is not None]
        return min(values) if values else (None, "")
    ratio = sorted(r["occ_export_ms"] / r["drafter_process_ms"] for r in rows)
    ratio_draw = sorted(r["occ_export_ms"] / r["drafter_ms"] for r in rows)
    print(f"\n{len(rows)} views, within 1 px, the worst view of each figure:")
    for key in ("vis_ref_in_ours_1px", "vis_ours_in_ref_1px", "hid_ref_in_ours_unmasked_1px", "hid_ours_in_ref_1px"):
        value, model = worst(key)
        print(f"  {key}: {pct(value)}% ({model})")
    if ratio:
        print(f"  OpenCascade export / drafter draw process: median {np.median(ratio):.1f}x "
              f"(min {ratio[0]:.1f}x, max {ratio[-1]:.1f}x); / drafter's drawing alone: median {np.median(ratio_draw):.1f}x")


if __name__ == "__main__":
    sys.exit(main())
