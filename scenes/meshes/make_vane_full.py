"""Regenerate the meshes of the full vane of Wang et al. 2021 §5.6: a
four-bladed vane (radius r_v = 0.05 m, blades 0.1 r_v thick and 4 r_v
high, the top of the blades at ground level) in a cylinder of soil of
radius 3 r_v and height 8 r_v, under an empty layer of r_v that extends the
mesh to 9 r_v for the material that heaves. Ten-node tetrahedra (the
F-patch parents, split into eight linear children when read), MSH 4.1
ASCII. Physical groups: surfaces "vane" (every blade face), "outer" (the
cylinder, soil and empty layer), "bottom"; volumes "soil" and "air" (the
empty layer). The mesh is finest along the blades and grows away from
them.

Run from this folder with the Gmsh Python API (`pip install gmsh`, tested
with Gmsh 4.15.2):

    python3 make_vane_full.py
"""

import sys

import gmsh

RV = 0.05
THICK = 0.1 * RV
OUTER = 3 * RV
GROUND = 8 * RV
TOP = 9 * RV
VANE_BOTTOM = GROUND - 4 * RV

# name: (element size at the blades, element size far from them)
MESHES = {
    # 347,797 linear tetrahedra and 60,858 nodes in the paper; 44,121
    # parents (352,968 children) and 64,901 nodes here.
    "vane_full.msh": (1.26 * THICK, 0.7 * RV),
    # A coarse mesh for the tests and the quick reproduction: 2,698
    # parents (21,584 children).
    "vane_full_quick.msh": (4 * THICK, 2.0 * RV),
}


def build(name, fine, coarse):
    gmsh.initialize()
    gmsh.model.add("vane_full")
    gmsh.option.setNumber("General.Terminal", 0)
    gmsh.option.setNumber("Mesh.MshFileVersion", 4.1)
    gmsh.option.setNumber("Mesh.Binary", 0)
    gmsh.option.setNumber("Mesh.RandomSeed", 1)
    occ = gmsh.model.occ
    soil = occ.addCylinder(0, 0, 0, 0, 0, GROUND, OUTER)
    air = occ.addCylinder(0, 0, GROUND, 0, 0, TOP - GROUND, OUTER)
    h = GROUND - VANE_BOTTOM
    a = occ.addBox(-RV, -THICK / 2, VANE_BOTTOM, 2 * RV, THICK, h)
    b = occ.addBox(-THICK / 2, -RV, VANE_BOTTOM, THICK, 2 * RV, h)
    vane, _ = occ.fuse([(3, a)], [(3, b)])
    cut, _ = occ.cut([(3, soil)], vane)
    # Conforming interface between the soil and the empty layer.
    pieces, _ = occ.fragment(cut, [(3, air)])
    occ.synchronize()
    volumes = [t for d, t in pieces if d == 3]
    soil_v, air_v = [], []
    for t in volumes:
        z0, z1 = gmsh.model.getBoundingBox(3, t)[2], gmsh.model.getBoundingBox(3, t)[5]
        (air_v if z0 > GROUND - 1e-6 else soil_v).append(t)
    groups = {"vane": [], "outer": [], "bottom": []}
    seen = set()
    for _, tag in gmsh.model.getBoundary([(3, v) for v in volumes], oriented=False, combined=False):
        if tag in seen:
            continue
        seen.add(tag)
        x0, y0, z0, x1, y1, z1 = gmsh.model.getBoundingBox(2, tag)
        if abs(z1 - z0) < 1e-6:  # OCC pads bounding boxes by 1e-7
            if z0 < 1e-6:
                groups["bottom"].append(tag)
            elif abs(z0 - VANE_BOTTOM) < 1e-6:  # the blades' lower end
                groups["vane"].append(tag)
        elif max(abs(x0), abs(x1), abs(y0), abs(y1)) > 2 * RV:
            groups["outer"].append(tag)
        else:
            groups["vane"].append(tag)
    for group, tags in groups.items():
        gmsh.model.addPhysicalGroup(2, tags, name=group)
    gmsh.model.addPhysicalGroup(3, soil_v, name="soil")
    gmsh.model.addPhysicalGroup(3, air_v, name="air")
    distance = gmsh.model.mesh.field.add("Distance")
    gmsh.model.mesh.field.setNumbers(distance, "SurfacesList", groups["vane"])
    threshold = gmsh.model.mesh.field.add("Threshold")
    gmsh.model.mesh.field.setNumber(threshold, "InField", distance)
    gmsh.model.mesh.field.setNumber(threshold, "SizeMin", fine)
    gmsh.model.mesh.field.setNumber(threshold, "SizeMax", coarse)
    gmsh.model.mesh.field.setNumber(threshold, "DistMin", 0.0)
    gmsh.model.mesh.field.setNumber(threshold, "DistMax", OUTER)
    gmsh.model.mesh.field.setAsBackgroundMesh(threshold)
    gmsh.option.setNumber("Mesh.MeshSizeExtendFromBoundary", 0)
    gmsh.option.setNumber("Mesh.MeshSizeFromPoints", 0)
    gmsh.option.setNumber("Mesh.MeshSizeFromCurvature", 0)
    gmsh.model.mesh.generate(3)
    gmsh.model.mesh.setOrder(2)
    _, tags, _ = gmsh.model.mesh.getElements(3)
    parents = sum(len(t) for t in tags)
    nodes = len(gmsh.model.mesh.getNodes()[0])
    print(f"{name}: {parents} ten-node tetrahedra ({8 * parents} children), {nodes} nodes; "
          f"groups {[(g, len(t)) for g, t in groups.items()]}, soil {soil_v}, air {air_v}")
    gmsh.write(name)
    gmsh.finalize()


only = sys.argv[1:]
for name, (fine, coarse) in MESHES.items():
    if not only or name in only:
        build(name, fine, coarse)
