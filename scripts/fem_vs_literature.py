#!/usr/bin/env python3
"""fem_vs_literature.py: the FEM reference's numbers beside the measurements.

Reads a FEM output folder (fem_summary.json, fem_force_depth.csv, as written
by `puncture fem` or `puncture validate`) and the scene it ran, and writes a
Markdown table that puts each number a reader can compare with a measurement
beside that measurement and its source (../shared/LITERATURE.md).

Usage: scripts/fem_vs_literature.py FEM_DIR SCENE_JSON OUT_MD [RATE_JSON]
RATE_JSON: results/fem_rate/rate.json (scripts/fem_rate_study.sh), for the
speed-trend rows.
"""
import csv
import json
import os
import sys

import fem_metrics  # scripts/fem_metrics.py
import provenance  # scripts/provenance.py (the script's own folder is on sys.path)


def cavity_pressure_kPa(mu0_kPa, alpha, stretch, n=4000):
    """Pressure (kPa) that opens a cylindrical hole in an infinite incompressible
    one-term Ogden solid (initial shear modulus mu0, exponent alpha) until its
    wall's hoop stretch is `stretch`, in plane strain (lambda_theta = lambda,
    lambda_r = 1/lambda): p = int_1^stretch W'(l) / (l^2 - 1) dl with
    W'(l) = 2 mu0 / alpha (l^(alpha-1) - l^(-alpha-1)) (midpoint rule)."""
    h = (stretch - 1.0) / n
    total = 0.0
    for i in range(n):
        l = 1.0 + (i + 0.5) * h
        total += 2 * mu0_kPa / alpha * (l ** (alpha - 1) - l ** (-alpha - 1)) / (l * l - 1) * h
    return total


def drop_notes(summary, rows, layers):
    """Per punctured layer: the force drop at its puncture, and whether its
    crack was already running (cutting column above 0.1 N while the layer was
    still flagged pressed), which releases the stored energy gradually."""
    out = []
    for p in summary.get("punctures", []):
        name = p["name"]
        state = f"{name}_state"
        running = [r for r in rows if r["phase"] == "insertion" and r.get(state) == "pressed"
                   and float(r["cutting_force_N"]) > 0.1]
        drop = p["force_N"] - p.get("force_after_N", p["force_N"])
        text = (f"{name}: {p['force_N']:.2f} N at its puncture ({p['depth_mm']:.1f} mm), {p.get('force_after_N', float('nan')):.2f} N "
                f"one step later (drop {drop:.2f} N)")
        if running and float(running[0]["depth_mm"]) <= p["depth_mm"] - 1.0:
            text += (f"; its crack was already dissipating fracture energy from {float(running[0]['depth_mm']):.1f} mm "
                     f"(cutting column {float(running[0]['cutting_force_N']):.2f} N there), i.e. it grew stably with the "
                     f"tip for {p['depth_mm'] - float(running[0]['depth_mm']):.1f} mm before it opened through the "
                     "layer's top, so its stored energy was released gradually")
        out.append(text)
    if not out:
        return []
    return ["Force drops at the punctures (measured curves show a drop where a tented layer's stored energy is released "
            "at once): " + "; ".join(out) + "."]


