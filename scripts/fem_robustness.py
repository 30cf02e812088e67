"""fem_robustness.py: scenes drawn at random over the ranges a researcher uses,
and the checks of an FEM reference's records made from its outputs alone.

draw_scene(rng, family, index) -> dict
    A scene (the JSON of scenes/default.json with every field the draw sets
    replaced). family "full": the default slab's geometry and mesh settings,
    each layer's thickness, modulus, stiffening, Prony terms, toughness,
    cohesive strength and friction drawn over the ranges of RANGES, speed
    1-20 mm/s, target depth over the whole slab, hold 0-10 s, bevel or blunt
    tip. family "small": the same draw on a 20 mm wide slab of thin layers
    (seconds per run), for the tests.

check_run(out_dir) -> list of str
    What contradicts itself in a run's fem_force_depth.csv and
    fem_summary.json, computed from the numbers written, not from the
    solver's flags: (1) shaft friction while every layer is still intact
    (the shaft meets tissue only through a cut); (2) a large force drop during
    insertion with no layer changing state near it; (3) a layer punctured
    before the one above it, or a state going back; (4) the summary's
    punctures not those of the state columns; (5) where the curve has the
    force's parts, a cutting part below zero or above the force beyond
    friction (the parts must split the total, not swing past it). Empty:
    consistent.

The thresholds (CHECKS) are in N and mm and stated on the results page.
"""
import copy
import json
import math
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import results_io  # noqa: E402

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), ".."))

# Ranges of the draw, per layer: (low, high); log-uniform where "log".
RANGES = {
    "skin": {"thickness_mm": (0.5, 3.0), "E_kPa": (10.0, 120.0, "log"), "alpha": (4.0, 12.0),
             "Gc": (300.0, 3000.0, "log"), "sigma_kPa": (500.0, 3000.0, "log")},
    "fat": {"thickness_mm": (2.0, 20.0), "E_kPa": (1.0, 10.0, "log"), "alpha": (8.0, 25.0),
            "Gc": (50.0, 600.0, "log"), "sigma_kPa": (100.0, 1000.0, "log")},
    "muscle": {"thickness_mm": (10.0, 40.0), "E_kPa": (10.0, 80.0, "log"), "alpha": (8.0, 25.0),
               "Gc": (200.0, 3000.0, "log"), "sigma_kPa": (300.0, 2000.0, "log")},
}
SMALL_THICKNESS_MM = {"skin": (0.5, 1.5), "fat": (1.0, 4.0), "muscle": (3.0, 8.0)}
FRICTION = (0.05, 0.3)            # dynamic Coulomb coefficient; static 1-1.5x
SPEED_MM_PER_S = (1.0, 20.0, "log")
HOLD_S = (0.0, 10.0)
BLUNT_SHARE = 0.1  # a blunt tip runs the 3D reference (about 10-20 min a scene)

# The consistency checks' thresholds.
CHECKS = {
    # (1) friction with every layer intact: above both
    "intact_friction_N": 0.1, "intact_friction_share": 0.25,
    # (2) a drop of the force over at most drop_window_mm of insertion, above
    # both, with no state change within state_window_mm of it
    "drop_N": 0.2, "drop_share": 0.15, "drop_window_mm": 1.5, "state_window_mm": 1.0,
    # (5) the parts within the total, to this tolerance (the CSV's rounding)
    "parts_tolerance_N": 1e-6,
}


def uniform(rng, spec):
    lo, hi = spec[0], spec[1]
    if len(spec) > 2 and spec[2] == "log":
        return math.exp(rng.uniform(math.log(lo), math.log(hi)))
    return rng.uniform(lo, hi)


def default_scene():
    with open(os.path.join(ROOT, "scenes", "default.json")) as f:
        return json.load(f)


