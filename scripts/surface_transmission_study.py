#!/usr/bin/python3
"""surface_transmission_study.py: do the FEM's layer surfaces move as the
coupled_surfaces effect draws them (core/coupled_surfaces.hpp)?

Usage: surface_transmission_study.py FEM_DIR SCENE_JSON OUT_DIR

FEM_DIR is one FEM reference of the scene (out/.fem_cache/<hash>, with its
VTU frames; `puncture validate` names it in validation_metrics.json). From the
axisymmetric frames it reads the vertical displacement of every layer's top
surface and compares, at six distances from the axis:
  1. while the skin is pressed: the fat's and the muscle's tops against the
     incompressible half-space transmission of the skin's top through the
     depth between them, u_h(rho) = integral G_h(|x - y|) u(y) dA,
     G_h = 3 h^3 / (2 pi (rho^2 + h^2)^(5/2)) (computed here by plain
     quadrature in angle and radius, independently of the C++);
  2. after the skin and fat broke: the broken layers' tops against "resting on
     the layer below" (the muscle top's own displacement at the same radius)
     and against the same half-space transmission upwards (to show which rule
     the FEM follows);
  3. the muscle after its break against the load rule (reciprocity: the
     break shape scaled by the needle's load and transmitted through the depth
     the tip went on), with the FEM's own forces;
  4. the fat after its break, squeezed onto the muscle, against the same rule.
Writes OUT_DIR/README.md (tables, with the command, git revision, machine and
date). Needs numpy (Debian python3-numpy, scripts/setup.sh).
"""
import base64
import json
import os
import re
import struct
import sys
import zlib

import numpy as np

import provenance
import results_io

RADII_MM = [0.4, 2.0, 4.0, 6.26, 9.8, 15.3]