def radial_pressure_notes(summary, rows, layers, a_mm):
    """What drives the shaft friction: the radial pressure the friction per
    unit length implies, beside the closed-form pressure that opens the bevel's
    stand-in ring crack (radius 2a/pi) to the needle radius a in each layer's law."""
    fr = fem_metrics.friction_per_mm(summary, rows)
    last = layers[-1]
    mat, fric = last.get("material", {}), last.get("shaft_friction", {})
    if not fr or mat.get("model") != "ogden" or "ogden_alpha" not in mat or "coefficient" not in fric:
        return []
    mu_c = fric["coefficient"]
    implied = fr[0] / (mu_c * 2 * 3.141592653589793 * a_mm) * 1e3  # N/mm^2 -> kPa
    stretch = 3.141592653589793 / 2  # a / (2a/pi)
    mu0 = mat["youngs_modulus_kPa"] / (2 * (1 + mat["poisson_ratio"]))
    alpha = mat["ogden_alpha"]
    g_inf = 1 - sum(t["g"] for t in mat.get("viscoelastic", {}).get("prony", []))
    p_inst = cavity_pressure_kPa(mu0, alpha, stretch)
    sens = ", ".join(f"alpha {al:g}: {cavity_pressure_kPa(mu0, al, stretch):.0f} kPa" for al in (2, 9, 15))
    return [f"What drives the shaft friction ({last['name']}, where the friction per unit length is fitted): the "
            f"radial pressure it implies is {implied:.0f} kPa (friction per mm / (coefficient {mu_c:g} x 2 pi a)). The "
            f"bevel's stand-in ring crack (radius 2a/pi) is opened to the needle radius a, a hoop stretch of pi/2; the "
            f"pressure that does this in an infinite incompressible one-term Ogden solid of the {last['name']}'s law "
            f"(mu0 {mu0:.1f} kPa, alpha {alpha:g}; plane strain, closed-form integral) is {p_inst:.0f} kPa "
            f"instantaneous and {g_inf * p_inst:.0f} kPa fully relaxed (relaxed fraction {g_inf:.2f}); with other "
            f"exponents: {sens}. So the Ogden exponent at a stretch far beyond the range it was fitted on sets the "
            "pressure (a factor of about 30 between alpha 9 and 21.4), relaxation removes part of it behind the tip, and "
            "the coefficient scales the friction linearly. The FEM's pressure is below the closed form's: the closed "
            "form opens the hole at once in plane strain in an infinite medium, where in the FEM the crack faces open "
            "over the bevel's length, relax while the tip moves on, and the tissue above and below carries part of the "
            "hoop load; the split between these was not measured."]


def read_inputs(argv):
    """Command line -> (FEM dir, scene path, output path, rate.json or None, fem_summary, scene, CSV rows)."""
    if len(argv) not in (4, 5):
        sys.exit(__doc__)
    fem_dir, scene_path, out = argv[1:4]
    rate = json.load(open(argv[4])) if len(argv) == 5 else None
    summary = json.load(open(os.path.join(fem_dir, "fem_summary.json")))
    scene = json.load(open(scene_path))
    rows = list(csv.DictReader(l for l in open(os.path.join(fem_dir, "fem_force_depth.csv")) if not l.startswith("#")))
    return fem_dir, scene_path, out, rate, summary, scene, rows


def page_header(fem_dir, scene_path, out, rate_path, rate, scene):
    """Run, scene and command -> the page's title, provenance, needle and layers, and the table's head."""
    a_mm = scene["needle"]["radius_mm"]
    layers = scene["layers"]
    L = []
    L.append("# FEM reference against measurements\n")
    rev = provenance.git_revision()
    rate_arg = f" {rate_path}" if rate else ""
    L.append(f"Command: `scripts/fem_vs_literature.py {fem_dir} {scene_path} {out}{rate_arg}` on the FEM run in `{fem_dir}` "
             f"(scene `{scene_path}`), git {rev}.  ")
    L.append(f"Machine: {provenance.machine()}.  ")
    L.append(f"Date: {provenance.utc_now()} UTC.\n")
    L.append(f"Needle: {scene['needle']['tip']} tip, {scene['needle'].get('tip_angle_deg', '')} degrees, radius "
             f"{a_mm} mm (18 G). Sample {scene['sample']['diameter_mm']} mm wide; layers "
             + ", ".join(f"{l['name']} {l['thickness_mm']} mm" for l in layers) + ".\n")
    L.append("| quantity | FEM reference | measurement / expectation | source |")
    L.append("|---|---|---|---|")
    return L


def puncture_rows(events, order):
    """Punctures by layer and their order -> the rows of the skin's puncture force and of the puncture order."""
    L = []
    skin = events.get("skin")
    L.append(f"| skin puncture force | {skin['force_N']:.2f} N at {skin['depth_mm']:.1f} mm tip depth |" if skin else
             "| skin puncture force | no puncture |")
    L[-1] += " median 1.22 N over 24 studies (range 0.5 mN-19.2 N); plausibility band for 18 G: 1-3 N | van Gerwen et al. 2012, Med. Eng. Phys. 34:665 (LITERATURE.md) |"
    L.append(f"| order of the punctures | {' -> '.join(order) if order else 'none'} | skin -> fat -> muscle | geometry |")
    return L