def prony_terms(rng):
    """0, 1 or 2 normalised Prony terms, relaxing fractions summing below 0.8."""
    n = rng.choice([0, 1, 1, 2])
    terms, left = [], 0.8
    for k in range(n):
        g = rng.uniform(0.1, 0.5) * left
        left -= g
        tau = math.exp(rng.uniform(math.log(0.1), math.log(1000.0)))
        terms.append({"g": round(g, 4), "tau_s": round(tau, 4)})
    return terms


def draw_scene(rng, family="full", index=0):
    s = default_scene()
    s["name"] = f"robustness_{family}_{index:03d}"
    s["description"] = f"FEM robustness study, family '{family}', scene {index} (scripts/fem_robustness.py)"
    for layer in s["layers"]:
        r = RANGES[layer["name"]]
        t = uniform(rng, SMALL_THICKNESS_MM[layer["name"]] if family == "small" else r["thickness_mm"])
        layer["thickness_mm"] = round(t, 3)
        m = layer["material"]
        m["youngs_modulus_kPa"] = round(uniform(rng, r["E_kPa"]), 3)
        m["ogden_alpha"] = round(uniform(rng, r["alpha"]), 3)
        terms = prony_terms(rng)
        if terms:
            m["viscoelastic"] = {"prony": terms, "modulus": rng.choice(["instantaneous", "long_term"])}
        else:
            m.pop("viscoelastic", None)
        p = layer["puncture"]
        p["toughness_J_per_m2"] = round(uniform(rng, r["Gc"]), 2)
        p["cohesive_strength_kPa"] = round(uniform(rng, r["sigma_kPa"]), 2)
        mu = rng.uniform(*FRICTION)
        layer["shaft_friction"] = {"coefficient": round(mu, 4), "static_coefficient": round(mu * rng.uniform(1.0, 1.5), 4)}
    total = sum(l["thickness_mm"] for l in s["layers"])
    ins = s["insertion"]
    ins["speed_mm_per_s"] = round(uniform(rng, SPEED_MM_PER_S), 3)
    ins["withdrawal_speed_mm_per_s"] = ins["speed_mm_per_s"]
    ins["target_depth_mm"] = round(rng.uniform(0.15, 0.9) * total, 3)
    ins["dwell_s"] = round(rng.uniform(*HOLD_S) if family == "full" else rng.uniform(0.0, 0.2), 3)
    if family == "small":
        s["sample"]["diameter_mm"] = 20.0
        ins["start_height_mm"] = 0.5
        for layer in s["layers"]:  # the real-time force mesh must fit in the sample (scene check)
            fm = layer["force_mesh"]
            fm["L_mm"] = min(fm["L_mm"], round(0.45 * s["sample"]["diameter_mm"] / (fm["w"] - 1), 3))
    if rng.random() < BLUNT_SHARE:
        blunt(s, rng)
    return s


def blunt(s, rng):
    """A flat (blunt) tip: it cannot cut, so each layer breaks at a critical
    force (drawn 0.5-5 N) or stretch (1.3-2.5), and the 3D reference runs it
    (insertion only, elastic layers: fem.geometry "3d")."""
    s["needle"]["tip"] = "blunt"
    s["fem"]["geometry"] = "3d"
    for layer in s["layers"]:
        layer["material"].pop("viscoelastic", None)
        if rng.random() < 0.5:
            layer["puncture"] = {"criterion": "critical_force", "critical_force_N": round(rng.uniform(0.5, 5.0), 3)}
        else:
            layer["puncture"] = {"criterion": "critical_stretch", "critical_stretch": round(rng.uniform(1.3, 2.5), 3)}


def read_force_depth(path):
    return results_io.read_csv_rows(path)


