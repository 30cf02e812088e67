"""blunt_3d_scene.py: the default slab for the 3D reference.

The default scene has a bevel needle and fracture-energy punctures, so `puncture fem`
runs the axisymmetric reference on it. The 3D reference (fem.geometry "3d") is the one
for blunt (flat) tips; its studies (fem_mesh_convergence.sh, fem_benchmark.sh) run it on
the same slab, elastic materials and needle radius with a flat tip and force-threshold
punctures. The default layers' viscoelastic terms are dropped (these studies are of the
elastic discretisation: each layer at its scene modulus, no relaxation) unless
--keep-viscoelastic (fem_3d_vs_axisymmetric.py's Prony case).

Usage: blunt_3d_scene.py SRC.json DST.json [--keep-viscoelastic]
"""
import json
import sys


def main(src, dst, keep_viscoelastic=False):
    s = json.load(open(src))
    s["name"] = s.get("name", "default") + "_blunt_3d"
    s["needle"]["tip"] = "blunt"
    s["fem"]["geometry"] = "3d"
    for layer in s["layers"]:
        # Indentation studies switch punctures off; a full run breaks a layer at this force.
        layer["puncture"] = {"criterion": "critical_force", "critical_force_N": 2.0,
                             "source": "force threshold of the 3D studies (the flat tip cannot cut)"}
        if not keep_viscoelastic:
            layer["material"].pop("viscoelastic", None)
    with open(dst, "w") as f:
        json.dump(s, f, indent=1)


if __name__ == "__main__":
    if len(sys.argv) not in (3, 4) or (len(sys.argv) == 4 and sys.argv[3] != "--keep-viscoelastic"):
        sys.exit("usage: blunt_3d_scene.py SRC.json DST.json [--keep-viscoelastic]")
    main(sys.argv[1], sys.argv[2], keep_viscoelastic=len(sys.argv) == 4)