def vtu_arrays(path):
    """The DataArrays of a deal.II .vtu (binary, zlib-compressed) by name ('points' for the coordinates)."""
    text = open(path).read()
    out = {}
    for m in re.finditer(r'<DataArray([^>]*)>\s*([^<]*)</DataArray>', text, re.S):
        attrs, data = m.group(1), m.group(2).strip()
        name = re.search(r'Name="([^"]*)"', attrs)
        name = name.group(1) if name else "points"
        kind = re.search(r'type="([^"]*)"', attrs).group(1)
        comps = re.search(r'NumberOfComponents="(\d+)"', attrs)
        comps = int(comps.group(1)) if comps else 1
        blocks = struct.unpack("<I", base64.b64decode(data[:8])[:4])[0]
        header_len = ((4 * (3 + blocks) + 2) // 3) * 4
        header = base64.b64decode(data[:header_len])
        sizes = struct.unpack("<%dI" % blocks, header[12:12 + 4 * blocks])
        raw = base64.b64decode(data[header_len:])
        buf, pos = b"", 0
        for s in sizes:
            buf += zlib.decompress(raw[pos:pos + s])
            pos += s
        dtype = {"Float32": np.float32, "Float64": np.float64, "Int32": np.int32, "UInt8": np.uint8}[kind]
        a = np.frombuffer(buf, dtype=dtype)
        out[name] = a.reshape(-1, comps) if comps > 1 else a
    return out


def surface_profile(frame, depth_mm):
    """(r, deflection) in mm of the material surface that starts at depth_mm (> 0 into the tissue)."""
    a = vtu_arrays(frame)
    p = a["points"] * 1e3
    u = a["displacement_m"] * 1e3
    sel = np.abs(p[:, 1] + depth_mm) < 1e-6
    r, w = p[sel, 0], -u[sel, 1]
    order = np.argsort(r)
    r, w = r[order], w[order]
    return np.concatenate([[0.0], r]), np.concatenate([[w[0]], w])


def transmitted(r_src, u_src, rho, h, n_s=3000, n_t=720):
    """Half-space transmission of the axisymmetric profile u_src(r_src) to radius rho at depth h (mm)."""
    s = np.linspace(0.0, r_src[-1], n_s)
    u = np.interp(s, r_src, u_src)
    t = np.linspace(0.0, 2 * np.pi, n_t, endpoint=False)
    d2 = rho ** 2 + s[:, None] ** 2 - 2 * rho * s[:, None] * np.cos(t)[None, :]
    g = (3 * h ** 3 / (2 * np.pi * (d2 + h * h) ** 2.5)).mean(axis=1) * 2 * np.pi
    return np.trapz(u * g * s, s)


def row(values):
    """Numbers -> one markdown row's cells, two decimals."""
    return " | ".join(f"{v:.2f}" for v in values)


def frames_by_depth(fem_dir, ins):
    """FEM dir and the scene's insertion -> {tip depth mm: VTU frame path}, insertion frames only (first per depth)."""
    frames = re.findall(r'timestep="([^"]*)" part="0" file="([^"]*)"', open(os.path.join(fem_dir, "fem_fields.pvd")).read())
    by_depth = {}
    for t, f in frames:
        depth = round(ins["speed_mm_per_s"] * float(t) - ins["start_height_mm"], 1)
        if float(t) * ins["speed_mm_per_s"] <= ins["start_height_mm"] + ins["target_depth_mm"] + 1e-9:
            by_depth.setdefault(depth, os.path.join(fem_dir, f))
    return by_depth


def table_head(last_column=None):
    """-> the head and rule of a table of deflections at RADII_MM (with one more column if given)."""
    extra = f" {last_column} |" if last_column else ""
    return ["| depth (mm) | surface | " + " | ".join(f"r = {r} mm" for r in RADII_MM) + " |" + extra,
            "|---|---|" + "---|" * (len(RADII_MM) + (1 if last_column else 0))]


def page_head(fem_dir, scene_path, out_dir, names):
    """Command and layer names -> the page's title, provenance, what it compares, and section 1's head."""
    return ["# How the FEM's layer surfaces move together\n",
            f"Command: `scripts/surface_transmission_study.py {fem_dir} {scene_path} {out_dir}`, git "
            f"{provenance.git_revision()}, {provenance.machine()}, {provenance.utc_now()} UTC.\n",
            f"FEM reference: `{fem_dir}` (axisymmetric frames of scene `{scene_path}`). Deflections in mm, > 0 into "
            "the tissue, of each layer's top surface (the material surface at its rest depth). The half-space "
            "transmission is the kernel of core/coupled_surfaces.hpp, evaluated here by plain quadrature. The rules "
            "have no fitted parameter, but they were chosen by looking at this reference (the default slab at 10 mm/s): "
            "these tables are in sample. Out of sample, the same rules in the real-time model are judged on the "
            "held-out cases (results/validation_heldout).\n",
            f"## 1. While the {names[0]} is pressed: the surfaces below it\n"] + table_head()


def nearest_frames(by_depth, wanted, tolerance_mm=0.6):
    """Frames and the depths a table asks for (mm) -> the frame depths nearest to them, within the tolerance
    (the FEM writes a frame every few load steps, so where they fall depends on its start height and cuts)."""
    have = sorted(by_depth)
    picked = []
    for w in wanted:
        if have:
            d = min(have, key=lambda x: abs(x - w))
            if abs(d - w) <= tolerance_mm and d not in picked:
                picked.append(d)
    return tuple(picked)


def source_and_targets(by_depth, tops, names, depths, source, targets, through):
    """Frames, layer tops and names -> rows: the source layer's top, then each target's top beside its transmission."""
    lines = []
    for d in depths:
        if d not in by_depth:
            continue
        rs, us = surface_profile(by_depth[d], tops[source])
        lines.append(f"| {d:.1f} | {names[source]} top (FEM) | {row(np.interp(RADII_MM, rs, us))} |")
        for k in targets:
            rt, ut = surface_profile(by_depth[d], tops[k])
            h = abs(tops[k] - tops[source])
            lines.append(f"| {d:.1f} | {names[k]} top (FEM) | {row(np.interp(RADII_MM, rt, ut))} |")
            lines.append(f"| {d:.1f} | {names[k]} top: transmission {through} {h:.1f} mm | "
                         f"{row([transmitted(rs, us, x, h) for x in RADII_MM])} |")
    return lines


def insertion_curve(fem_dir):
    """FEM dir -> the insertion rows of fem_force_depth.csv (dicts of strings)."""
    rows = [l for l in open(os.path.join(fem_dir, "fem_force_depth.csv")) if not l.startswith("#")]
    head = rows[0].strip().split(",")
    curve = [dict(zip(head, r.strip().split(","))) for r in rows[1:]]
    return [r for r in curve if r["phase"] == "insertion"]


def break_depth(curve, name):
    """Insertion rows and a layer's name -> the tip depth (mm, 0.1) of its first punctured row, or None."""
    broke = next((r for r in curve if r.get(f"{name}_state") == "punctured"), None)
    return None if broke is None else round(float(broke["depth_mm"]), 1)


def load_rule_rows(by_depth, tops, names, force, k, zb, depths):
    """Layer k's top past its break at zb beside the load rule with the FEM's own forces -> table rows."""
    lines = []
    rb, ub = surface_profile(by_depth[zb], tops[k])
    fb = float(force[zb]["force_N"])
    for d in depths:
        if d not in by_depth or d not in force:
            continue
        r = force[d]
        tip = float(r["tip_force_N"]) + float(r["cutting_force_N"])
        shaft = float(r["friction_force_N"])
        c = d - zb
        rule_values = np.array([tip / fb * transmitted(rb, ub, x, c) + shaft / fb * transmitted(rb, ub, x, c / 2)
                                for x in RADII_MM])
        rt, ut = surface_profile(by_depth[d], tops[k])
        fem = np.interp(RADII_MM, rt, ut)
        rel = np.sqrt(np.mean((rule_values - fem) ** 2)) / np.max(np.abs(fem))
        lines.append(f"| {d:.1f} | {names[k]} top (FEM) | {row(fem)} | |")
        lines.append(f"| {d:.1f} | {names[k]} top: the load rule | {row(rule_values)} | {rel:.2f} |")
    return lines


LOAD_RULE_TEXT = ("Rule (core/coupled_surfaces.hpp): the shape at the break times (force at the tip / force at the "
                  "break) transmitted through c, plus (shaft force / force at the break) through c / 2, c = depth - "
                  "{zb:.1f} mm; the FEM's own forces (fem_force_depth.csv: the needle's whole force at the break; tip + "
                  "cutting at the tip, friction along the shaft). Relative RMSE over the six radii, of the FEM's "
                  "largest.\n")


def load_rule_sections(fem_dir, by_depth, tops, names):
    """FEM dir, frames, layer tops and names -> sections 3 and 4: broken layers held by the needle's load."""
    # 3. and 4. Broken layers held by the needle's load (reciprocity).
    curve = insertion_curve(fem_dir)
    force = {round(float(r["depth_mm"]), 1): r for r in curve}
    lines = []
    zb = break_depth(curve, names[2])
    if zb is not None and zb in by_depth:
        lines += ["", f"## 3. The {names[2]} after its break ({zb:.1f} mm): held by the needle's load\n",
                  LOAD_RULE_TEXT.format(zb=zb)] + table_head("RMSE / largest")
        lines += load_rule_rows(by_depth, tops, names, force, 2, zb,
                                nearest_frames(by_depth, (16.4, 18.4, 20.4, 24.4, 28.4)))
    zf = break_depth(curve, names[1])
    if zf is not None and zf in by_depth:
        lines += ["", f"## 4. The {names[1]} after its break ({zf:.1f} mm), squeezed between the tip and the "
                  f"{names[2]}: held by the needle's load\n",
                  f"The tip broke the {names[1]} below the {names[2]}'s rest surface; until the {names[2]} is pressed "
                  f"by the tip itself the broken {names[1]} carries the needle's load (in the real-time model: until the "
                  f"{names[2]}'s mesh has taken over the deformation it was met with). " + LOAD_RULE_TEXT.format(zb=zf)
                  ] + table_head("RMSE / largest")
        lines += load_rule_rows(by_depth, tops, names, force, 1, zf,
                                tuple(d for d in sorted(by_depth) if zf < d <= zf + 1.5))
    return lines


READING = ("Reading: below a pressed surface the half-space transmission follows the FEM through the thin skin "
           "(the fat's top) at every depth; through the thick fat onto the stiffer muscle it is right near the "
           "break (8 mm) but too large earlier, because the FEM's fat stiffens as it is squeezed (the muscle's "
           "share of the skin's centre deflection grows with the depth, the linear kernel's does not). Above a "
           "pressed surface the broken layers rest on it: within 0.1 mm of the muscle's top from r = 6 mm on, up "
           "to 0.5 mm shallower at 2-4 mm (the fat bridges), the skin deeper right at the axis (the shaft drags "
           "the hole's rim); the upward transmission is 2-4 times too small near the axis, so coupled_surfaces "
           "draws a broken surface on the layer below it, not through a kernel. The last layer after its break "
           "follows the load rule of section 3 as the tip goes deeper, and so does a broken layer squeezed onto "
           "the layer below it until that layer bears the tip (section 4).")


def main():
    """Command line (FEM_DIR SCENE_JSON OUT_DIR) -> OUT_DIR/README.md."""
    if len(sys.argv) != 4:
        sys.exit(__doc__)
    fem_dir, scene_path, out_dir = sys.argv[1:]
    scene = json.load(open(scene_path))
    tops = np.cumsum([0.0] + [l["thickness_mm"] for l in scene["layers"]])[:3]
    by_depth = frames_by_depth(fem_dir, scene["insertion"])
    names = [l["name"] for l in scene["layers"]]
    lines = page_head(fem_dir, scene_path, out_dir, names)
    lines += source_and_targets(by_depth, tops, names, nearest_frames(by_depth, (2.0, 4.0, 6.0, 8.0)), 0, (1, 2),
                                "through")
    lines += ["", f"## 2. After the {names[0]} and the {names[1]} broke: the broken surfaces over the pressed "
              f"{names[2]}\n"] + table_head()
    lines += source_and_targets(by_depth, tops, names, nearest_frames(by_depth, (11.4, 13.4, 18.4, 28.4)), 2, (1, 0),
                                "up through")
    lines += load_rule_sections(fem_dir, by_depth, tops, names)
    lines += ["", READING]
    os.makedirs(out_dir, exist_ok=True)
    results_io.write_text(os.path.join(out_dir, "README.md"), "\n".join(lines) + "\n")
    print("wrote", os.path.join(out_dir, "README.md"))


if __name__ == "__main__":
    main()