def check_run(out_dir, layer_names=None):
    """The contradictions in a run's outputs (see the module comment)."""
    rows = read_force_depth(os.path.join(out_dir, "fem_force_depth.csv"))
    with open(os.path.join(out_dir, "fem_summary.json")) as f:
        summary = json.load(f)
    if layer_names is None:
        layer_names = [k[:-len("_state")] for k in rows[0] if k.endswith("_state")]
    c = CHECKS
    problems = []
    order = {"untouched": 0, "pressed": 1, "punctured": 2}
    states = [[order[r[n + "_state"]] for n in layer_names] for r in rows]
    depth = [float(r["depth_mm"]) for r in rows]
    force = [float(r["force_N"]) for r in rows]
    # The 3D reference (flat punch) has no shaft friction and inserts only.
    friction = [float(r.get("friction_force_N", 0.0)) for r in rows]
    phase = [r.get("phase", "insertion") for r in rows]
    # (1) shaft friction while every layer is intact.
    for k, r in enumerate(rows):
        if any(s == 2 for s in states[k]):
            continue
        lim = max(c["intact_friction_N"], c["intact_friction_share"] * abs(force[k]))
        if abs(friction[k]) > lim:
            problems.append(f"shaft friction {friction[k]:.3g} N at {depth[k]:.3g} mm ({phase[k]}) "
                            f"while no layer is punctured (force {force[k]:.3g} N)")
            break
    # (2) an unexplained force drop during insertion: from a local maximum of
    # the force, a fall beyond the threshold within drop_window_mm, with no
    # state change between state_window_mm before the maximum and as far
    # after the depth where the fall crossed the threshold (a slow decline
    # that continues a puncture's drop starts at no new maximum).
    change_depths = [depth[k] for k in range(1, len(rows)) if states[k] != states[k - 1]]
    ins = [k for k in range(len(rows)) if phase[k] == "insertion"]
    for n, a in enumerate(ins):
        before = force[ins[n - 1]] if n > 0 else -math.inf
        after = force[ins[n + 1]] if n + 1 < len(ins) else -math.inf
        if not (force[a] >= before and force[a] > after):
            continue
        limit = max(c["drop_N"], c["drop_share"] * force[a])
        b = next((k for k in ins[n + 1:] if depth[k] - depth[a] <= c["drop_window_mm"] and force[a] - force[k] > limit),
                 None)
        if b is None:
            continue
        w = c["state_window_mm"]
        if not any(depth[a] - w <= d <= depth[b] + w for d in change_depths):
            problems.append(f"the force falls from {force[a]:.3g} N at {depth[a]:.3g} mm to {force[b]:.3g} N "
                            f"at {depth[b]:.3g} mm with no layer changing state near it")
            break
    # (3) order and irreversibility of the states.
    for k in range(1, len(rows)):
        for i in range(len(layer_names)):
            if states[k][i] < states[k - 1][i]:
                problems.append(f"{layer_names[i]} goes back from a later state at {depth[k]:.3g} mm")
            if states[k][i] == 2 and any(states[k][j] != 2 for j in range(i)):
                problems.append(f"{layer_names[i]} punctured at {depth[k]:.3g} mm before a layer above it")
        if len(problems) > 4:
            break
    # (5) the cutting part within [0, force - friction].
    if rows and "cutting_force_N" in rows[0]:
        tol = c["parts_tolerance_N"]
        for k, r in enumerate(rows):
            cut = float(r["cutting_force_N"])
            if cut < -tol or cut > max(0.0, force[k] - friction[k]) + tol:
                problems.append(f"cutting part {cut:.3g} N at {depth[k]:.3g} mm ({phase[k]}) outside "
                                f"[0, force - friction = {force[k] - friction[k]:.3g} N]")
                break
    # (4) the summary's punctures are the state columns'.
    punctured = [layer_names[i] for i in range(len(layer_names)) if states[-1][i] == 2]
    listed = [p["name"] for p in summary.get("punctures", [])]
    if sorted(punctured) != sorted(listed):
        problems.append(f"summary lists punctures {listed}, the state columns {punctured}")
    return problems


def write_scene(scene, path):
    tmp = f"{path}.{os.getpid()}.part"  # one per process: tasks of a study run side by side
    with open(tmp, "w") as f:
        json.dump(scene, f, indent=1)
    os.replace(tmp, path)