def cutting_force_rows(layers, events, ins, a_mm):
    """Layers, punctures and insertion rows -> per fracture-energy layer, the FEM's cutting force beside G_c x 2a."""
    L = []
    column = fem_metrics.value
    # Cutting force = G_c x cut width (2a): expected per layer, and the FEM's
    # mean cutting column while the tip is inside the layer (after its puncture).
    for i, l in enumerate(layers):
        p = l.get("puncture", {})
        if p.get("criterion") != "fracture_energy":
            continue
        gc = p["toughness_J_per_m2"]
        expected = gc * 2 * a_mm * 1e-3
        ev = events.get(l["name"])
        vals = []
        if ev:
            nxt = events.get(layers[i + 1]["name"]) if i + 1 < len(layers) else None
            hi = nxt["depth_mm"] if nxt else 1e9
            vals = [column(r, "cutting_force_N") for r in ins if ev["depth_mm"] + 0.5 <= column(r, "depth_mm") < hi]
        if vals:
            fem = f"{sum(vals) / len(vals):.2f} N (mean of {len(vals)} steps inside the layer after its puncture)"
        elif ev:
            fem = "no step inside the layer after its puncture (the next layer broke at once)"
        else:
            fem = "not punctured"
        L.append(f"| cutting force in {l['name']} | {fem} | G_c x 2a = {gc:g} J/m^2 x {2 * a_mm:g} mm = {expected:.2f} N | "
                 f"{p.get('source', '')[:100]} |")
    return L


def friction_rows(summary, rows, ins, order):
    """Summary, rows, insertion rows and puncture order -> the friction share, per unit length and at the target."""
    L = []
    column = fem_metrics.value
    # Friction share of the total at the deepest insertion point.
    if ins:
        last = ins[-1]
        tot = column(last, "force_N")
        fr = column(last, "friction_force_N")
        share = 100 * fr / tot if tot > 0 else float("nan")
        L.append(f"| friction share of the force at the target depth | {fr:.3f} of {tot:.3f} N ({share:.0f} %) | "
                 "21 % (tearing 61 %, spreading 18 %) | Barnett, Lee, Moore 2016, J. Manuf. Sci. Eng. 138:011005 |")
    # Friction per unit length of shaft: least-squares slope of the friction
    # column against depth from 1 mm below the last puncture to the target
    # depth (the shaft then slides through every punctured layer).
    if ins and order:
        fr = fem_metrics.friction_per_mm(summary, rows)
        if fr:
            slope, z0, z1, n = fr
            band = "inside" if 0.013 <= slope <= 0.080 else ("above" if slope > 0.080 else "below")
            L.append(f"| shaft friction per unit length | {slope:.3f} N/mm (slope of the friction column over "
                     f"{z0:.1f}-{z1:.1f} mm, {n} steps; {band} the measured 0.013-0.080 N/mm) | "
                     "bovine liver 0.013 N/mm sliding, 0.018 N/mm static (Karnopp fit per metre of contact); "
                     "PVC phantom 0.034 / 0.059 / 0.080 N/mm at 1 / 3 / 9 mm/s | "
                     "Okamura, Simone, O'Leary 2004, IEEE TBME 51:1707; DiMaio & Salcudean 2003 (via van Gerwen 2012) |")
        L.append(f"| friction force at the target depth | {column(ins[-1], 'friction_force_N'):.2f} N | survey of maximum "
                 "friction forces: median 1.0 N, range 0.15-2.8 N (10 papers) | van Gerwen, Dankelman, "
                 "van den Dobbelsteen 2012, Med. Eng. Phys. 34:665, Table 2 |")
    return L


def relaxation_rows(rows, layers):
    """Rows and layers -> the row of the force's relaxation in the hold (none without a hold)."""
    L = []
    relax = fem_metrics.dwell_relaxation(rows)
    if relax:
        f0, f1, hold, frac = relax
        terms = ", ".join(f"{l['name']} g_inf {1 - sum(t['g'] for t in l['material']['viscoelastic']['prony']):.2f}"
                          for l in layers if "viscoelastic" in l.get("material", {}))
        L.append(f"| relaxation in the hold at the target depth | {f0:.2f} N -> {f1:.2f} N after {hold:.1f} s: "
                 f"{frac:.2f} of the force left ({terms or 'elastic layers'}) | insertion forces relax by tens of "
                 "percent within seconds of a hold; passive muscle under a sudden indentation: long-term / short-term "
                 "shear modulus 0.07-0.14, plateau after about 20 s | Okamura 2004, Mahvash & Dupont 2010 "
                 "(LITERATURE.md); Palevski et al. 2006, J. Biomech. Eng. 128:782 |")
    return L


def speed_trend_rows(rate, layers):
    """rate.json (or None) and layers -> the puncture forces and friction at the slowest and fastest speed."""
    L = []
    if rate:
        runs = sorted(rate["runs"], key=lambda r: r["speed_mm_per_s"])
        lo, hi = runs[0], runs[-1]
        def pf(run, name):
            return next((p["force_N"] for p in run["punctures"] if p["layer"] == name), None)
        for l in layers:
            a, b = pf(lo, l["name"]), pf(hi, l["name"])
            if a and b:
                L.append(f"| {l['name']} puncture force, {lo['speed_mm_per_s']:g} -> {hi['speed_mm_per_s']:g} mm/s | "
                         f"{a:.2f} -> {b:.2f} N ({100 * (b / a - 1):+.0f} %) | cadaver skin and muscle: insensitive to "
                         "speed; porcine and lamb heart: falls with speed | Schneider, Peck & Melvin 1978; Mahvash & "
                         "Dupont 2009; Alja'afreh 2010 (results/fem_rate/README.md) |")
        a, b = lo["friction_per_mm_N"], hi["friction_per_mm_N"]
        if a and b:
            L.append(f"| shaft friction per unit length, {lo['speed_mm_per_s']:g} -> {hi['speed_mm_per_s']:g} mm/s | "
                     f"{a:.3f} -> {b:.3f} N/mm ({100 * (b / a - 1):+.0f} %) | PVC phantom 0.034 -> 0.080 N/mm at "
                     "1 -> 9 mm/s (+135 %) | DiMaio & Salcudean 2003 (via van Gerwen 2012) [2nd] |")
    return L


def withdrawal_and_energy_rows(summary, wd):
    """Summary and withdrawal rows -> the rows of the force on withdrawal and of the energy balance."""
    L = []
    column = fem_metrics.value
    if wd:
        mn = min(column(r, "force_N") for r in wd)
        mf = min(column(r, "friction_force_N") for r in wd)
        L.append(f"| force on withdrawal | min {mn:.3f} N (friction min {mf:.3f} N) | negative: friction reverses | "
                 "Okamura, Simone, O'Leary 2004, IEEE TBME 51:1707 |")
    L.append(f"| energy: needle work (insertion) / crack dissipation / stabilisation | "
             f"{summary.get('needle_work_insertion_J', float('nan')) * 1e3:.2f} / {summary.get('cohesive_dissipation_J', 0) * 1e3:.2f} / "
             f"{summary.get('stabilization_dissipation_J', 0) * 1e3:.3f} mJ | stabilisation a small share | numerical check |")
    return L


def write_page(out, L):
    """Output path and page lines -> the page written through OUT.part (no half-written page)."""
    tmp = out + ".part"
    open(tmp, "w").write("\n".join(L) + "\n")
    os.replace(tmp, out)
    print("wrote", out)


def main():
    """Command line (FEM_DIR SCENE_JSON OUT_MD [RATE_JSON]) -> the page OUT_MD."""
    fem_dir, scene_path, out, rate, summary, scene, rows = read_inputs(sys.argv)
    a_mm = scene["needle"]["radius_mm"]
    layers = scene["layers"]
    events = {p["name"]: p for p in summary.get("punctures", [])}
    order = [p["name"] for p in summary.get("punctures", [])]
    ins = [r for r in rows if r["phase"] == "insertion"]
    wd = [r for r in rows if r["phase"] == "withdrawal"]
    L = page_header(fem_dir, scene_path, out, sys.argv[4] if rate else None, rate, scene)
    L += puncture_rows(events, order)
    L += cutting_force_rows(layers, events, ins, a_mm)
    L += friction_rows(summary, rows, ins, order)
    L += relaxation_rows(rows, layers)
    L += speed_trend_rows(rate, layers)
    pressure_notes = radial_pressure_notes(summary, rows, layers, a_mm)
    pressure_notes += drop_notes(summary, rows, layers)
    L += withdrawal_and_energy_rows(summary, wd)
    L.append("")
    L.append("Notes. The cutting column is the crack's fracture energy dissipated per unit tip advance (rate-independent "
             "part of the cohesive law); while a crack runs ahead of the tip it also carries energy the tissue releases, "
             "so single steps can exceed the needle force. The skin tents deeply on the 60 mm slab before it cuts, "
             "which puts the puncture depth beyond the few millimetres of in vivo tests on skin held by the body.")
    L += [""] + pressure_notes
    write_page(out, L)


if __name__ == "__main__":
    main()
